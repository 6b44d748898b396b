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

"""Constant moving axle forces on the girders: the coupling without vehicle dynamics."""

from __future__ import annotations

import numpy as np

from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.train import MovingForces
from ttb_sim.sim.coupling.base import FreeDofState, girder_wheel_load, VehicleOutputs
from ttb_sim.sim.coupling.girder_load import MovingLoad
from ttb_sim.sim.integrators.protocol import Integrator

__all__ = ['MovingForceCoupling']


class MovingForceCoupling(FreeDofState):
    """
    Constant vertical forces crossing the girders (Fryba's moving-load problem).

    Parameters
    ----------
    forces : MovingForces
        Axle layout and force of each axle (N, downward).
    structure : Structure
        The assembled bridge.
    integrator : Integrator
        The structure's integrator.
    lean : bool
        Evaluate the load with the lean kernel
        (:class:`~ttb_sim.sim.coupling.girder_load.MovingLoad`), equal to round-off,
        instead of the general girder lookup.

    """

    n_bodies = 0
    n_axles = 1

    def __init__(self, forces: MovingForces, structure: Structure, integrator: Integrator,
                 *, lean: bool = False) -> None:
        self.forces = forces
        self.structure = structure
        self.nm = integrator
        n_free = structure.n_free
        self.u = np.zeros(n_free)
        self.v = np.zeros(n_free)
        self.a = np.zeros(n_free)
        self._no_vehicle = VehicleOutputs(np.zeros((0, 3)), np.zeros((0, 3)),
                                          np.zeros((0, 1, 2, 3)))
        self._lean = (MovingLoad(structure.girder, forces.loads, n_free, structure.n_full)
                      if lean else None)

    def _full_load(self, head: float) -> np.ndarray:
        positions = head - self.forces.axles.offsets
        if self._lean is not None:
            return self._lean.full(positions)
        return girder_wheel_load(self.structure.girder, self.structure.n_full, positions,
                                 self.forces.loads)

    def start(self, head: float) -> None:
        """Start at rest with the forces applied at their initial positions."""
        st = self.structure
        load = girder_wheel_load(st.girder, st.n_full, head - self.forces.axles.offsets,
                                 self.forces.loads)
        self.a = self.nm.initial_acceleration(self.u, self.v, load[st.free])

    def step(self, head: float, speed: float) -> None:
        """Advance the girders one step under the forces at their end-of-step positions."""
        positions = head - self.forces.axles.offsets
        if self._lean is not None:
            force = self._lean(positions)
        else:
            st = self.structure
            force = girder_wheel_load(st.girder, st.n_full, positions,
                                      self.forces.loads)[st.free]
        self.u, self.v, self.a = self.nm.step(self.u, self.v, self.a, force)

    def structure_load(self, head: float) -> np.ndarray:
        """Return the axle forces on all DOFs."""
        return self._full_load(head)

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the girder displacements."""
        return (self.u,)

    def vehicle_outputs(self) -> VehicleOutputs:
        """Return empty vehicle outputs (moving forces have no bodies)."""
        return self._no_vehicle
