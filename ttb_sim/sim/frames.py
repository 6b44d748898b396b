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

"""Frames: what the stepping core emits at each output tick (SI units, track axes)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Layout:
    """Sizes of the things a run reports, known before the first frame."""

    n_spans: int
    n_supports: int
    n_bodies: int
    """Number of car bodies with an IMU (quarter cars: one per axle)."""
    n_axles: int = 1
    """Axles per body with wheel-rail forces (4 for multibody cars)."""
    observers: tuple[str, ...] = ()
    """Names of the displacement observers."""
    piles: tuple[tuple[int, int], ...] = ()
    """(pier number, 1-based; number of piles) of every piled pier, in frame order."""
    soil_points: int = 0
    """Number of ground observation points (all piled piers together)."""
    train: bool = True
    """Whether a train runs (False for a substructure alone: no odometry)."""

    @property
    def n_piles(self) -> int:
        """Total number of piles over all piled piers."""
        return sum(n for _, n in self.piles)


@dataclass(frozen=True)
class Frame:
    """
    The observable state at one output tick.

    Attributes
    ----------
    step : solver step index
    time : simulation time (s)
    head_position : position of the train head along the track (m)
    speed : train speed (m/s)
    midspan : (n_spans, 3) girder mid-span displacement (m), z up
    bearings : (n_supports, 2, 3) bearing forces on each support, left/right (N)
    body_acceleration : (n_bodies, 3) car-body acceleration, gravity excluded (m/s^2)
    body_angular_velocity : (n_bodies, 3) car-body angular velocity (rad/s)
    wheel_rail : (n_bodies, n_axles, 2, 3) force of the rail on each wheel, left/right (N)
    observers : (n_observers, 3) displacement at each observer (m)
    pile_displacement : (n_piles, 3) pile-head displacement, area-weighted mean over the
        head (m), piles in :attr:`Layout.piles` order
    pile_acceleration : (n_piles, 3) pile-head acceleration (m/s^2)
    pile_rotation_rate : (n_piles, 3) pile-head rotation rate (rad/s)
    soil_points : (n_points, 9) ground points: x, y, z (m), displacement (m) and
        acceleration (m/s^2)

    """

    step: int
    time: float
    head_position: float
    speed: float
    midspan: np.ndarray
    bearings: np.ndarray
    body_acceleration: np.ndarray
    body_angular_velocity: np.ndarray
    wheel_rail: np.ndarray
    observers: np.ndarray
    pile_displacement: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pile_acceleration: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pile_rotation_rate: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    soil_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 9)))

    @property
    def stamp_ns(self) -> int:
        """Simulation time in integer nanoseconds (message stamps)."""
        return int(round(self.time * 1e9))
