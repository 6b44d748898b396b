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
The coupling protocol: a vehicle model and the structure it runs on, advanced together.

:class:`~ttb_sim.sim.simulation.Simulation` has one stepping loop written
against :class:`Coupling`; each vehicle model (moving forces, quarter cars,
multibody cars on the slab track) implements it over the structure's
:class:`~ttb_sim.sim.integrators.protocol.Integrator`. A coupling owns the
structure state (free DOFs) and its vehicle state, and reports what a frame needs.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np

from ttb_sim.model.bridge import GirderLine
from ttb_sim.sim.integrators.protocol import Integrator

__all__ = ['Coupling', 'FreeDofState', 'FusedCoupling', 'girder_wheel_load', 'VehicleOutputs']


@dataclass(frozen=True)
class VehicleOutputs:
    """The vehicle's part of a frame (SI units, track axes, z up)."""

    body_acceleration: np.ndarray
    """(n_bodies, 3) body acceleration (m/s^2)."""
    body_angular_velocity: np.ndarray
    """(n_bodies, 3) body angular velocity (rad/s)."""
    wheel_rail: np.ndarray
    """(n_bodies, n_axles, 2, 3) force of rail on wheel, left and right (N)."""


class Coupling(Protocol):
    """A vehicle model coupled to the structure, stepped by the simulation loop."""

    n_bodies: int
    """Bodies reported per frame (cars or quarter cars; 0 for moving forces)."""
    n_axles: int
    """Axles per body reported in the wheel-rail output."""

    def start(self, head: float) -> None:
        """Set the state at t = 0 with the train head at ``head`` (m)."""

    def step(self, head: float, speed: float) -> None:
        """Advance one time step; ``head`` is the head position at its end (m)."""

    def structure_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the structure's (u, v, a) on the free DOFs."""

    def bridge_state(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the structure's (u, v) at free bridge DOFs ``dofs`` (girders, bearings)."""

    def load_bridge(self, dofs: np.ndarray, values: np.ndarray) -> None:
        """Add ``values`` at free bridge DOFs ``dofs`` (unique) to the next step's load."""

    def structure_load(self, head: float) -> np.ndarray:
        """Return the load applied to all DOFs (N), for the reactions of rigid supports."""

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the displacements the divergence check watches: structure first, then vehicle."""

    def vehicle_outputs(self) -> VehicleOutputs:
        """Return the vehicle's part of the current frame."""


@runtime_checkable
class FusedCoupling(Coupling, Protocol):
    """
    A coupling that can take many steps in one compiled loop (the ``realtime`` variant).

    :meth:`fused` tells whether the loop is available for this model and
    integrator; :meth:`advance` then takes the steps between two frames with the
    same arithmetic as calling :meth:`step` once per step.
    """

    def fused(self) -> bool:
        """Tell whether :meth:`advance` runs the compiled loop."""

    def advance(self, head: float, speed: float, dt: float, steps: int,
                limit: float) -> tuple[float, int, float]:
        """
        Take up to ``steps`` steps; return (head, steps taken, largest displacement).

        Each step moves the head by ``speed * dt``; the loop stops after a step
        whose largest displacement is not finite or exceeds ``limit``.
        """


class FreeDofState:
    """
    The structure side of a coupling that solves the structure on its free DOFs.

    Gives :class:`Coupling`'s structure state and bridge access from the
    coupling's ``u``, ``v``, ``a`` and its integrator ``nm``.
    """

    nm: Integrator
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray

    def structure_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the structure state (u, v, a) on the free DOFs."""
        return self.u, self.v, self.a

    def bridge_state(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return (u, v) at the free DOFs ``dofs``."""
        return self.u[dofs], self.v[dofs]

    def load_bridge(self, dofs: np.ndarray, values: np.ndarray) -> None:
        """Add ``values`` at the free DOFs ``dofs`` (unique) to the next step's load."""
        self.nm.external = (dofs, values)


def girder_wheel_load(girder: GirderLine, n_full: int, positions: np.ndarray,
                      forces: np.ndarray) -> np.ndarray:
    """
    Return the full-DOF load of downward wheel forces on the girders.

    Parameters
    ----------
    girder : GirderLine
        The girder lookup.
    n_full : int
        Number of all DOFs.
    positions : numpy.ndarray
        (n,) wheel positions along the track (m).
    forces : numpy.ndarray
        (n,) downward force of each wheel (N).

    """
    element, (n0,) = girder.rows(positions)
    return np.bincount(girder.w_dofs_full[element].ravel(),
                       weights=(-forces[:, None] * n0).ravel(), minlength=n_full)


def girder_green(integrator: Integrator, n_free: int,
                 girder_dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the inverse effective matrix among the girder DOFs, and each DOF's slot in it.

    ``integrator.solve`` of a unit load on each of ``girder_dofs`` (free DOFs of a
    system of ``n_free``). The block gets one more row and column of zeros, the
    slot of the constrained DOFs (index ``n_free`` in ``w_dofs``).
    """
    k = girder_dofs.size
    unit = np.zeros((n_free, k))
    unit[girder_dofs, np.arange(k)] = 1.0
    green = np.zeros((k + 1, k + 1))
    green[:k, :k] = np.asarray(integrator.solve(unit))[girder_dofs]
    slot = np.full(n_free + 1, k, dtype=np.intp)
    slot[girder_dofs] = np.arange(k)
    return green, slot
