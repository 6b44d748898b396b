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
FRONT_MARGIN + ADVANCE]``. The girders, bearings and piers are kept whole.
Every other track DOF follows the bridge:

* stiffness and state: u_far = T_t u_bridge, the static response of the
  unloaded track to the bridge's displacement (T_t = -K_tt^-1 K_tb, computed
  once; Guyan condensation). The reduced stiffness T^T K T therefore gives the
  bridge exactly the static stiffness the full model has, including the
  track's continuity over the span joints through its compliant layers.
  Entries of T_t below BASIS_DROP of their column's largest are dropped.
* mass and damping: the far track rides rigidly on the girder axis below it
  (local; the rotation about x carries the offsets), so the reduced M and C
  stay as sparse as the full model's and the history mat-vec shrinks with the
  DOFs. The far track's layers and fasteners do not deform in this motion and
  add no damping.

When the front axle comes within FRONT_MARGIN of the window's end the window
is rebuilt ahead (about every ADVANCE metres of travel, a second or two of
set-up each): the state is expanded to all DOFs with the old T and restricted
to the new window's DOFs. Track that enters the window starts where the
unloaded track would be; track that leaves it behind the train loses its
vibration relative to the girder.

Range of validity: the wheel-rail forces see the full track within the
window. The bridge sees the far track through its static stiffness and as
mass moving with the girder: right below the far track's own resonances on
its layers and fasteners (about 100 Hz and up on the default track), i.e.
for the bridge band (measured on paper_ttbi: the lowest twelve modes, 2-4 Hz,
within 0.04 % of the full model). Lost is the track vibration left behind
the train and any wave that would run ahead of the window in the track.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import time

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe.beam import field_rows, offset_rows
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
dropped. Measured on paper_ttbi: 1e-5 keeps the lowest twelve modes within 0.04 %; 1e-4
moved them by up to 0.3 %, and 1e-3 (measured with this basis for the mass too) by up to
10 %, for a sparser reduced stiffness."""
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
        T, (n_free, n_reduced): all free DOFs from the reduced ones, the far
        track statically condensed (the stiffness and the state).
    local_basis : scipy.sparse.csr_matrix
        The same with the far track riding rigidly on the girder (local: the
        mass and damping, so that they stay as sparse as the full model's).
    kept : numpy.ndarray
        (n_reduced,) free index of each reduced DOF (increasing).
    full_to_reduced : numpy.ndarray
        (n_full,) reduced index of each full DOF; ``n_reduced`` (the ground
        slot) where the DOF is not a reduced one.

    """

    start: float
    end: float
    basis: sp.csr_matrix
    local_basis: sp.csr_matrix
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
    a given bridge displacement. Vertically it decays within metres of each
    girder node, longitudinally (the continuous rails) over tens of metres;
    entries below ``BASIS_DROP`` of the largest in their column are dropped.
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
    if touched.size == 0:
        return sp.csr_matrix((n_free, n_free))
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


def rigid_track_basis(structure: Structure) -> sp.csr_matrix:
    """
    Return the track riding rigidly on the girder axis below it, (n_free, n_free).

    Each track node on the bridge moves as the girder axis at its x (Hermite
    shape functions of the girder element; the rotation about x carries the
    node's lateral and vertical offsets; the longitudinal motion is the
    axis's). Track off the bridge has zero rows (rigid ground). Local: each
    node depends on the 12 DOFs of one girder element.
    """
    n_free = structure.n_free
    ftf = structure.full_to_free
    track_free, x = track_free_dofs(structure)
    track = structure.track
    assert track is not None
    y = np.zeros(x.size)
    z = np.zeros(x.size)
    first = track_free[:, 0]
    for line in (*track.rails, track.slab, track.base):
        at = np.isin(first, ftf[line.dofs[:, [0, 6]]])
        y[at], z[at] = line.y, line.z
    girder = structure.girder_beam
    on = (x >= girder.start[0]) & (x <= girder.end)
    element, xi, _ = girder.locate(x[on])
    fields = field_rows(xi, girder.length[element])                # (n, 6, 12)
    arm = np.stack([np.zeros(xi.size), y[on], z[on]], axis=-1)
    node_rows = fields.copy()
    node_rows[:, 1:3] = offset_rows(fields, arm)[:, 1:3]
    cols = np.broadcast_to(ftf[girder.dofs[element]][:, None, :], node_rows.shape)
    rows = np.broadcast_to(track_free[on][:, :, None], node_rows.shape)
    ok = (rows < n_free) & (cols < n_free) & (node_rows != 0.0)
    return sp.csr_matrix((node_rows[ok], (rows[ok], cols[ok])), shape=(n_free, n_free))


def track_window(structure: Structure, static: sp.csr_matrix, rigid: sp.csr_matrix,
                 start: float, end: float) -> TrackWindow:
    """
    Build the reduction basis with the track detailed between ``start`` and ``end``.

    Parameters
    ----------
    structure : Structure
        The assembled track and bridge.
    static, rigid : scipy.sparse.csr_matrix
        :func:`static_track_basis` and :func:`rigid_track_basis` of the structure.
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
    select = sp.diags(far.astype(float))

    def basis(far_motion: sp.csr_matrix) -> sp.csr_matrix:
        coo = (select @ far_motion).tocoo()
        return sp.csr_matrix((np.concatenate([np.ones(n_red), coo.data]),
                              (np.concatenate([kept, coo.row]),
                               np.concatenate([np.arange(n_red), free_to_red[coo.col]]))),
                             shape=(n_free, n_red))

    full_to_red = free_to_red[structure.full_to_free]
    return TrackWindow(start, end, basis(static), basis(rigid), kept, full_to_red)


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
        self._bases: tuple[sp.csr_matrix, sp.csr_matrix] | None = None
        self.window_moves = 0
        """How many times the window was built (the first included)."""
        self.window_time = 0.0
        """CPU time spent building windows (s), the static basis included."""

    def _rail_compliance(self, integrator: Integrator,
                         full_to_free: np.ndarray) -> RailCompliance:
        """
        Return the full model's rail compliance; each window uses it restricted.

        Computed once, on the full model: the element blocks and the K^-1 columns
        of a rail node well inside the window (the wheels are at least
        BACK_MARGIN / FRONT_MARGIN from its ends) are those of the window's
        model up to what the condensed far track changes tens of metres away,
        and the single-solve step checks the exact rail motion under every
        wheel against them. Probing each window's own K^-1 instead would not
        stay local: the condensed far track couples the girder nodes over tens
        of metres (measured: 4.8 -> 17.7 s and 1.9 GiB per window).
        """
        self._full_compliance = super()._rail_compliance(integrator, full_to_free)
        return self._full_compliance

    def _axle_span(self, head: float) -> tuple[float, float]:
        x = head + self.contact_x
        return float(np.min(x)), float(np.max(x))

    def _move_window(self, head: float) -> None:
        """Build the window around the train at ``head`` and carry the state over."""
        begin = time.process_time()
        rear, front = self._axle_span(head)
        st = self.structure
        old = self.window
        if old is not None:
            state = [old.basis @ s for s in (self.u, self.v, self.a)]
        else:
            state = [np.zeros(st.n_free)] * 3
        if self._bases is None:
            self._bases = (static_track_basis(st, self._method), rigid_track_basis(st))
        window = track_window(st, *self._bases, rear - BACK_MARGIN,
                              front + FRONT_MARGIN + ADVANCE)
        t, local = window.basis, window.local_basis
        self.nm = Newmark(project(st.mass, local), project(st.damping, local),
                          project(st.stiffness, t), self._dt, method=self._method, lean=True)
        self.static_stiffness = self.nm.stiffness
        self.n_free = window.size
        ftr = window.full_to_reduced
        self.rail_dofs = tuple(ftr[r.dofs] for r in self.rails)
        free_to_red = np.full(st.n_free + 1, window.size)
        free_to_red[window.kept] = np.arange(window.size)
        self.compliance = self._full_compliance.restricted(free_to_red, window.size)
        self.u, self.v, self.a = (s[window.kept].copy() for s in state)
        self.window = window
        self.window_moves += 1
        self.window_time += time.process_time() - begin
        log.debug('track window %.1f .. %.1f m: %d of %d DOFs', window.start, window.end,
                  window.size, st.n_free)

    def start(self, head: float) -> None:
        """Build the first window and start from the static equilibrium on it."""
        self.window = None
        self.window_moves = 0
        self.window_time = 0.0
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
        """
        Return the track-bridge state on every free DOF, for the frames.

        The bridge and the window's track are the solved DOFs themselves; the far
        track is shown riding rigidly on the girder (the local basis: measured 30
        times cheaper per frame than the static one, and they differ only by the
        far track's deflection on its layers, which carry no load).
        """
        assert self.window is not None, 'start() first'
        t = self.window.local_basis
        return t @ self.u, t @ self.v, t @ self.a
