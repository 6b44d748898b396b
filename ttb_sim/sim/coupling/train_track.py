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
Train-track-bridge interaction: multibody cars on the rails, solved in each step.

Both subsystems use Newmark's average-acceleration method with constant
effective matrices: the track-bridge matrix K + 2/dt C + 4/dt^2 M (sparse,
factorised once) and, per car, A = K + 2/dt (C + G(V)) + 4/dt^2 M (42 x 42,
inverted once per speed). At the end of a step both states are affine in the
contact forces g = (Fx, Fy, Fz, Mz) of the 8 wheels of every car (force of the
rail on the wheel, track axes):

* wheel contact points: w = w* + H A^-1 H^T g (exact, per car);
* rail head under each wheel: r = r* - R K^-1 R^T g. The effective track matrix
  is dominated by 4/dt^2 M, so its inverse is local: the rail's compliance at a
  wheel is the 12 x 12 block of K^-1 over the rail element under it (computed
  once by probing), and wheels (>= 2.5 m apart) do not see each other inside
  one step. The rail element under a wheel also deflects within itself, beyond
  what its nodes' cubic interpolation carries: r gets - C_i g, C_i the
  element's interior flexibility at the wheel (the element clamped at its
  nodes, :func:`ttb_sim.fe.beam.interior_compliance`; its velocity follows by
  the trapezoidal rule). Without it the rail would be too stiff under a wheel
  between its nodes, and the wheel would feel that at the element-passing
  frequency V / L_e: mainly in the lateral force, through the rail's twist,
  which the elements interpolate linearly. With it the static rail-head motion
  under a wheel is the same on any rail mesh.

The contact laws close the system, all at the end of the step: Hertz's normal
force on the vertical compression, the contact geometry (rolling radius,
contact angle and rigid-contact wheel height from the profile table at the
wheelset's lateral position relative to the rail; the compression is measured
from that height, which stays continuous when the contact jumps to the flange)
and Kalker's linear creep forces on the creepages, which are affine in the
end-of-step velocities, saturated by the Shen-Hedrick-Elkins law. A Newton
iteration solves them (with the derivatives of the geometry and of the
saturation); only the load scaling of the creep coefficients is taken from the
previous step (an explicit lag of O(dt)).
After the Newton iteration the track is solved exactly with those forces and
the rail displacement under every wheel is compared with the local prediction;
any mismatch above ``contact.tolerance`` is fed back and the iteration
repeated, so each step's contact forces satisfy the contact laws on the exact
track response to that tolerance.

The lean solver variants take the same step compiled when numba is installed
(:mod:`ttb_sim.sim.contact_kernels`) and solve the track once per step instead
of twice: the predictor's rail motion under the wheels comes from each rail
node's K^-1 columns on the DOFs near it (probed once, with the compliance
blocks), the contact is iterated on it and the track solved for predictor and
contact loads together; the exact rail motion then corrects the offsets as
above, and the step is accepted when all three components agree to the
tolerance. ``reference`` keeps the numpy step with two solves.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import math
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import DivergenceError, ModelError
from ttb_sim.fe.beam import interior_compliance
from ttb_sim.fe.factorization import factorize
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.irregularity import GRID_SLACK, TrackIrregularity
from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.vehicle.dofs import dofs as car_dofs
from ttb_sim.model.vehicle.matrices import gyroscopic_matrix, train_matrices
import ttb_sim.model.wheel_rail as ct
from ttb_sim.model.wheel_rail.contact_parameters import ContactParameters
from ttb_sim.model.wheel_rail.contact_table import contact_geometry_table, ContactGeometryTable
from ttb_sim.sim import kernels
from ttb_sim.sim.coupling.base import FreeDofState, VehicleOutputs
from ttb_sim.sim.integrators.protocol import Integrator
from ttb_sim.sim.lean import point_rows_and_slopes

log = logging.getLogger(__name__)

PROBE_SPACING = 24
"""Rail nodes between simultaneous probes of the local track compliance."""
COMPONENTS = 4
"""Contact force components per wheel: Fx, Fy, Fz (on the wheel), Mz (spin moment)."""
GEOMETRY_STEP = 1e-6
"""Lateral step (m) of the central difference of the rigid-contact wheel height."""
INFLUENCE_HOPS = 10
"""Couplings of the effective track matrix over which the single-solve step keeps each
rail node's K^-1 columns (measured on paper_ttbi: the columns fall to 3e-7 of their peak
8 couplings away, 3e-15 at 10)."""
INFLUENCE_PROBE_DISTANCE = 30.0
"""Least distance (m) between simultaneous probes when the K^-1 columns are kept: the
probes' responses reach each other through the slab and the girders. Measured error of
the predictor's rail motion under the wheels: paper_ttbi (0.31 m rail elements) 2e-7 m
with probes 15 m apart, 4e-12 m at 30 m; a one-span model (0.6 m) 8e-8 m at 15 m,
9e-13 m at 29 m."""
INFLUENCE_DROP = 1e-12
"""Entries of a node's K^-1 columns below this fraction of their largest are dropped
(on a one-span model 590 of 1 870 DOFs kept per node on average)."""


def gather(vector: np.ndarray, index: np.ndarray) -> np.ndarray:
    """
    Return ``vector`` extended by one zero (the ground slot) at extended free indices.

    Equal to ``np.append(vector, 0.0)[index]`` without copying the whole vector.
    """
    n = vector.shape[0]
    return np.where(index < n, vector[np.minimum(index, n - 1)], 0.0)


def rail_section_columns(rail: BeamLine) -> np.ndarray:
    """Return a rail's (n_el, 4) EA, GJ, EI_y, EI_z, for its interior flexibility."""
    sec = rail.section
    assert sec is not None, 'the rails carry their sections (build_track)'
    return np.ascontiguousarray(np.column_stack([sec.ea, sec.gj, sec.ei_y, sec.ei_z]),
                                dtype=float)


@dataclass(frozen=True)
class ContactState:
    """Contact quantities of every wheel at the end of a step, shape (n_cars, 8, ...)."""

    force: np.ndarray
    """(n_cars, 8, 4) Fx, Fy, Fz (N) and Mz (N m) of the rail on the wheel."""
    compression: np.ndarray
    """(n_cars, 8) Hertz compression (m)."""
    iterations: int
    """Newton iterations of the step (all cars)."""


@dataclass(frozen=True)
class ContactKernels:
    """The compiled kernels of the contact step (:mod:`ttb_sim.sim.contact_kernels`)."""

    rail_rows: Callable[..., Any]
    rail_values: Callable[..., Any]
    rail_load: Callable[..., Any]
    contact_newton: Callable[..., Any]
    rail_predictor: Callable[..., Any]
    rail_irregularity: Callable[..., Any]
    contact_setup: Callable[..., Any]
    rail_check: Callable[..., Any]

    @classmethod
    def load(cls) -> ContactKernels | None:
        """Return the compiled kernels, or None without numba (the numpy step runs)."""
        found = []
        for name in ('rail_rows', 'rail_values', 'rail_load', 'contact_newton',
                     'rail_predictor', 'rail_irregularity', 'contact_setup', 'rail_check'):
            kernel = kernels.compiled(name)
            if kernel is None:
                return None
            found.append(kernel)
        return cls(*found)


class RailCompliance:
    """
    Local blocks of the inverse effective track matrix over each rail element.

    Parameters
    ----------
    integrator : Integrator
        The factorised track-bridge system.
    rails : tuple of BeamLine
        Left and right rail (full DOFs).
    full_to_free : numpy.ndarray
        Extended free index of each full DOF.
    influence_hops : int, optional
        Also keep each rail node's K^-1 columns (its 6 DOFs) on the DOFs within
        this many couplings of the node in the effective matrix, where they
        exceed INFLUENCE_DROP of their largest (from the same probes, spaced
        INFLUENCE_PROBE_DISTANCE apart so that they do not disturb each other):
        :attr:`influence`. None (the reference) keeps only the blocks.

    """

    def __init__(self, integrator: Integrator, rails: tuple[BeamLine, ...],
                 full_to_free: np.ndarray, influence_hops: int | None = None) -> None:
        n_free = integrator.mass.shape[0]
        self.blocks = []
        self.influence: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        """Per rail: (start (n_nodes + 1,), DOFs (nnz,), values (nnz, 6)): node i's
        K^-1 columns on the DOFs ``dofs[start[i]:start[i + 1]]``."""
        for rail in rails:
            spacing = PROBE_SPACING
            if influence_hops is not None:
                spacing = max(spacing, math.ceil(INFLUENCE_PROBE_DISTANCE / rail.length.min()))
            dofs = full_to_free[rail.dofs]                     # (n_el, 12)
            nodes = np.vstack([dofs[:, :6], dofs[-1:, 6:]])    # (n_nodes, 6)
            n_nodes = nodes.shape[0]
            columns = _Columns(n_nodes)
            reach = sp.csc_matrix((n_free, n_nodes))
            if influence_hops is not None:
                reach = neighbourhoods(integrator, nodes, influence_hops)
            # cols[i, j, :] = K^-1 column of node i, DOF j, restricted to nodes i-1..i+1.
            local = np.zeros((n_nodes, 6, 3, 6))
            for offset in range(spacing):
                probe = np.arange(offset, n_nodes, spacing)
                rhs = np.zeros((n_free + 1, 6))
                for j in range(6):
                    rhs[nodes[probe, j], j] = 1.0
                sol = np.vstack([integrator.solve(rhs[:n_free]), np.zeros((1, 6))])
                if influence_hops is not None:
                    for p in probe.tolist():
                        near = reach.indices[reach.indptr[p]:reach.indptr[p + 1]]
                        columns.add(p, near, sol)
                for k, shift in enumerate((-1, 0, 1)):
                    at = np.clip(probe + shift, 0, n_nodes - 1)
                    local[probe, :, k, :] = sol[nodes[at]].transpose(0, 2, 1)
            # Element block B[e] over (node e, node e+1) x (node e, node e+1).
            n_el = n_nodes - 1
            b = np.zeros((n_el, 12, 12))
            e = np.arange(n_el)
            b[:, :6, :6] = local[e, :, 1, :].transpose(0, 2, 1)
            b[:, 6:, :6] = local[e, :, 2, :].transpose(0, 2, 1)
            b[:, :6, 6:] = local[e + 1, :, 0, :].transpose(0, 2, 1)
            b[:, 6:, 6:] = local[e + 1, :, 1, :].transpose(0, 2, 1)
            self.blocks.append(0.5 * (b + b.transpose(0, 2, 1)))
            if influence_hops is not None:
                self.influence.append(columns.arrays())

    def restricted(self, free_to_kept: np.ndarray, n_kept: int) -> RailCompliance:
        """
        Return this compliance on a subset of the free DOFs (a reduced model's).

        The element blocks stay as they are (they are indexed by rail element);
        each node's K^-1 columns keep their entries on kept DOFs, renumbered.
        Used where the kept DOFs solve the same model near the rails (the
        reduced track's window): the columns then differ only by what the
        condensed DOFs far away change, and the single-solve step's check
        corrects the rest.

        Parameters
        ----------
        free_to_kept : numpy.ndarray
            (n_free + 1,) the new index of each free DOF (and of the ground slot);
            ``n_kept`` where the DOF is not kept.
        n_kept : int
            Number of kept DOFs.

        """
        out = RailCompliance.__new__(RailCompliance)
        out.blocks = self.blocks
        out.influence = []
        for start, dofs, values in self.influence:
            new = free_to_kept[dofs]
            keep = new < n_kept
            node = np.repeat(np.arange(start.size - 1), np.diff(start))[keep]
            counts = np.bincount(node, minlength=start.size - 1)
            out.influence.append((np.concatenate([[0], np.cumsum(counts)]).astype(np.intp),
                                  new[keep].astype(np.intp),
                                  np.ascontiguousarray(values[keep])))
        return out


class _Columns:
    """Each rail node's K^-1 columns on its neighbourhood, the small entries dropped."""

    def __init__(self, n_nodes: int) -> None:
        self._dofs: list[np.ndarray] = [np.zeros(0, dtype=np.intp)] * n_nodes
        self._values: list[np.ndarray] = [np.zeros((0, 6))] * n_nodes

    def add(self, node: int, near: np.ndarray, solution: np.ndarray) -> None:
        """Keep the probe solution (n_free + 1, 6) of ``node`` on its DOFs ``near``."""
        values = solution[near]
        keep = np.any(np.abs(values) >= INFLUENCE_DROP * np.abs(values).max(), axis=1)
        self._dofs[node] = near[keep].astype(np.intp)
        self._values[node] = values[keep]

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return (start (n_nodes + 1,), DOFs (nnz,), values (nnz, 6)), node after node."""
        counts = [d.size for d in self._dofs]
        start = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
        return (start, np.concatenate(self._dofs),
                np.ascontiguousarray(np.concatenate(self._values)))


def neighbourhoods(integrator: Integrator, nodes: np.ndarray, hops: int) -> sp.csc_matrix:
    """
    Return the free DOFs within ``hops`` couplings of each node: column i holds node i's.

    Couplings are the non-zeros of the effective matrix (K, C, M).
    """
    n_free = integrator.mass.shape[0]
    pattern = (abs(integrator.stiffness) + abs(integrator.damping)
               + abs(integrator.mass)).tocsr()
    pattern.data[:] = 1.0
    n_nodes = nodes.shape[0]
    valid = nodes < n_free
    cols = np.repeat(np.arange(n_nodes), 6)[valid.ravel()]
    reach = sp.csr_matrix((np.ones(cols.size), (nodes.ravel()[valid.ravel()], cols)),
                          shape=(n_free, n_nodes))
    for _ in range(hops):
        reach = pattern @ reach + reach
        reach.data[:] = 1.0
    reach = reach.tocsc()
    reach.sort_indices()
    return reach


class TrainTrackCoupling(FreeDofState):
    """
    State and coupled step of multibody cars running on the slab track.

    Parameters
    ----------
    car : CarParameters
        The car record (every car of the train alike).
    contact : ContactParameters
        Wheel-rail contact settings.
    n_cars, car_length
        Cars in the train and their length over couplers (m).
    structure : Structure
        The assembled track and bridge (with ``structure.track``).
    integrator : Integrator
        The track-bridge integrator (its dt is the step).
    irregularity : TrackIrregularity or None
        The track's irregularity (None = smooth).

    """

    n_axles = 4

    def __init__(self, car: CarParameters, contact: ContactParameters, n_cars: int,
                 car_length: float, structure: Structure, integrator: Integrator,
                 irregularity: TrackIrregularity | None) -> None:
        self.contact = contact
        self.structure = structure
        self.nm = integrator
        self.irregularity = irregularity
        self.params = car
        p = self.params
        tm = train_matrices(p, n_cars, car_length)
        self.n_cars = tm.n_cars
        self.n_bodies = self.n_cars
        n = self.n_cars
        self.mass = tm.mass[:42, :42].toarray()
        self.damping = tm.damping[:42, :42].toarray()
        self.stiffness = tm.stiffness[:42, :42].toarray()
        self.gravity = tm.gravity[:42].copy()
        h = np.zeros((8, COMPONENTS, 42))
        h[:, 0] = tm.hx[:8, :42].toarray()
        h[:, 1] = tm.hy[:8, :42].toarray()
        h[:, 2] = tm.hz[:8, :42].toarray()
        h[:, 3] = tm.hyaw[:8, :42].toarray()
        self.h = h.reshape(8 * COMPONENTS, 42)
        self.contact_x = tm.contact_x.reshape(n, 8)
        self.side = tm.contact_side.reshape(n, 8)
        self.r0 = p.wheel_radius
        cc = contact
        self.g_hertz = float(ct.hertz_constant(p.wheel_radius, cc.tread))
        self.friction = cc.friction
        self.p0 = p.static_wheel_load
        ellipse = ct.hertz_ellipse(self.p0, p.wheel_radius)
        self.creep0 = ct.creep_coefficients(ellipse.a, ellipse.b)
        self._creep0 = np.array(self.creep0, dtype=float)
        self.table: ContactGeometryTable | None = (
            contact_geometry_table() if cc.geometry == 'profiles' else None)
        self._tables = self._geometry_tables()
        """The profile table's columns for the compiled step (constant)."""
        track = structure.track
        if track is None:
            raise ModelError('multibody cars need the slab track: the structure has none')
        self.rails = track.rails
        self.head_arm = np.array([0.0, 0.0, track.rail_head])
        self._rail_sections = tuple(rail_section_columns(r) for r in self.rails)
        """Each rail's (n_el, 4) EA, GJ, EI_y, EI_z, for the interior flexibility."""
        ftf = structure.full_to_free
        self.rail_dofs = tuple(ftf[r.dofs] for r in self.rails)
        self._kernels = ContactKernels.load() if getattr(integrator, 'lean', False) else None
        """The compiled contact step (lean variants with numba), else None (numpy step)."""
        self.influence_hops = INFLUENCE_HOPS if self._kernels is not None else None
        """Reach of the local K^-1 columns of the single-solve step; None: two solves."""
        self.compliance = self._rail_compliance(integrator, ftf)
        self._no_load = np.zeros(structure.n_full)   # read-only, shared by every frame
        self._speed = math.nan
        self.tol = cc.tolerance
        self.max_iter = cc.max_iterations
        n_free = self.n_free = structure.n_free
        """Size of the solved track-bridge state (all free DOFs here)."""
        self.static_stiffness = structure.stiffness
        """Stiffness of the solved state, for the static equilibrium."""
        self.u = np.zeros(n_free)
        self.v = np.zeros(n_free)
        self.a = np.zeros(n_free)
        self.q = np.zeros((n, 42))
        self.qv = np.zeros((n, 42))
        self.qa = np.zeros((n, 42))
        self.force = np.zeros((n, 8, COMPONENTS))
        self.compression = np.zeros((n, 8))
        self.saturation = np.ones((n, 8))
        self.iterations = 0
        self._rail_y = np.zeros((n, 8))
        self._rail_offset = np.zeros((n, 8, COMPONENTS))
        self._wheelset_y = 6 * np.repeat(np.arange(3, 7), 2) + 1
        self._slope_offset = np.zeros((n, 8, 3))
        self._interior = np.zeros((n, 8, 3))
        """Interior deflection of the rail element under each wheel (m), :meth:`_rail_rows`."""
        self._interior_v = np.zeros((n, 8, 3))
        """Its velocity by the trapezoidal rule (m/s)."""
        self.solves = 0
        """Track solves of the last step."""
        self._zero = np.zeros(n_free)
        self._work: dict[str, np.ndarray] = {}

    def _rail_compliance(self, integrator: Integrator,
                         full_to_free: np.ndarray) -> RailCompliance:
        """Return the local rail compliance blocks of the solved system."""
        return RailCompliance(integrator, self.rails, full_to_free, self.influence_hops)

    # -- geometry and kinematics ---------------------------------------------------------
    def _rail_rows(self, x: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """
        Return rail-head rows R, R' (n_cars, 8, 3, 12), ext-free DOFs, B blocks and C_i.

        C_i (n_cars, 8, 3, 3) is the interior flexibility of the rail element under
        each wheel (:func:`ttb_sim.fe.beam.interior_compliance`): the rail head
        under a wheel moves by R u - C_i F for the force F the wheel puts on it.
        """
        shape = x.shape
        xi = np.zeros(shape)
        length = np.zeros(shape)
        dofs = np.zeros(shape + (12,), dtype=int)
        blocks = np.zeros(shape + (12, 12))
        interior = np.zeros(shape + (3, 3))
        for r, side in enumerate((1.0, -1.0)):
            sel = self.side == side
            rail = self.rails[r]
            element, xi[sel], inside = rail.locate(x[sel])
            if not np.all(inside):
                raise DivergenceError('a wheel ran off the modelled track at x = '
                                      f'{x[sel][~inside][0]:.2f} m; the run is longer than '
                                      'the track (check solver.duration)')
            length[sel] = rail.length[element]
            dofs[sel] = self.rail_dofs[r][element]
            blocks[sel] = self.compliance.blocks[r][element]
            sec = self._rail_sections[r][element]
            interior[sel] = interior_compliance(xi[sel], length[sel], sec[:, 0], sec[:, 1],
                                                sec[:, 2], sec[:, 3], float(self.head_arm[2]))
        # Rows and slopes of both rails in one evaluation (elementwise, so the same numbers).
        rows, slope = point_rows_and_slopes(xi.ravel(), length.ravel(), self.head_arm)
        return (rows.reshape(shape + (3, 12)), slope.reshape(shape + (3, 12)), dofs, blocks,
                interior)

    def _irregularity(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return vertical and lateral rail irregularity and lateral slope under each wheel."""
        z = np.zeros_like(x)
        y = np.zeros_like(x)
        dy = np.zeros_like(x)
        if self.irregularity is None:
            return z, y, dy
        s = self.irregularity.sample(x, outside='zero')
        left = self.side > 0
        z = np.where(left, s.value[0], s.value[1])
        y = np.where(left, s.value[2], s.value[3])
        dy = np.where(left, s.slope[2], s.slope[3])
        return z, y, dy

    def _geometry(self, lateral: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return rolling radius, contact angle and rigid-contact height of each wheel.

        The height (m, up) is where the wheel's contact point would sit on rigid
        rails at this relative shift (:meth:`ContactGeometryTable.wheel_height`);
        with the conicity model it is r - r0 (knife-edge rails).
        """
        if self.table is not None:
            g = self.table.wheelset_geometry(lateral)
            h = self.table.wheel_height(lateral, self.params.contact_semi_distance)
        else:
            g = ct.simplified_geometry(lateral, self.contact.conicity, self.r0)
            h = g.rolling_radius - self.r0
        left = self.side > 0
        radius = np.where(left, g.rolling_radius[..., 0], g.rolling_radius[..., 1])
        angle = np.where(left, g.contact_angle[..., 0], g.contact_angle[..., 1])
        height = np.where(left, h[..., 0], h[..., 1])
        return radius, angle, height

    # -- train matrices -----------------------------------------------------------------
    def _update_speed(self, speed: float) -> None:
        if speed == self._speed:
            return
        nm = self.nm
        damping = self.damping + gyroscopic_matrix(self.params, speed)
        self.train_damping = damping
        eff = self.stiffness + nm.a1 * damping + nm.a0 * self.mass
        self.a_inv = np.linalg.inv(eff)
        self.dw = self.h @ self.a_inv @ self.h.T
        self.ey = (self.a_inv @ self.h.T)[self._wheelset_y]
        self._speed = speed

    # -- static equilibrium -------------------------------------------------------------
    def equilibrium(self, head: float) -> None:
        """
        Put train and track in static equilibrium under gravity at a head position.

        Vertical problem only (the train is symmetric and the track straight):
        Newton on the car DOFs and the wheel loads, with the exact static track
        flexibility under the wheels (one static factorisation, one solve per wheel).
        The wheelsets stand centred on the track; vertical irregularity and the
        rigid-contact height change caused by lateral irregularity are included.
        """
        n = self.n_cars
        x = head + self.contact_x
        rows, _, dofs, _, interior = self._rail_rows(x)
        irr_z, irr_y, _ = self._irregularity(x)
        # The wheelsets start centred on the track (y = 0): with lateral irregularity
        # the rails are shifted under them, which raises or lowers each wheel's
        # rigid-contact height; the static loads and attitude take that in.
        irr_z = irr_z + self._geometry(-irr_y)[2]
        n_free = self.n_free
        m = 8 * n
        lu = factorize(self.static_stiffness, method=self.nm.method)
        rhs = np.zeros((n_free + 1, m))
        flat = dofs.reshape(m, 12)
        rz = rows[..., 2, :].reshape(m, 12)
        rhs[flat, np.arange(m)[:, None]] = rz
        zcol = np.vstack([lu.solve(rhs[:n_free]), np.zeros((1, m))])
        flex = np.einsum('ik,ikj->ij', rz, zcol[flat])     # r_z = -flex @ P
        flex[np.diag_indices(m)] += interior[..., 2, 2].ravel()
        # Vertical subproblem: z, roll, pitch of body and bogies; z, roll of the
        # wheelsets (their pitch is the free spin).
        sub = np.sort(np.concatenate([car_dofs(range(3), ['z', 'roll', 'pitch']),
                                      car_dofs(range(3, 7), ['z', 'roll'])]))
        k_sub = self.stiffness[np.ix_(sub, sub)]
        hz = self.h.reshape(8, COMPONENTS, 42)[:, 2][:, sub]      # (8, n_sub)
        g_sub = self.gravity[sub]
        n_sub = sub.size
        q = np.zeros((n, n_sub))
        load = np.full(m, self.p0)
        # Below a quarter of the static compression the Hertz law is continued by its
        # tangent, so that Newton starts from an unloaded train; the converged state
        # lies on the Hertz law itself.
        d_min = 0.25 * float(ct.static_compression(self.p0, self.g_hertz))
        f_min = float(ct.normal_force(d_min, self.g_hertz))
        k_min = float(ct.normal_force_derivative(d_min, self.g_hertz))
        for _ in range(60):
            w = np.einsum('ks,cs->ck', hz, q).ravel()
            delta = -flex @ load + irr_z.ravel() - w
            low = delta < d_min
            f = np.where(low, f_min + k_min * (delta - d_min),
                         ct.normal_force(np.maximum(delta, d_min), self.g_hertz))
            kh = np.where(low, k_min,
                          ct.normal_force_derivative(np.maximum(delta, d_min), self.g_hertz))
            # Residuals: K q - hz^T P - g = 0 ; P - f(delta) = 0.
            r1 = (q @ k_sub.T) - np.einsum('ks,ck->cs', hz, load.reshape(n, 8)) - g_sub
            r2 = load - f
            size = n * n_sub + m
            jac = np.zeros((size, size))
            for c in range(n):
                s = slice(c * n_sub, (c + 1) * n_sub)
                jac[s, s] = k_sub
                jac[s, n * n_sub + 8 * c:n * n_sub + 8 * c + 8] = -hz.T
                rows_c = slice(n * n_sub + 8 * c, n * n_sub + 8 * c + 8)
                jac[rows_c, s] = kh[8 * c:8 * c + 8, None] * hz
            jac[n * n_sub:, n * n_sub:] = np.eye(m) + kh[:, None] * flex
            step = np.linalg.solve(jac, -np.concatenate([r1.ravel(), r2]))
            dq = step[:n * n_sub].reshape(n, n_sub)
            dload = step[n * n_sub:]
            q += dq
            load += dload
            # Converged when both the loads and the compressions have settled (on a
            # symmetric car the loads are right from the start; the compressions not).
            d_delta = -flex @ dload - np.einsum('ks,cs->ck', hz, dq).ravel()
            if (np.max(np.abs(dload)) < 1e-6 * self.p0
                    and np.max(np.abs(d_delta)) < 1e-6 * d_min):
                break
        else:
            raise DivergenceError('static equilibrium of the train on the track did not '
                                  'converge in 60 Newton iterations')
        self.q[:, sub] = q
        self.qv[:] = 0.0
        self.qa[:] = 0.0
        self.u = -(zcol[:n_free] @ load)
        self.v[:] = 0.0
        self.a[:] = 0.0
        self.force[:] = 0.0
        self._rail_offset[:] = 0.0
        self._slope_offset[:] = 0.0
        self.force[..., 2] = load.reshape(n, 8)
        self._interior = -interior[..., 2] * self.force[..., 2:3]
        self._interior_v = np.zeros((n, 8, 3))
        w = np.einsum('ks,cs->ck', hz, q)
        self.compression = (-(flex @ load) + irr_z.ravel() - w.ravel()).reshape(n, 8)
        self.saturation[:] = 1.0
        log.info('static equilibrium: wheel loads %.1f .. %.1f kN', load.min() / 1e3,
                 load.max() / 1e3)

    def _check_flange(self, lateral: np.ndarray) -> None:
        """Raise DivergenceError when a wheelset runs beyond the contact-geometry table."""
        if self.table is None:
            return
        limit = float(self.table.lateral[-1])
        beyond = np.abs(lateral) > limit
        if np.any(beyond):
            car, wheel = np.argwhere(beyond)[0]
            shift = lateral[car, wheel] * 1e3
            raise DivergenceError(
                f'wheelset {wheel // 2 + 1} of car {car + 1} shifted {shift:.1f} mm relative '
                f'to the rail, beyond the {limit * 1e3:.0f} mm of the contact-geometry '
                'table: the flange is climbing the rail (derailment). Usually the '
                'car hunts at this speed; check car.yaw_dampers and car.yaw_damping')

    def _accept_interior(self, interior: np.ndarray, force: np.ndarray, a1: float) -> None:
        """Take the end-of-step interior deflection under the wheels and its velocity."""
        now = -np.einsum('cwij,cwj->cwi', interior, force[..., :3])
        self._interior_v = a1 * (now - self._interior) - self._interior_v
        self._interior = now

    # -- one step -------------------------------------------------------------------------
    def step(self, head: float, speed: float) -> None:
        """Advance train, track and bridge together to the head position ``head``."""
        if self._kernels is not None:
            self._step_compiled(head, speed, self._kernels)
        else:
            self._step_numpy(head, speed)

    def _step_numpy(self, head: float, speed: float) -> None:
        """Take the step with numpy (the reference path, and the lean path without numba)."""
        self._update_speed(speed)
        nm, n = self.nm, self.n_cars
        n_free = self.n_free
        x = head + self.contact_x
        rows, slope, dofs, blocks, interior = self._rail_rows(x)
        irr_z, irr_y, irr_dy = self._irregularity(x)

        # Predictors (no contact force).
        h_v, h_a = nm.history(self.u, self.v, self.a)
        u_star = nm.solve(nm.effective_load(np.zeros(n_free), h_v, h_a))
        u_dofs = gather(u_star, dofs)
        r_star = np.einsum('cwij,cwj->cwi', rows, u_dofs)
        rs_star = np.einsum('cwij,cwj->cwi', slope, u_dofs)
        r_hist = np.einsum('cwij,cwj->cwi', rows, gather(h_v, dofs))
        a0, a1 = nm.a0, nm.a1
        qh_v = -a1 * self.q - self.qv
        qh_a = -a0 * self.q - 2.0 * a1 * self.qv - self.qa
        rhs_t = self.gravity - qh_a @ self.mass.T - qh_v @ self.train_damping.T
        q_star = rhs_t @ self.a_inv.T
        w_star = (q_star @ self.h.T).reshape(n, 8, COMPONENTS)
        w_hist = (qh_v @ self.h.T).reshape(n, 8, COMPONENTS)

        # Local rail compliance: r = r* - Dr g_xyz, r' = r'* - Ds g_xyz; the rail head
        # under a wheel also deflects within its element (Dr includes that, C_i).
        dr = np.einsum('cwij,cwjk,cwlk->cwil', rows, blocks, rows) + interior
        ds = np.einsum('cwij,cwjk,cwlk->cwil', slope, blocks, rows)

        # Creep coefficients scaled with the previous step's normal load.
        normal = np.maximum(self.force[..., 2], 0.0)
        f11, f22, f23, f33 = ct.scale_creep_coefficients(self.creep0, self.p0, normal)
        side = self.side

        # Affine maps of the end-of-step quantities in g (per car, 32 unknowns).
        m = 8 * COMPONENTS
        eye = np.eye(m)
        dwm = np.broadcast_to(self.dw, (n, m, m))                # wheel: w = w* + Dw g
        rail_disp = np.zeros((n, m, m))                          # rail: r = r* - Rm g
        rail_vel = np.zeros((n, m, m))
        idx = np.arange(8) * COMPONENTS
        for i in range(3):
            for j in range(3):
                rail_disp[:, idx + i, idx + j] = dr[..., i, j]
                rail_vel[:, idx + i, idx + j] = a1 * dr[..., i, j] + speed * ds[..., i, j]
        w0 = w_star.reshape(n, m)
        wv0 = a1 * w0 + w_hist.reshape(n, m)
        r0p = np.zeros((n, 8, COMPONENTS))
        r0p[..., :3] = r_star
        rv0 = np.zeros((n, 8, COMPONENTS))
        # The interior deflection's velocity continues by the trapezoidal rule.
        rv0[..., :3] = (a1 * r_star + r_hist + speed * rs_star
                        - a1 * self._interior - self._interior_v)
        # Start from the last step's correction of the local rail model: it is what the
        # local blocks leave out (coupling of wheels through slab and girder) and
        # changes little from step to step, so one exact solve usually suffices.
        offset = self._rail_offset.copy()
        # Sensitivities of compression and creepages to g (constant within the step).

        def part(mat: np.ndarray, k: int) -> np.ndarray:
            return mat.reshape(n, 8, COMPONENTS, m)[:, :, k]

        def value(vec: np.ndarray, k: int) -> np.ndarray:
            return vec.reshape(n, 8, COMPONENTS)[..., k]

        # Wheelset lateral displacement: y = y* + Ey g (for the contact geometry).
        y_star = q_star[:, self._wheelset_y]
        d_yrel = self.ey[None] + part(rail_disp, 1)
        d_delta0 = -part(rail_disp, 2) - part(dwm, 2)
        d_xi_x = (a1 * part(dwm, 0) + part(rail_vel, 0)) / speed
        d_xi_y = (a1 * part(dwm, 1) + part(rail_vel, 1)) / speed - part(dwm, 3)
        g = self.force.reshape(n, m).copy()
        total_iter = 0
        change = math.inf
        for _outer in range(self.max_iter):
            rp = (r0p + offset).reshape(n, m)
            rvp = (rv0 + a1 * offset).reshape(n, m)
            for _ in range(self.max_iter):
                total_iter += 1
                w = w0 + np.einsum('cij,cj->ci', dwm, g)
                wv = wv0 + a1 * np.einsum('cij,cj->ci', dwm, g)
                r = rp - np.einsum('cij,cj->ci', rail_disp, g)
                rv = rvp - np.einsum('cij,cj->ci', rail_vel, g)
                # Contact geometry at the end-of-step lateral position.
                y_rel = y_star + np.einsum('wj,cj->cw', self.ey, g) - value(r, 1) - irr_y
                # Geometry at y and y +/- GEOMETRY_STEP in one (elementwise) evaluation.
                radii, angles, heights = self._geometry(
                    np.stack([y_rel, y_rel + GEOMETRY_STEP, y_rel - GEOMETRY_STEP]))
                radius, angle, angle_hi, angle_lo = radii[0], angles[0], angles[1], angles[2]
                height, height_hi, height_lo = heights
                height_slope = (height_hi - height_lo) / (2 * GEOMETRY_STEP)
                tan_slope = (np.tan(angle_hi) - np.tan(angle_lo)) / (2 * GEOMETRY_STEP)
                cosg, sing, tan_g = np.cos(angle), np.sin(angle), np.tan(angle)
                d_delta = d_delta0 + height_slope[..., None] * d_yrel
                d_xi_sp = a1 * part(dwm, 3) * cosg[..., None] / speed
                delta = value(r, 2) + irr_z - value(w, 2) + height
                fz = ct.normal_force(delta, self.g_hertz)
                kh = ct.normal_force_derivative(delta, self.g_hertz)
                xi_x = (value(wv, 0) - value(rv, 0)) / speed + 1.0 - radius / self.r0
                xi_y = (value(wv, 1) - value(rv, 1) - speed * irr_dy) / speed - value(w, 3)
                xi_sp = value(wv, 3) * cosg / speed - side * sing / self.r0
                # Kalker's linear creep forces, saturated (Shen-Hedrick-Elkins) at this
                # iterate; the Jacobian includes the derivative of the factor.
                lin_x = -f11 * xi_x
                lin_y = -(f22 * xi_y + f23 * xi_sp)
                lin_m = f23 * xi_y - f33 * xi_sp
                fx, fy, mz, eps = ct.she_saturation(lin_x, lin_y, lin_m, fz, self.friction)
                d_lin_x = -f11[..., None] * d_xi_x
                d_lin_y = -f22[..., None] * d_xi_y - f23[..., None] * d_xi_sp
                d_lin_m = f23[..., None] * d_xi_y - f33[..., None] * d_xi_sp
                e_x, e_y, e_n = ct.she_factor_gradient(lin_x, lin_y, fz, self.friction)
                d_eps = (e_x[..., None] * d_lin_x + e_y[..., None] * d_lin_y
                         + (e_n * kh)[..., None] * d_delta)
                creep_x = eps[..., None] * d_lin_x + lin_x[..., None] * d_eps
                creep_y = eps[..., None] * d_lin_y + lin_y[..., None] * d_eps
                creep_m = eps[..., None] * d_lin_m + lin_m[..., None] * d_eps
                fy = fy - side * tan_g * fz
                target = np.stack([fx, fy, fz, mz], axis=-1).reshape(n, m)
                jac_f = np.stack([creep_x,
                                  creep_y - (side * tan_g * kh)[..., None] * d_delta
                                  - (side * tan_slope * fz)[..., None] * d_yrel,
                                  kh[..., None] * d_delta, creep_m], axis=2).reshape(n, m, m)
                dg = np.linalg.solve(eye - jac_f, (target - g)[..., None])[..., 0]
                g = g + dg
                change = float(np.max(np.abs(np.einsum('cwj,cj->cw', d_delta, dg))))
                if change < self.tol:
                    break
            else:
                raise DivergenceError(f'contact iteration did not converge in {self.max_iter} '
                                      f'iterations (last change {change:.3g} m)')
            # Exact track response to these forces.
            gx = g.reshape(n, 8, COMPONENTS)[..., :3]
            load = np.zeros(n_free + 1)
            np.add.at(load, dofs.ravel(), -np.einsum('cwij,cwi->cwj', rows, gx).ravel())
            u_new = u_star + nm.solve(load[:n_free])
            r_exact = (np.einsum('cwij,cwj->cwi', rows, gather(u_new, dofs))
                       - np.einsum('cwij,cwj->cwi', interior, gx))
            r_model = rp.reshape(n, 8, COMPONENTS)[..., :3] - np.einsum(
                'cwij,cwj->cwi', dr, gx)
            mismatch = r_exact - r_model
            if np.max(np.abs(mismatch[..., 2])) <= self.tol:
                break
            offset[..., :3] += mismatch
        else:
            raise DivergenceError('rail displacement under the wheels did not converge to '
                                  f'contact.tolerance = {self.tol:g} m')

        self._check_flange(y_rel)
        self._rail_offset = offset
        self._rail_offset[..., :3] += mismatch
        # Accept the step.
        g3 = g.reshape(n, 8, COMPONENTS)
        q_new = q_star + (g @ self.h) @ self.a_inv.T
        self.qv = a1 * q_new + qh_v
        self.qa = a0 * q_new + qh_a
        self.q = q_new
        self.v, self.a = nm.finish(u_new, h_v, h_a)
        self.u = u_new
        self.force = g3
        self._accept_interior(interior, g3, a1)
        self.compression = delta
        self._rail_y = r_exact[..., 1]
        self.saturation = eps
        self.iterations = total_iter
        self.solves = _outer + 2

    def _buffer(self, name: str, shape: tuple[int, ...], dtype: Any = float) -> np.ndarray:
        """Return a work array of the compiled step, reallocated when its shape changes."""
        buf = self._work.get(name)
        if buf is None or buf.shape != shape:
            buf = self._work[name] = np.zeros(shape, dtype=dtype)
        return buf

    def _geometry_tables(self) -> tuple[np.ndarray, ...]:
        """Return the profile table's columns for the compiled step (empty: the cone)."""
        table = self.table
        if table is None:
            return np.zeros(0), np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0), np.zeros(0)
        return tuple(np.ascontiguousarray(c, dtype=float) for c in (
            table.lateral, table.rolling_radius, table.contact_angle, table.rise, table.roll))

    def _step_compiled(self, head: float, speed: float, k: ContactKernels) -> None:
        """
        Take the step with the compiled kernels: the numpy step's formulas, in loops.

        The rail rows, the local compliance, the irregularity, the step's constants
        of the contact iteration, its Newton iteration, the rail loads and the
        check of the rail's response run compiled
        (:mod:`ttb_sim.sim.contact_kernels`); the train's small products stay numpy's,
        as in :meth:`_step_numpy`.

        With the local K^-1 columns (:attr:`influence_hops`) the step solves the
        track once: the rail motion of the predictor under the wheels comes from
        those columns, its small error joins the rail offset (and a slope offset),
        and the one solve is of the whole right-hand side, predictor and contact
        loads together. The step is accepted, as in the numpy step, when the
        exact rail displacement under every wheel agrees with the local model to
        ``contact.tolerance``; otherwise the offsets are corrected and the track
        solved again. Without the columns the track is solved twice, as in the
        numpy step.
        """
        self._update_speed(speed)
        nm, n = self.nm, self.n_cars
        n_free = self.n_free
        m = 8 * COMPONENTS
        x = head + self.contact_x
        rows = self._buffer('rows', (n, 8, 3, 12))
        slope = self._buffer('slope', (n, 8, 3, 12))
        dofs = self._buffer('dofs', (n, 8, 12), np.intp)
        element = self._buffer('element', (n, 8), np.intp)
        dr = self._buffer('dr', (n, 8, 3, 3))
        ds = self._buffer('ds', (n, 8, 3, 3))
        interior = self._buffer('interior', (n, 8, 3, 3))
        left, right = self.rails
        off = k.rail_rows(x, self.side, left.start, left.length, self.rail_dofs[0],
                          self.compliance.blocks[0], self._rail_sections[0], right.start,
                          right.length, self.rail_dofs[1], self.compliance.blocks[1],
                          self._rail_sections[1], float(self.head_arm[2]), rows, slope, dofs,
                          dr, ds, interior, element)
        if off >= 0:
            raise DivergenceError('a wheel ran off the modelled track at x = '
                                  f'{x.flat[off]:.2f} m; the run is longer than '
                                  'the track (check solver.duration)')
        irr_z, irr_y, irr_dy = np.zeros((n, 8)), np.zeros((n, 8)), np.zeros((n, 8))
        irr = self.irregularity
        if irr is not None:
            k.rail_irregularity(x, self.side, float(irr.x_start), float(irr.dx), irr.values,
                                irr.slopes, irr.curvatures, GRID_SLACK, irr_z, irr_y, irr_dy)

        # Predictors (no contact force).
        single = bool(self.compliance.influence)
        zero = self._zero if self._zero.shape[0] == n_free else np.zeros(n_free)
        h_v, h_a = nm.history(self.u, self.v, self.a)
        rhs = nm.effective_load(zero, h_v, h_a)
        r_star = self._buffer('r_star', (n, 8, 3))
        rs_star = self._buffer('rs_star', (n, 8, 3))
        r_hist = self._buffer('r_hist', (n, 8, 3))
        if single:
            infl_l, infl_r = self.compliance.influence
            k.rail_predictor(element, self.side, *infl_l, *infl_r, rows, slope, rhs, r_star,
                             rs_star)
            u_star = rhs
        else:
            u_star = nm.solve(rhs)
            k.rail_values(rows, u_star, dofs, r_star)
            k.rail_values(slope, u_star, dofs, rs_star)
        k.rail_values(rows, h_v, dofs, r_hist)
        a0, a1 = nm.a0, nm.a1
        qh_v = -a1 * self.q - self.qv
        qh_a = -a0 * self.q - 2.0 * a1 * self.qv - self.qa
        rhs_t = self.gravity - qh_a @ self.mass.T - qh_v @ self.train_damping.T
        q_star = rhs_t @ self.a_inv.T
        w0 = q_star @ self.h.T
        wv0 = a1 * w0 + qh_v @ self.h.T
        creep = self._buffer('creep', (4, n, 8))
        r0p = self._buffer('r0p', (n, 8, COMPONENTS))
        rv0 = self._buffer('rv0', (n, 8, COMPONENTS))
        rvel = self._buffer('rvel', (n, 8, 3, 3))
        y_star = self._buffer('y_star', (n, 8))
        # The contact iteration's rail model includes the interior flexibility; the check
        # of the solved track compares the nodes' part (the interior one is the same in
        # both).
        dr_model = self._buffer('dr_model', (n, 8, 3, 3))
        np.add(dr, interior, out=dr_model)
        k.contact_setup(self.force, self._creep0, float(self.p0), r_star, rs_star, r_hist,
                        self._interior, self._interior_v, dr_model, ds, a1, float(speed), q_star,
                        self._wheelset_y, creep, r0p, rv0, rvel, y_star)
        offset = self._rail_offset.copy()
        slope_offset = self._slope_offset.copy()
        lateral, radius_table, angle_table, rise, roll = self._tables
        g = self.force.reshape(n, m).copy()
        y_rel = np.empty((n, 8))
        delta = np.empty((n, 8))
        eps = np.empty((n, 8))
        load = self._buffer('load', (n_free + 1,))
        r_exact = self._buffer('r_exact', (n, 8, 3))
        mismatch = self._buffer('mismatch', (n, 8, 3))
        slope_mismatch = self._buffer('slope_mismatch', (n, 8, 3))
        total_iter = 0
        for _outer in range(self.max_iter):
            iterations, change = k.contact_newton(
                g, w0, wv0, r0p, rv0, offset, slope_offset, self.dw, dr_model, rvel, self.ey,
                y_star, irr_y, irr_z, irr_dy, self.side, creep, lateral, radius_table,
                angle_table, rise, roll, float(self.params.contact_semi_distance),
                float(self.contact.conicity), float(self.r0), self.g_hertz,
                float(self.friction), a1, float(speed), GEOMETRY_STEP, float(self.tol),
                int(self.max_iter), y_rel, delta, eps)
            total_iter += iterations
            if not change < self.tol:
                raise DivergenceError(f'contact iteration did not converge in {self.max_iter} '
                                      f'iterations (last change {change:.3g} m)')
            # Exact track response to these forces.
            k.rail_load(rows, g, dofs, load)
            if single:
                u_new = nm.solve(rhs + load[:n_free])
            else:
                u_new = u_star + nm.solve(load[:n_free])
            # The single-solve step checks every component: its predictor is local too.
            worst = k.rail_check(rows, slope, u_new, dofs, r0p, offset, dr, ds, g, rs_star,
                                 slope_offset, single, r_exact, mismatch, slope_mismatch)
            if worst <= self.tol:
                break
            offset[..., :3] += mismatch
            slope_offset += slope_mismatch
        else:
            raise DivergenceError('rail displacement under the wheels did not converge to '
                                  f'contact.tolerance = {self.tol:g} m')

        self._check_flange(y_rel)
        self._rail_offset = offset
        self._rail_offset[..., :3] += mismatch
        self._slope_offset = slope_offset + slope_mismatch
        # Accept the step.
        q_new = q_star + (g @ self.h) @ self.a_inv.T
        self.qv = a1 * q_new + qh_v
        self.qa = a0 * q_new + qh_a
        self.q = q_new
        self.v, self.a = nm.finish(u_new, h_v, h_a)
        self.u = u_new
        self.force = g.reshape(n, 8, COMPONENTS)
        self._accept_interior(interior, self.force, a1)
        self.compression = delta
        self._rail_y = r_exact[..., 1] + self._interior[..., 1]
        self.saturation = eps
        self.iterations = total_iter
        self.solves = _outer + 1 + (0 if single else 1)

    # -- the Coupling protocol ------------------------------------------------------------
    def start(self, head: float) -> None:
        """Start from the static equilibrium of train and track under gravity."""
        self.equilibrium(head)

    def structure_load(self, head: float) -> np.ndarray:
        """Return zero: the wheel loads act through the rails, not on the girder DOFs."""
        return self._no_load

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the track-bridge and car displacements."""
        return self.u, self.q

    def vehicle_outputs(self) -> VehicleOutputs:
        """Return car-body accelerations, angular velocities and the wheel-rail forces."""
        n = self.n_cars
        return VehicleOutputs(self.qa[:, 0:3].copy(), self.qv[:, 3:6].copy(),
                              self.force[..., :3].reshape(n, 4, 2, 3).copy())
