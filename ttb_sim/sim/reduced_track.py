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
The reduced track-bridge (``solver.variant: reduced``): detail only in a window at the train.

Only the track near the train is solved in detail: rails, fasteners, slabs and
base plates whose nodes lie within ``[rear axle - BACK_MARGIN, front axle +
FRONT_MARGIN + ADVANCE]``. Every other track node rides on the structure
beneath it (a Ritz reduction u = T u_r with a sparse, local T): on the bridge
it moves with the girder axis below (the Hermite shape functions of the girder
element, rigid offsets for the rotation about x; the longitudinal motion is the
axis's, so the far track adds no composite bending stiffness), on the
approaches it stays on the rigid ground. The girders, bearings and piers are
kept whole. The reduced matrices are T^T M T, T^T C T, T^T K T: symmetric,
sparse, and the far track's mass and its rails' and slabs' bending stiffness
stay in the bridge.

When the front axle comes within FRONT_MARGIN of the window's end the window
is rebuilt ahead (about every ADVANCE metres of travel, 1-2 s of set-up each):
the state is expanded to all DOFs with the old T and restricted to the new
window's DOFs. Track that enters the window starts on the girder (where the
unloaded track ahead of the train is); track that leaves it behind the train
loses its motion relative to the girder.

Validity: the wheel-rail forces see the full track within the window; the
girder sees the far track as rigidly attached mass. The far track's own
vibration relative to the girder (slab and base on their layers, rails on the
fasteners) starts at about 100 Hz on the default track, so the bridge
response is represented for the bridge band (up to a few tens of Hz); what is
lost is the high-frequency track vibration left behind the train.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe.factorization import factorize
from ttb_sim.model.bridge import Structure
from ttb_sim.model.irregularity import TrackIrregularity
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.wheel_rail.parameters import ContactParameters
from ttb_sim.sim.coupling.train_track import RailCompliance, TrainTrackCoupling
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.integrators.protocol import Integrator

log = logging.getLogger(__name__)

BACK_MARGIN = 30.0
"""Detailed track kept behind the last axle (m)."""
FRONT_MARGIN = 30.0
"""Detailed track kept ahead of the first axle (m): the window moves before it is less."""
ADVANCE = 40.0
"""Extra detailed track ahead, so the window moves about every ADVANCE metres of travel."""
BASIS_DROP = 1e-5
"""Entries of the static track basis below this fraction of their column's largest are
dropped (the response decays within a few metres of a girder node)."""
BASIS_CHUNK = 64
"""Bridge DOFs per batch of the static solves that build the basis."""


@dataclass(frozen=True)
class TrackWindow:
    """
    The reduction basis of one window position.

    Attributes
    ----------
    start, end : float
        The detailed track lies between these positions (m along the track).
    basis : scipy.sparse.csr_matrix
        T, (n_free, n_reduced): all free DOFs from the reduced ones.
    kept : numpy.ndarray
        (n_reduced,) free index of each reduced DOF (increasing).
    full_to_reduced : numpy.ndarray
        (n_full,) reduced index of each full DOF; ``n_reduced`` (the ground
        slot) where the DOF is not a reduced one.

    """

    start: float
    end: float
    basis: sp.csr_matrix
    kept: np.ndarray
    full_to_reduced: np.ndarray

    @property
    def size(self) -> int:
        """Number of reduced DOFs."""
        return int(self.kept.size)


def track_free_dofs(structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the track's free DOFs, (n_nodes, 6) (``n_free`` where constrained), and node x (m).

    Raises
    ------
    ValueError
        If the structure has no track.

    """
    track = structure.track
    if track is None:
        raise ValueError('the reduced track needs a structure with a track')
    first, xs = [], []
    for line in (*track.rails, track.slab, track.base):
        for col, x in ((0, line.start), (6, line.start + line.length)):
            first.append(line.dofs[:, col])
            xs.append(x)
    dof0, index = np.unique(np.concatenate(first), return_index=True)
    full = dof0[:, None] + np.arange(6)
    return structure.full_to_free[full], np.concatenate(xs)[index]


def static_track_basis(structure: Structure, method: str) -> sp.csr_matrix:
    """
    Return the static response of the unloaded track to the bridge's motion.

    T_t = -K_tt^-1 K_tb, (n_free, n_free) with non-zero rows only at the track
    DOFs and non-zero columns only at the bridge DOFs (girders, bearings, piers)
    that the track rests on: where the track would be, with no load on it, for
    a given bridge displacement. It decays within a few metres of each girder
    node (rails and plates on stiff layers); entries below ``BASIS_DROP`` of
    the largest in their column are dropped.
    """
    n_free = structure.n_free
    track_free, _ = track_free_dofs(structure)
    track = np.unique(track_free[track_free < n_free])
    is_track = np.zeros(n_free, dtype=bool)
    is_track[track] = True
    bridge = np.flatnonzero(~is_track)
    k = structure.stiffness.tocsr()
    k_tt = k[track][:, track].tocsc()
    k_tb = k[track][:, bridge].tocsc()
    touched = np.flatnonzero(np.diff(k_tb.indptr))     # bridge DOFs the track rests on
    lu = factorize(k_tt, method=method)
    rows, cols, vals = [], [], []
    for chunk in np.array_split(touched, max(1, touched.size // BASIS_CHUNK)):
        x = -lu.solve(k_tb[:, chunk].toarray())
        peak = np.max(np.abs(x), axis=0)
        r, c = np.nonzero(np.abs(x) > BASIS_DROP * peak)
        rows.append(track[r])
        cols.append(bridge[chunk[c]])
        vals.append(x[r, c])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n_free, n_free))


def track_window(structure: Structure, static: sp.csr_matrix, start: float,
                 end: float) -> TrackWindow:
    """
    Build the reduction basis with the track detailed between ``start`` and ``end``.

    Parameters
    ----------
    structure : Structure
        The assembled track and bridge.
    static : scipy.sparse.csr_matrix
        :func:`static_track_basis` of the structure.
    start, end : float
        Ends of the detailed track (m along the track).

    """
    n_free = structure.n_free
    track_free, x = track_free_dofs(structure)
    valid = track_free < n_free
    is_track = np.zeros(n_free, dtype=bool)
    is_track[track_free[valid]] = True
    inside = (x >= start) & (x <= end)
    keep = ~is_track
    keep[track_free[inside][valid[inside]]] = True
    kept = np.flatnonzero(keep)
    n_red = kept.size
    free_to_red = np.full(n_free + 1, n_red)
    free_to_red[kept] = np.arange(n_red)
    # Kept DOFs: identity rows; far track: the static response to the bridge DOFs
    # (every bridge DOF is kept).
    far = np.zeros(n_free, dtype=bool)
    far[track_free[~inside][valid[~inside]]] = True
    far_rows = sp.diags(far.astype(float)) @ static
    coo = far_rows.tocoo()
    basis = sp.csr_matrix((np.concatenate([np.ones(n_red), coo.data]),
                           (np.concatenate([kept, coo.row]),
                            np.concatenate([np.arange(n_red), free_to_red[coo.col]]))),
                          shape=(n_free, n_red))
    full_to_red = free_to_red[structure.full_to_free]
    return TrackWindow(start, end, basis, kept, full_to_red)


def project(matrix: sp.spmatrix, basis: sp.csr_matrix) -> sp.csr_matrix:
    """Return T^T A T, symmetrised (A symmetric)."""
    reduced = (basis.T @ (sp.csr_matrix(matrix) @ basis)).tocsr()
    return ((reduced + reduced.T) * 0.5).tocsr()


class ReducedTrainTrackCoupling(TrainTrackCoupling):
    """
    :class:`TrainTrackCoupling` on the reduced track-bridge of a window that moves with the train.

    The contact step is the parent's, on the reduced state; the window is
    rebuilt ahead of the train as it runs (module docstring). The frames get
    the state of every free DOF (:meth:`structure_state`).

    Parameters
    ----------
    car, contact, n_cars, car_length, structure, integrator, irregularity
        As for :class:`TrainTrackCoupling`; only the time step and the
        factorisation method of ``integrator`` are used.

    """

    def __init__(self, car: CarParameters, contact: ContactParameters, n_cars: int,
                 car_length: float, structure: Structure, integrator: Integrator,
                 irregularity: TrackIrregularity | None) -> None:
        super().__init__(car, contact, n_cars, car_length, structure, integrator, irregularity)
        self._dt = float(integrator.dt)
        self._method = str(integrator.method)
        self.window: TrackWindow | None = None
        self._static: sp.csr_matrix | None = None
        self.window_moves = 0
        """How many times the window was built (the first included)."""

    def _rail_compliance(self, integrator: Integrator,
                         full_to_free: np.ndarray) -> RailCompliance:
        """Return an empty compliance: the window's is built with the window."""
        return RailCompliance(integrator, (), full_to_free)

    def _axle_span(self, head: float) -> tuple[float, float]:
        x = head + self.contact_x
        return float(np.min(x)), float(np.max(x))

    def _move_window(self, head: float) -> None:
        """Build the window around the train at ``head`` and carry the state over."""
        rear, front = self._axle_span(head)
        st = self.structure
        old = self.window
        if old is not None:
            state = [old.basis @ s for s in (self.u, self.v, self.a)]
        else:
            state = [np.zeros(st.n_free)] * 3
        if self._static is None:
            self._static = static_track_basis(st, self._method)
        window = track_window(st, self._static, rear - BACK_MARGIN,
                              front + FRONT_MARGIN + ADVANCE)
        t = window.basis
        self.nm = Newmark(project(st.mass, t), project(st.damping, t),
                          project(st.stiffness, t), self._dt, method=self._method, lean=True)
        self.static_stiffness = self.nm.stiffness
        self.n_free = window.size
        ftr = window.full_to_reduced
        self.rail_dofs = tuple(ftr[r.dofs] for r in self.rails)
        self.compliance = RailCompliance(self.nm, self.rails, ftr)
        self.u, self.v, self.a = (s[window.kept].copy() for s in state)
        self.window = window
        self.window_moves += 1
        log.debug('track window %.1f .. %.1f m: %d of %d DOFs', window.start, window.end,
                  window.size, st.n_free)

    def start(self, head: float) -> None:
        """Build the first window and start from the static equilibrium on it."""
        self.window = None
        self.window_moves = 0
        self._move_window(head)
        super().start(head)

    def step(self, head: float, speed: float) -> None:
        """Move the window when the train nears its end, then take the coupled step."""
        assert self.window is not None, 'start() first'
        rear, front = self._axle_span(head)
        if front + FRONT_MARGIN > self.window.end or rear < self.window.start:
            self._move_window(head)
        super().step(head, speed)

    def structure_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the track-bridge state on every free DOF (far track on the girder)."""
        assert self.window is not None, 'start() first'
        t = self.window.basis
        return t @ self.u, t @ self.v, t @ self.a
