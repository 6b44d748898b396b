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
The quarter cars' compiled loop on a girder system with its piled piers' interiors condensed.

:class:`CondensedGirders` builds, for :class:`~.wheels.QuarterCarTrain`, the kept
system of :mod:`ttb_sim.sim.integrators.condensed` (its integrator, its Green's
function on the girder, the loop's state on the kept DOFs, the interiors' modal
state) and writes the whole state back after each call of the loop.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ttb_sim.sim.coupling.base import girder_green
from ttb_sim.sim.integrators.condensed import condense_interiors, ModalInteriors
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.integrators.protocol import Integrator

if TYPE_CHECKING:
    from ttb_sim.sim.coupling.quarter_car.wheels import QuarterCarTrain


NO_INTERIORS = (np.zeros(1, dtype=np.int64), np.zeros((0, 0), dtype=np.int64),
                *(np.zeros(0, complex) for _ in range(2)), np.zeros((0, 0), complex),
                np.zeros((0, 3, 0), complex),
                np.zeros((0, 0, 0)), np.zeros((0, 0, 0)),
                *(np.zeros(0, complex) for _ in range(3)))
"""The compiled loop's interiors when none is condensed (start = [0])."""


class CondensedGirders:
    """
    The compiled loop's system with the monolithic piled piers' interiors condensed (module).

    :mod:`~ttb_sim.sim.integrators.condensed` takes each reduced substructure's
    coordinates but its pier top out of the girder system and steps them mode by
    mode inside the loop; this holds the kept system's integrator, its Green's
    function on the girder, the loop's state on the kept DOFs and the interiors'
    modal state, and writes the whole state back after each call of the loop.
    """

    def __init__(self, interiors: ModalInteriors, nm: Newmark, train: QuarterCarTrain) -> None:
        self.interiors = interiors
        self.nm: Integrator = nm
        self.size = interiors.keep.size
        girder, n_free = train.structure.girder, train.structure.n_free
        self.w_dofs = np.where(girder.w_dofs >= n_free, self.size, girder.w_dofs)
        dofs = np.unique(self.w_dofs)
        self.green, self.slot = girder_green(nm, self.size, dofs[dofs < self.size])
        self.kept = tuple(np.zeros(self.size) for _ in range(3))
        modes = sum(m.rho.size for m in interiors.modes)
        self._modal = tuple(np.zeros(modes, complex) for _ in range(3))
        self.arguments = (*interiors.packed(), *self._modal)

    @classmethod
    def of(cls, train: QuarterCarTrain) -> CondensedGirders | None:
        """Return the condensed system of a train's structure, or None (nothing to condense)."""
        st, nm = train.structure, train.nm
        blocks = [p.block for p in st.piled if p.block is not None]
        if not blocks:
            return None
        interiors = condense_interiors(st.mass, st.damping, st.stiffness, blocks, nm.dt)
        if interiors is None:
            return None
        index = interiors.kept_index
        girder = st.girder.w_dofs[st.girder.w_dofs < st.n_free]
        if not np.array_equal(index[girder], girder):   # the loop's wheels index the girders
            return None
        mass, damping, stiffness = interiors.kept_matrices(st.mass, st.damping, st.stiffness)
        kept = Newmark(mass, damping, stiffness, nm.dt, method=nm.method, lean=True, fused=True)
        if kept.fused_arrays() is None:
            return None
        return cls(interiors, kept, train)

    def start(self, state: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
        """Take the whole state (a start, or a state set from outside); return the kept one."""
        keep = self.interiors.keep
        for out, values in zip(self.kept, state):
            out[:] = values[keep]
        eta, e = self.interiors.amplitudes(*state)
        self._modal[0][:] = eta
        self._modal[1][:] = e
        return self.kept

    def expand(self, state: tuple[np.ndarray, ...]) -> None:
        """Write the kept state and the interiors' coordinates into the whole ``state``."""
        self.interiors.expand(self.kept, self._modal[0], state)
