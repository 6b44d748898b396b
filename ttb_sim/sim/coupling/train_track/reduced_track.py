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
base plates whose nodes lie within ``[rear axle - margin, front axle + margin +
ADVANCE]`` (``solver.window_margin``, default MARGIN), widened to the nearest
slab-unit joints. The girders, bearings and piers are kept whole, and so are
the rail nodes over every joint between slab units (the rail cuts). Every
other track DOF follows them:

* stiffness and state: u_far = T_t u_master, the static response of the
  unloaded track to the motion of the bridge and of the rail cuts (T_t =
  -K_tt^-1 K_tm, computed once; Guyan condensation). The slab units touch
  each other only through the rails, so with the rails cut over the joints
  every unit is condensed on its own: T_t is local (a unit's nodes follow the
  girder below it and the two cuts at its ends) and so is the reduced
  stiffness T^T K T, which gives the bridge exactly the static stiffness of
  the full model, the track's continuity over the span joints included.
* mass and damping: the far track rides rigidly on the girder axis below it
  (local; the rotation about x carries the offsets), the cuts move as
  themselves. The far track's layers and fasteners do not deform in this
  motion and add no damping.

When the front axle comes within the margin of the window's end the window is
rebuilt ahead (about every ADVANCE metres of travel): the state is expanded to
all DOFs with the old T and restricted to the new window's DOFs. Track that
enters the window starts where the unloaded track would be; track that leaves
it behind the train loses its vibration relative to the girder.

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

from ttb_sim.errors import ModelError
from ttb_sim.fe.beam import field_rows, offset_rows
from ttb_sim.fe.factorization import factorize
from ttb_sim.model.irregularity import TrackIrregularity
from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.wheel_rail.contact_parameters import ContactParameters
from ttb_sim.sim.coupling.train_track.multibody import TrainTrackCoupling
from ttb_sim.sim.coupling.train_track.rail_compliance import RailCompliance
from ttb_sim.sim.integrators.multirate import check_coupling, MultiRateNewmark
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.integrators.protocol import Integrator

log = logging.getLogger(__name__)

MARGIN = 100.0
"""Default detailed track kept behind the last axle and ahead of the first (m): the window
moves before the front margin is less. Measured on the first 3.5 s of paper_ttbcpsi against
the full model, margins 30 / 60 / 100 m: pile-head acceleration 9.0 / 5.7 / 3.4 % RMS,
bearing forces 0.90 / 0.54 / 0.29 %, pile-head displacement 0.0027 / 0.0020 / 0.0013 %, for
107 / 116 / 123 s of CPU (the full model 170 s); and with ``realtime`` over the whole
passage of paper_ttbi (300 km/h, rail steps 2 against 5 at 30 m): bearing forces 0.50 %
against 1.41 %, the issue's budget being 1 % (docs/performance.md)."""
ADVANCE = 40.0
"""Extra detailed track ahead, so the window moves about every ADVANCE metres of travel."""
BASIS_DROP = 1e-12
"""Entries of the static track basis below this fraction of their column's largest are
dropped (round-off: the basis of a slab unit is dense over the unit)."""
BASIS_CHUNK = 64
"""Bridge DOFs per batch of the static solves that build the basis."""


def rail_and_slab_dofs(structure: Structure) -> np.ndarray:
    """Return the full DOFs of both rails and the slabs (the multi-rate step's fast part)."""
    track = structure.track
    if track is None:
        raise ModelError('the track-bridge has no slab track: no rails and slabs to step apart')
    lines = (*track.rails, track.slab)
    return np.unique(np.concatenate([line.dofs.ravel() for line in lines]))


def fast_track_range(structure: Structure) -> slice:
    """Return the free DOFs of the rails and slabs, one contiguous range (the track's first)."""
    free = structure.full_to_free[rail_and_slab_dofs(structure)]
    free = np.unique(free[free < structure.n_free])
    if free[-1] - free[0] + 1 != free.size:
        raise ModelError('the rails and slabs are not numbered as one range of free DOFs')
    return slice(int(free[0]), int(free[-1]) + 1)


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
    free_to_reduced : numpy.ndarray
        (n_free + 1,) reduced index of each free DOF and of the ground slot;
        ``n_reduced`` where the DOF is not a reduced one.
    full_to_reduced : numpy.ndarray
        (n_full,) reduced index of each full DOF; ``n_reduced`` (the ground
        slot) where the DOF is not a reduced one.
    reaches_start, reaches_end : bool
        The window takes the track to its first (last) node: it cannot move
        further that way.

    """

    start: float
    end: float
    basis: sp.csr_matrix
    local_basis: sp.csr_matrix
    kept: np.ndarray
    free_to_reduced: np.ndarray
    full_to_reduced: np.ndarray
    reaches_start: bool = False
    reaches_end: bool = False

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


@dataclass(frozen=True)
class StaticTrackBasis:
    """
    The static response of the unloaded track to its masters (:func:`static_track_basis`).

    Attributes
    ----------
    basis : scipy.sparse.csr_matrix
        T_t, (n_free, n_free): non-zero rows at the condensed track DOFs, non-zero
        columns at the masters they rest on.
    cuts : numpy.ndarray
        Free DOFs of the rail nodes over the slab-unit joints (masters, kept in
        every window).
    joints : numpy.ndarray
        Positions of the joints between slab units (m along the track, increasing).

    """

    basis: sp.csr_matrix
    cuts: np.ndarray
    joints: np.ndarray


def slab_joints(structure: Structure) -> np.ndarray:
    """
    Return the positions of the joints between slab units (m, increasing).

    A joint is where consecutive slab elements share no node (a unit ends), with
    or without a gap between them.
    """
    track = structure.track
    if track is None:
        raise ValueError('the reduced track needs a structure with a track')
    slab = track.slab
    joint = np.flatnonzero(slab.dofs[1:, 0] != slab.dofs[:-1, 6])
    end = slab.start[joint] + slab.length[joint]
    return 0.5 * (end + slab.start[joint + 1])


def rail_cuts(structure: Structure, joints: np.ndarray) -> np.ndarray:
    """Return the free DOFs of each rail's node nearest to every joint (sorted)."""
    track = structure.track
    assert track is not None
    cuts = []
    for rail in track.rails:
        x = np.append(rail.start, rail.start[-1] + rail.length[-1])
        nodes = np.vstack([rail.dofs[:, :6], rail.dofs[-1:, 6:]])
        nearest = np.abs(x[None, :] - joints[:, None]).argmin(axis=1)
        cuts.append(structure.full_to_free[nodes[nearest]].ravel())
    cut = np.unique(np.concatenate(cuts)) if cuts else np.zeros(0, dtype=np.intp)
    return cut[cut < structure.n_free]


def static_track_basis(structure: Structure, method: str) -> StaticTrackBasis:
    """
    Return the static response of the unloaded track to the bridge and the rail cuts.

    T_t = -K_tt^-1 K_tm over the track DOFs t other than the rail cuts, the
    masters m being the bridge DOFs (girders, bearings, piers) and the rail
    nodes over the slab-unit joints: where the track would be, with no load on
    it, for a given motion of the masters. The slab units touch each other only
    through the rails, so each unit responds only to the girder below it and
    the cuts at its two ends. Entries below ``BASIS_DROP`` of the largest in
    their column are dropped. A track without joints is condensed whole.
    """
    n_free = structure.n_free
    track_free, _ = track_free_dofs(structure)
    joints = slab_joints(structure)
    cuts = rail_cuts(structure, joints)
    track = np.setdiff1d(track_free[track_free < n_free], cuts)
    is_track = np.zeros(n_free, dtype=bool)
    is_track[track] = True
    masters = np.flatnonzero(~is_track)
    k = structure.stiffness.tocsr()
    k_tt = k[track][:, track].tocsc()
    k_tm = k[track][:, masters].tocsc()
    touched = np.flatnonzero(np.diff(k_tm.indptr))     # masters the track rests on
    if touched.size == 0:
        return StaticTrackBasis(sp.csr_matrix((n_free, n_free)), cuts, joints)
    lu = factorize(k_tt, method=method)
    rows, cols, vals = [], [], []
    for chunk in np.array_split(touched, max(1, touched.size // BASIS_CHUNK)):
        x = -lu.solve(k_tm[:, chunk].toarray())
        peak = np.max(np.abs(x), axis=0)
        r, c = np.nonzero(np.abs(x) > BASIS_DROP * peak)
        rows.append(track[r])
        cols.append(masters[chunk[c]])
        vals.append(x[r, c])
    basis = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n_free, n_free))
    return StaticTrackBasis(basis, cuts, joints)


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


def track_window(structure: Structure, static: StaticTrackBasis, rigid: sp.csr_matrix,
                 start: float, end: float) -> TrackWindow:
    """
    Build the reduction basis with the track detailed between ``start`` and ``end``.

    The ends move out to the nearest slab-unit joints, so that every far unit
    is condensed whole (its statics exact).

    Parameters
    ----------
    structure : Structure
        The assembled track and bridge.
    static : StaticTrackBasis
        :func:`static_track_basis` of the structure.
    rigid : scipy.sparse.csr_matrix
        :func:`rigid_track_basis` of the structure.
    start, end : float
        Ends of the detailed track before widening (m along the track).

    """
    joints = static.joints
    before, after = joints[joints <= start], joints[joints >= end]
    # Beyond the first (last) joint the window takes the track to its end: an end unit cut
    # inside would be condensed in part, onto kept DOFs of its own (a stiff link that the
    # multi-rate exchange does not survive: gain 0.037 at a start 1.3 m before the first
    # joint of paper_ttbi, against 1.1e-4 for every window ending on joints).
    n_free = structure.n_free
    track_free, x = track_free_dofs(structure)
    start = float(before[-1]) if before.size else float(x.min())
    end = float(after[0]) if after.size else float(x.max())
    valid = track_free < n_free
    is_track = np.zeros(n_free, dtype=bool)
    is_track[track_free[valid]] = True
    inside = (x >= start) & (x <= end)
    keep = ~is_track
    keep[track_free[inside][valid[inside]]] = True
    keep[static.cuts] = True
    kept = np.flatnonzero(keep)
    n_red = kept.size
    free_to_red = np.full(n_free + 1, n_red)
    free_to_red[kept] = np.arange(n_red)
    # Kept DOFs: identity rows; far track: its response to the masters (the bridge DOFs
    # and the rail cuts, all kept).
    select = sp.diags((~keep).astype(float))

    def basis(far_motion: sp.csr_matrix) -> sp.csr_matrix:
        coo = (select @ far_motion).tocoo()
        return sp.csr_matrix((np.concatenate([np.ones(n_red), coo.data]),
                              (np.concatenate([kept, coo.row]),
                               np.concatenate([np.arange(n_red), free_to_red[coo.col]]))),
                             shape=(n_free, n_red))

    return TrackWindow(start, end, basis(static.basis), basis(rigid), kept, free_to_red,
                       free_to_red[structure.full_to_free], reaches_start=not before.size,
                       reaches_end=not after.size)


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
    margin : float
        Detailed track kept behind the last axle and ahead of the first (m).

    """

    def __init__(self, car: CarParameters, contact: ContactParameters, n_cars: int,
                 car_length: float, structure: Structure, integrator: Integrator,
                 irregularity: TrackIrregularity | None, margin: float = MARGIN,
                 rail_steps: int = 0) -> None:
        self.margin = float(margin)
        self.rail_steps = int(rail_steps)
        """Rail steps per step of the structure under the rails (multi-rate,
        :class:`~ttb_sim.sim.integrators.multirate.MultiRateNewmark`); 0 = one system."""
        if self.rail_steps:   # refused before anything steps: every window has these links
            fast = fast_track_range(structure)
            slow = np.setdiff1d(np.arange(structure.n_free), np.arange(fast.start, fast.stop))
            check_coupling(structure.mass, structure.damping, structure.stiffness, fast, slow,
                           float(integrator.dt), self.rail_steps)
        super().__init__(car, contact, n_cars, car_length, structure, integrator, irregularity)
        self._contact_min = float(np.min(self.contact_x))
        self._contact_max = float(np.max(self.contact_x))
        self._bridge_load: tuple[np.ndarray, np.ndarray] | None = None
        """The latest :meth:`load_bridge` (free DOFs, values), carried to each window."""
        self._dt = float(integrator.dt)
        self._method = str(integrator.method)
        self.window: TrackWindow | None = None
        self._bases: tuple[StaticTrackBasis, sp.csr_matrix] | None = None
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
        the margin from its ends) are those of the window's
        model up to what the condensed far track changes tens of metres away,
        and the single-solve step checks the exact rail motion under every
        wheel against them. Probing each window's own K^-1 instead would not
        stay local: the condensed far track couples the girder nodes over tens
        of metres (measured: 4.8 -> 17.7 s and 1.9 GiB per window).
        """
        self._full_compliance = super()._rail_compliance(integrator, full_to_free)
        return self._full_compliance

    def _axle_span(self, head: float) -> tuple[float, float]:
        # min(head + x_i) is head + min(x_i) exactly: rounding is monotonic.
        return head + self._contact_min, head + self._contact_max

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
        window = track_window(st, *self._bases, rear - self.margin,
                              front + self.margin + ADVANCE)
        t, local = window.basis, window.local_basis
        mass, damping, stiffness = (project(st.mass, local), project(st.damping, local),
                                    project(st.stiffness, t))
        # check=True: every window's exchange is checked, not only the whole track's at build
        self.nm = (MultiRateNewmark(mass, damping, stiffness, self._dt,
                                    self._fast_dofs(window), self.rail_steps,
                                    method=self._method, check=True)
                   if self.rail_steps else
                   Newmark(mass, damping, stiffness, self._dt, method=self._method, lean=True))
        self.static_stiffness = self.nm.stiffness
        self.n_free = window.size
        ftr = window.full_to_reduced
        self.rail_dofs = tuple(ftr[r.dofs] for r in self.rails)
        self.compliance = self._full_compliance.restricted(window.free_to_reduced, window.size)
        self.u, self.v, self.a = (s[window.kept].copy() for s in state)
        self.window = window
        self._apply_bridge_load()
        self.window_moves += 1
        self.window_time += time.process_time() - begin
        log.debug('track window %.1f .. %.1f m: %d of %d DOFs', window.start, window.end,
                  window.size, st.n_free)

    def _fast_dofs(self, window: TrackWindow) -> np.ndarray:
        """Return the window's rail and slab DOFs (reduced numbering): the fast partition."""
        reduced = window.full_to_reduced[rail_and_slab_dofs(self.structure)]
        return np.unique(reduced[reduced < window.size])

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
        window = self.window
        due = ((front + self.margin > window.end and not window.reaches_end)
               or (rear < window.start and not window.reaches_start))
        if due and self.nm.at_slow_step:
            self._move_window(head)
        super().step(head, speed)

    def bridge_state(self, dofs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return (u, v) at free bridge DOFs ``dofs``: every bridge DOF is a window DOF."""
        assert self.window is not None, 'start() first'
        solved = self.window.free_to_reduced[dofs]
        return self.u[solved], self.v[solved]

    def load_bridge(self, dofs: np.ndarray, values: np.ndarray) -> None:
        """Add ``values`` at free bridge DOFs ``dofs`` to the next step's load (any window)."""
        self._bridge_load = (dofs, values)
        self._apply_bridge_load()

    def _apply_bridge_load(self) -> None:
        if self._bridge_load is not None and self.window is not None:
            dofs, values = self._bridge_load
            self.nm.external = (self.window.free_to_reduced[dofs], values)

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
