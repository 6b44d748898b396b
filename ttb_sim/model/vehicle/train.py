# Copyright 2026 The ttb_sim Authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Reduced vehicle models that run on the girders: moving forces and quarter cars.

Axles are listed by their distance behind the train head. A quarter car is a
sprung mass on a linear spring-dashpot over a wheel of (optional) unsprung mass
that stays in contact with what it runs on: the girder on the bridge, rigid
ground off it. Vehicle displacements are measured from static equilibrium, z up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.model.constants import GRAVITY


@dataclass(frozen=True)
class Axles:
    """Axle layout of a train."""

    offsets: np.ndarray
    """Distance of each axle behind the head (m), shape (n_axles,)."""

    @property
    def count(self) -> int:
        """Number of axles."""
        return int(self.offsets.size)

    @property
    def train_length(self) -> float:
        """Distance from the head to the last axle (m)."""
        return float(self.offsets.max()) if self.count else 0.0


@dataclass(frozen=True)
class MovingForces:
    """Constant vertical forces (N, downward), one per axle."""

    axles: Axles
    loads: np.ndarray


@dataclass(frozen=True)
class QuarterCars:
    """
    One quarter car per axle (arrays of shape (n_axles,), SI units).

    ``axles_per_car`` groups consecutive axles into the cars they are published
    as (``car01/axle1``..``axle4``): the four quarter cars of a car of the
    train's layout, or one axle per car for axles placed by hand.
    """

    axles: Axles
    sprung_mass: np.ndarray
    unsprung_mass: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    axles_per_car: int = 1

    @property
    def static_load(self) -> np.ndarray:
        """Static contact force of each wheel (N)."""
        return (self.sprung_mass + self.unsprung_mass) * GRAVITY

    def natural_frequency(self) -> np.ndarray:
        """Bounce frequency of each sprung mass on its suspension, wheel fixed (Hz)."""
        return np.sqrt(self.stiffness / self.sprung_mass) / (2 * np.pi)


@dataclass(frozen=True)
class MultibodyCars:
    """
    A train of 42-DOF cars (:mod:`ttb_sim.model.vehicle.car`) on wheel-rail contact.

    Only the axle layout lives here; the matrices and the contact state belong
    to :class:`ttb_sim.sim.coupling.train_track.TrainTrackCoupling`.
    """

    axles: Axles
    n_cars: int
    car_length: float

    @property
    def length(self) -> float:
        """Length of the train over couplers (m)."""
        return self.n_cars * self.car_length


Vehicle = MovingForces | QuarterCars | MultibodyCars
