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
Constant moving axle forces on the girders: the coupling without vehicle dynamics.

With a fused integrator (the ``realtime`` variant) the steps between two frames
run as one compiled loop, :func:`advance_moving_forces`:
the moving load, the lean Newmark step and the divergence check of every step,
the same arithmetic as the step-by-step path (``test/sim/test_realtime.py``).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.train import MovingForces
from ttb_sim.sim.coupling.base import FreeDofState, girder_wheel_load, VehicleOutputs
from ttb_sim.sim.coupling.girder_load import moving_load, MovingLoad
from ttb_sim.sim.integrators.newmark_kernels import largest_magnitude, newmark_ldl_step
from ttb_sim.sim.integrators.protocol import Integrator
from ttb_sim.sim.kernel_registry import KernelTable

__all__ = ['advance_moving_forces', 'MovingForceCoupling']

HELPERS = ('moving_load', 'newmark_ldl_step', 'largest_magnitude')
"""Functions the compiled loop calls (:func:`ttb_sim.fe.compiled.jit` compiles them first)."""


def advance_moving_forces(head: float, speed: float, dt: float, steps: int,
                          offsets: np.ndarray, forces: np.ndarray, h: float, n_el: int,
                          length: float, w_dofs: np.ndarray, indptr: np.ndarray,
                          indices: np.ndarray, data: np.ndarray, lp: np.ndarray,
                          li: np.ndarray, lx: np.ndarray, dinv: np.ndarray, order: np.ndarray,
                          a0: float, a1: float, u: np.ndarray, v: np.ndarray, a: np.ndarray,
                          history_buffer: np.ndarray, rhs: np.ndarray, work: np.ndarray,
                          load: np.ndarray, positions: np.ndarray,
                          limit: float) -> tuple[float, int, float]:
    """
    Take up to ``steps`` steps of the girders under the moving forces, in place.

    Each step moves the head by ``speed * dt`` (the simulation loop's own
    arithmetic), loads the girders at the axles' end-of-step positions
    (:func:`~ttb_sim.sim.coupling.girder_load.moving_load` into ``load``, n_free + 1
    slots) and takes :func:`~ttb_sim.sim.integrators.newmark_kernels.newmark_ldl_step`.
    Stops after the first step whose largest displacement is not finite or
    exceeds ``limit``.

    Returns
    -------
    (head, steps taken, largest displacement of the last step)

    """
    n = u.shape[0]
    peak = 0.0
    for step in range(steps):
        head += speed * dt
        for i in range(offsets.shape[0]):
            positions[i] = head - offsets[i]
        moving_load(positions, forces, h, n_el, length, w_dofs, load)
        newmark_ldl_step(indptr, indices, data, lp, li, lx, dinv, order, a0, a1, u, v, a,
                         load[:n], history_buffer, rhs, work)
        peak = largest_magnitude(u, 0.0)
        if not peak <= limit:
            return head, step + 1, peak
    return head, steps, peak


KERNELS = KernelTable({'advance_moving_forces': advance_moving_forces})
"""The compiled loop of the ``realtime`` variant."""


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
        self._fused: tuple[Any, ...] | None = None
        """(kernel, integrator arrays) of the compiled loop, () without it; None: not looked."""
        self._constants: tuple[Any, ...] = ()
        self._buffers: tuple[np.ndarray, ...] = ()

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

    def fused(self) -> bool:
        """Tell whether :meth:`advance` runs the compiled loop (else it steps one by one)."""
        if self._fused is None:
            arrays = self.nm.fused_arrays()
            kernel = KERNELS.compiled('advance_moving_forces')
            ok = arrays is not None and kernel is not None and self._lean is not None
            self._fused = (kernel, arrays) if ok else ()
        return bool(self._fused)

    def advance(self, head: float, speed: float, dt: float, steps: int,
                limit: float) -> tuple[float, int, float]:
        """
        Take up to ``steps`` steps at ``speed`` from the head at ``head`` (the compiled loop).

        Returns (head, steps taken, largest displacement of the last step); fewer
        steps than asked when one exceeded ``limit`` or was not finite.
        """
        assert self.fused(), 'advance() needs the compiled loop: check fused() first'
        assert self._fused is not None
        kernel, arrays = self._fused
        if not self._constants:
            girder, n = self.structure.girder, self.structure.n_free
            self._constants = (
                self.forces.axles.offsets.astype(np.float64),
                np.asarray(self.forces.loads, dtype=np.float64), float(girder.element_length),
                girder.n_spans * girder.elements_per_span, float(girder.length),
                girder.w_dofs, *arrays, self.nm.a0, self.nm.a1)
            self._buffers = (np.zeros(n), np.zeros(n), np.zeros(n + 1),
                             np.zeros(self.forces.axles.count))
        return kernel(float(head), float(speed), float(dt), int(steps), *self._constants,
                      self.u, self.v, self.a, self.nm.history_buffer, *self._buffers,
                      float(limit))

    def structure_load(self, head: float) -> np.ndarray:
        """Return the axle forces on all DOFs."""
        return self._full_load(head)

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the girder displacements."""
        return (self.u,)

    def vehicle_outputs(self) -> VehicleOutputs:
        """Return empty vehicle outputs (moving forces have no bodies)."""
        return self._no_vehicle
