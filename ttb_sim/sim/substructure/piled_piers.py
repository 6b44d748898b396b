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
Piled piers stepped beside the bridge: bearing-force coupling with multi-time-step integration.

The superstructure O (train, track, girders, bearings) and each piled
substructure U (pier, cap, piles, soil as a
:class:`~ttb_sim.model.foundation.operator.FoundationOperator`) exchange only
the bearing forces ([P] Eq. 12). A bearing link of stiffness k and damping c
between a girder end (DOFs u_g, kinematics G_g) and the pier top (u_p, G_p)
carries F = k (G_g u_g + G_p u_p) + c (G_g v_g + G_p v_p). Each side keeps
the part of F that depends on its own DOFs in its own implicit matrices (O:
the links to a fixed pier top; U: G_p^T k G_p on the pier top) and receives
the other part as a load:

- on the girders, -G_g^T [k G_p u_p + c G_p v_p] (:meth:`Coupling.load_bridge`);
- on the pier top, -G_p^T [k G_g u_g + c G_g v_g].

Multi-time-step ([P] Eqs. 13-14; PHYSICS.md section 7): O advances at dt, U
at n dt (``solver.substructure_steps``). Within a macro step [t_m, t_m + n dt]
O leads: at each of its n steps it sees the pier top predicted from U's state
at t_m, u_p(t_m + tau) = u_p + tau v_p + tau^2/2 a_p (and v_p + tau a_p),
which is [P] Eq. 14 with the pier-top motion extrapolated rather than
interpolated; when O has reached t_m + n dt, U takes its Newmark step with the
girders' load at that very time, the load its end-of-step equation needs.
Both sides are Newmark average acceleration; n = 1 is the staggered
reference, and ``solver.coupling: monolithic`` ([P] Eq. 11) the exact one.

Why this scheme and why it is stable. The alternative of PHYSICS.md section 7
(U first under the bearing forces of t_m or their average over the previous
macro step, the pier top interpolated for O) lags U's load by (n + 1)/2 dt:
measured on the spring-founded ten-span bridge it is 1.4 % off the monolithic
solution at n = 3, dt = 1e-4 s and blows up at n = 3, dt = 5e-4 s. Here U's
load is exact in time and only O's view of the pier top is extrapolated (error
O(tau^3)): 0.04 % at n = 3 and stable at n = 3, dt = 5e-4 s and n = 10,
dt = 1e-4 s over 12 s of free decay. Like every staggered scheme it is only
conditionally stable: the macro-step map of a girder end and a pier top joined
by a bearing has spectral radius up to 1 + 1e-3 undamped at n = 3, dt = 1e-4 s
(bearing 2e10 N/m, 25 t pier top); the stiffness-proportional Rayleigh damping
the girders and piers carry (2 % at f1 and 4 f1: 2.5e-4 s for the paper's
girder) brings it below 1 over pier-top masses 10 t-1000 t, bearings 1e9-2e10
N/m, pier stiffness 1e8-2.6e10 N/m for n <= 5 at dt = 1e-4 s (docs/coupled.md
gives the table). The Gravouil-Combescure scheme would be stable without that
damping at the cost of an interface solve per step; the monolithic coupling
is the unconditionally stable reference.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
import scipy.linalg as sla

from ttb_sim.errors import ScenarioError
from ttb_sim.model.foundation.observation import gauge_rows
from ttb_sim.model.foundation.operator import TOP
from ttb_sim.model.foundation.records import FoundationError
from ttb_sim.model.structure import PiledPier, Structure


@dataclass
class PierState:
    """State of one substructure: q, q', q'' (generalised coordinates)."""

    u: np.ndarray
    v: np.ndarray
    a: np.ndarray


class DenseNewmark:
    """Newmark average acceleration on a small dense system (Cholesky of K + 2/dt C + 4/dt^2 M)."""

    def __init__(self, mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray,
                 dt: float) -> None:
        self.dt = dt
        self.a0, self.a1 = 4.0 / dt**2, 2.0 / dt
        self.mass, self.damping, self.stiffness = mass, damping, stiffness
        effective = stiffness + self.a1 * damping + self.a0 * mass
        self._factor = sla.cho_factor(0.5 * (effective + effective.T))

    def step(self, state: PierState, force: np.ndarray) -> PierState:
        """Advance one step under the load ``force`` at the end of the step."""
        h_v = -self.a1 * state.u - state.v
        h_a = -self.a0 * state.u - 2.0 * self.a1 * state.v - state.a
        rhs = force - self.mass @ h_a - self.damping @ h_v
        u = sla.cho_solve(self._factor, rhs, check_finite=False)   # checked per step
        return PierState(u, self.a1 * u + h_v, self.a0 * u + h_a)


@dataclass(frozen=True)
class BearingCoupling:
    """The bearing links of one piled pier, split into girder and pier-top parts."""

    girder_dofs: np.ndarray
    """(n_links, 6) extended free indices of the girder-end DOFs."""
    girder: np.ndarray
    """(n_links, 3, 6) G_g."""
    pier: np.ndarray
    """(n_links, 3, 6) G_p."""
    stiffness: np.ndarray
    """(n_links, 3)."""
    damping: np.ndarray
    """(n_links, 3)."""

    @classmethod
    def of(cls, structure: Structure, pier: PiledPier) -> BearingCoupling:
        """Return the coupling of ``pier``'s bearings in ``structure``."""
        bg = structure.bearings
        assert bg is not None, 'piled piers need elastic bearings (scenario rule)'
        kin = bg.kinematics[pier.links]
        assert np.all(bg.dofs[pier.links, :6] < structure.n_free), 'girder ends are free'
        return cls(bg.dofs[pier.links, :6], kin[:, :, :6], kin[:, :, 6:],
                   bg.stiffness[pier.links], bg.damping[pier.links])

    def pier_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Return (G_p^T k G_p, G_p^T c G_p): the bearings as U sees them, pier top fixed in O."""
        return (np.einsum('lai,la,laj->ij', self.pier, self.stiffness, self.pier),
                np.einsum('lai,la,laj->ij', self.pier, self.damping, self.pier))

    def on_pier(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """
        Return the load on the pier top (6,) from the girder-end state.

        ``u`` and ``v`` are (n_links, 6), at :attr:`girder_dofs` (elastic bearings
        leave every girder-end DOF free: no zero slot to gather).
        """
        f = (self.stiffness * np.einsum('lai,li->la', self.girder, u)
             + self.damping * np.einsum('lai,li->la', self.girder, v))
        return -np.einsum('lai,la->i', self.pier, f)

    def on_girders(self, top_u: np.ndarray, top_v: np.ndarray) -> np.ndarray:
        """Return the loads (n_links, 6) on the girder ends from the pier-top state."""
        f = (self.stiffness * np.einsum('lai,i->la', self.pier, top_u)
             + self.damping * np.einsum('lai,i->la', self.pier, top_v))
        return -np.einsum('lai,la->li', self.girder, f)


class PiledFoundations:
    """
    The partitioned piled piers of a structure, stepped beside the bridge.

    The bridge's coupling exchanges the bearing forces with them before and
    after every bridge step (:meth:`before_step`, :meth:`after_step`).

    Parameters
    ----------
    structure : Structure
        The bridge, assembled with the piled piers left out (partitioned).
    dt : float
        The bridge's time step (s).
    substeps : int
        n: bridge steps per substructure step.

    """

    def __init__(self, structure: Structure, dt: float, substeps: int) -> None:
        self.piers = tuple(p for p in structure.piled if p.block is None)
        self.substeps = int(substeps)
        self.dt = float(dt)
        self.n_supports = structure.n_supports
        self.couplings = tuple(BearingCoupling.of(structure, p) for p in self.piers)
        dt_u = self.dt * self.substeps
        self.solvers = []
        for pier, coupling in zip(self.piers, self.couplings):
            op = pier.operator
            k_b, c_b = coupling.pier_matrices()
            k, c = op.stiffness.copy(), op.damping.copy()
            k[np.ix_(TOP, TOP)] += k_b
            c[np.ix_(TOP, TOP)] += c_b
            self.solvers.append(DenseNewmark(op.mass, c, k, dt_u))
        self.states = [PierState(np.zeros(p.operator.size), np.zeros(p.operator.size),
                                 np.zeros(p.operator.size)) for p in self.piers]
        """Each substructure's state at the last macro-step end."""
        girder_dofs = np.concatenate([c.girder_dofs.ravel() for c in self.couplings]
                                     or [np.zeros(0, dtype=np.intp)])
        self._girder_dofs, self._slot = np.unique(girder_dofs, return_inverse=True)
        """The girder DOFs the bearings load (unique), and each link DOF's place among them."""
        self._loads = np.zeros(self._girder_dofs.size)
        self.step_index = 0
        """Bridge steps taken."""

    @property
    def active(self) -> bool:
        """True when there is anything to step."""
        return bool(self.piers)

    def before_step(self, load_bridge: Callable[[np.ndarray, np.ndarray], None]) -> None:
        """
        Load the girders with the pier tops predicted at the end of this bridge step.

        ``load_bridge(dofs, values)`` adds the bearing forces to the bridge's next
        step (:meth:`Coupling.load_bridge`).
        """
        loads = np.concatenate([
            coupling.on_girders(*self._predicted_top(i)).ravel()
            for i, coupling in enumerate(self.couplings)])
        self._loads.fill(0.0)
        np.add.at(self._loads, self._slot, loads)
        load_bridge(self._girder_dofs, self._loads)

    def _predicted_top(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        state = self._predicted(i, self.step_index + 1, TOP)
        return state.u, state.v

    def after_step(self, bridge_state: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
                   ) -> None:
        """
        Advance the substructures when the bridge has reached a macro-step end.

        ``bridge_state(dofs)`` returns the bridge's (u, v) at free DOFs ``dofs``
        (:meth:`Coupling.bridge_state`); it is called at macro-step ends only.
        """
        self.step_index += 1
        if self.step_index % self.substeps:
            return
        for i, (coupling, solver) in enumerate(zip(self.couplings, self.solvers)):
            force = np.zeros(self.piers[i].operator.size)
            force[TOP] = coupling.on_pier(*bridge_state(coupling.girder_dofs))
            self.states[i] = solver.step(self.states[i], force)

    def _predicted(self, i: int, step: int, dofs: slice | np.ndarray = slice(None)
                   ) -> PierState:
        """Return pier ``i``'s state (``dofs``) at bridge step ``step`` of this macro step."""
        s = self.states[i]
        u, v, a = s.u[dofs], s.v[dofs], s.a[dofs]
        tau = (step - self.substeps * (self.step_index // self.substeps)) * self.dt
        return PierState(u + tau * v + 0.5 * tau**2 * a, v + tau * a, a)

    def current(self) -> list[PierState]:
        """Return every pier's state at the bridge's current time (as the bridge saw it)."""
        return [self._predicted(i, self.step_index) for i in range(len(self.piers))]

    def tops(self) -> tuple[np.ndarray, np.ndarray]:
        """Return the pier-top (u, v), shape (n_supports, 6), at the bridge's current time."""
        u, v, _ = self.top_states()
        return u, v

    def top_states(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the pier-top (u, v, a), shape (n_supports, 6), at the bridge's current time."""
        out = np.zeros((3, self.n_supports, len(TOP)))
        for pier, state in zip(self.piers, self.current()):
            out[:, pier.support] = state.u[TOP], state.v[TOP], state.a[TOP]
        return out[0], out[1], out[2]


def pile_coordinates(structure: Structure, foundations: PiledFoundations,
                     ue: np.ndarray) -> list[np.ndarray]:
    """Return the coordinates q of every piled pier with an interface, in structure order."""
    states = iter(foundations.current())
    out = []
    for pier in structure.piled:
        q = ue[pier.block] if pier.block is not None else next(states).u
        if pier.operator.interface is not None:
            out.append(q)
    return out


@dataclass(frozen=True)
class PileGauges:
    """The pile strain gauges of a structure: per piled pier, its gauges' rows over q."""

    count: int
    """Number of gauges (all piers)."""
    rows: dict[int, tuple[np.ndarray, np.ndarray]]
    """Per index into ``structure.piled``: (the gauges' places in frame order, rows (g, n))."""

    @classmethod
    def of(cls, structure: Structure, requests: Sequence[tuple[int, int, float]]
           ) -> PileGauges:
        """
        Return the gauges ``requests`` (pier 1-based, pile 1-based, depth m) read.

        Raises
        ------
        ScenarioError
            For a pier that is not piled, a pile not in its group or a depth off the pile.

        """
        supports = [p.support + 1 for p in structure.piled]
        wanted: dict[int, list[tuple[int, int, float]]] = {}
        for place, (pier, pile, depth) in enumerate(requests):
            if pier not in supports:
                raise ScenarioError(f'pile strain gauge at pier{pier:02d}/pile{pile:02d}: pier '
                                    f'{pier} is not piled; piled piers: {supports}')
            wanted.setdefault(supports.index(pier), []).append((place, pile - 1, depth))
        rows = {}
        for k, items in wanted.items():
            op = structure.piled[k].operator
            if op.pile_strain is None or op.pile_layer_depths is None:
                raise ScenarioError(f'pier{supports[k]:02d}: its foundation has no pile '
                                    'strain rows (a pier column on springs)')
            try:
                matrix = gauge_rows(op.pile_strain, op.pile_layer_depths,
                                    [(pile, depth) for _, pile, depth in items])
            except FoundationError as exc:
                raise ScenarioError(f'pile strain gauge at pier{supports[k]:02d}: {exc}'
                                    ) from None
            rows[k] = (np.array([place for place, _, _ in items]), np.asarray(matrix))
        return cls(len(requests), rows)


class PileOutputs:
    """
    The pile and soil fields of a :class:`~ttb_sim.sim.frames.Frame` (none unpiled).

    Monolithic piers read their coordinates from the structure state (extended
    free ue, ve, ae); partitioned ones from ``foundations`` at the current time.
    Soil points are placed in track axes: x from the pier's support, z from the
    ground surface ``depth`` below the bearings. ``gauges`` adds ``pile_strain``.
    Each pier's output rows (pile heads, pile rotations, soil points) are stacked
    once into one matrix, so a frame costs one product per pier with its [q, q'', q'].
    """

    def __init__(self, structure: Structure, foundations: PiledFoundations,
                 gauges: PileGauges | None = None) -> None:
        self.structure = structure
        self.foundations = foundations
        self.gauges = gauges
        self._rows = []
        self._positions = []
        for pier in structure.piled:
            op = pier.operator
            rotations = (op.pile_rotations if op.pile_rotations is not None
                         else np.zeros((3 * op.n_piles, op.size)))
            self._rows.append(np.vstack([op.pile_heads, rotations, op.soil_points]))
            origin = np.array([pier.support * structure.girder.span_length, 0.0, -op.depth])
            self._positions.append(op.soil_point_positions + origin)
        self._piles = sum(p.operator.n_piles for p in structure.piled)
        self._points = sum(len(p.operator.soil_point_names) for p in structure.piled)

    def __call__(self, ue: np.ndarray, ve: np.ndarray, ae: np.ndarray) -> dict[str, np.ndarray]:
        """Return the fields of one frame (new arrays, the frame's own)."""
        structure, gauges = self.structure, self.gauges
        if not structure.piled:
            return {}
        states = iter(self.foundations.current())
        disp, acc, rot = (np.empty((self._piles, 3)) for _ in range(3))
        soil = np.empty((self._points, 12))
        strain = np.zeros((gauges.count if gauges is not None else 0, 3))
        piles = points = 0
        for k, pier in enumerate(structure.piled):
            if pier.block is not None:
                q, qv, qa = ue[pier.block], ve[pier.block], ae[pier.block]
            else:
                state = next(states)
                q, qv, qa = state.u, state.v, state.a
            out = self._rows[k] @ np.column_stack([q, qa, qv])   # (rows, u|a|v)
            n_p, n_s = pier.operator.n_piles, self._positions[k].shape[0]
            disp[piles:piles + n_p] = out[:3 * n_p, 0].reshape(-1, 3)
            acc[piles:piles + n_p] = out[:3 * n_p, 1].reshape(-1, 3)
            rot[piles:piles + n_p] = out[3 * n_p:6 * n_p, 2].reshape(-1, 3)
            soil[points:points + n_s, :3] = self._positions[k]
            # rows (point, axis), columns u|a|v -> per point [u xyz, a xyz, v xyz]
            soil[points:points + n_s, 3:] = (
                out[6 * n_p:].reshape(n_s, 3, 3).transpose(0, 2, 1).reshape(n_s, 9))
            piles += n_p
            points += n_s
            if gauges is not None and k in gauges.rows:
                places, rows = gauges.rows[k]
                strain[places, 0] = rows @ q
        return {'pile_displacement': disp, 'pile_acceleration': acc,
                'pile_rotation_rate': rot, 'soil_points': soil, 'pile_strain': strain}


class RigidDisplacement:
    """
    [P] Eq. 16 beside the computed girder: the mid-span a rigid girder would have.

    A rigid girder on supports that settle as the mean head of their piles
    has its mid-span at the mean of the two: sum_i U_p,i / 2N for a girder on
    one piled pier of N piles, the mean of both piers' for a girder on two.
    The tracker keeps, per span with a piled support, the peaks and the RMS
    of the estimate and of the computed mid-span displacement (vertical).
    """

    def __init__(self, structure: Structure) -> None:
        self.n_spans = structure.girder.n_spans
        piled = [p.support for p in structure.piled]
        # the girders resting on a piled support: the spans on either side of it
        self.spans = sorted({k for s in piled for k in (s - 1, s) if 0 <= k < self.n_spans})
        counts = [p.operator.n_piles for p in structure.piled]
        rows = np.split(np.arange(sum(counts)), np.cumsum(counts)[:-1])
        self._slices = dict(zip(piled, rows))
        # the mean settlement of each support's piles as one product: (supports + 1, piles)
        self._mean = np.zeros((self.n_spans + 1, sum(counts)))
        for support, pile_rows in self._slices.items():
            if pile_rows.size:
                self._mean[support, pile_rows] = 1.0 / pile_rows.size
        spans = np.asarray(self.spans, dtype=np.intp)
        self._ends = (spans, spans + 1)
        n = len(self.spans)
        self._peak = np.zeros((2, n))
        self._sq = np.zeros((3, n))
        self._frames = 0

    def update(self, midspan: np.ndarray, pile_displacement: np.ndarray) -> None:
        """Take one frame: mid-span (n_spans, 3) and pile heads (n_piles, 3) displacements."""
        if not self.spans or pile_displacement.size == 0:
            return
        settle = self._mean @ pile_displacement[:, 2]
        left, right = self._ends
        estimate = 0.5 * (settle[left] + settle[right])
        computed = midspan[left, 2]
        self._peak[0] = np.maximum(self._peak[0], np.abs(estimate))
        self._peak[1] = np.maximum(self._peak[1], np.abs(computed))
        self._sq += np.stack([estimate, computed, computed - estimate]) ** 2
        self._frames += 1

    def summary(self) -> list[dict[str, float]]:
        """Return per span: girder number and the peaks and RMS values (m)."""
        rms = np.sqrt(self._sq / max(self._frames, 1))
        return [{'girder': k + 1, 'rigid_peak': float(self._peak[0, i]),
                 'computed_peak': float(self._peak[1, i]), 'rigid_rms': float(rms[0, i]),
                 'computed_rms': float(rms[1, i]), 'difference_rms': float(rms[2, i])}
                for i, k in enumerate(self.spans)]


class InterfaceCheck:
    """
    How far the piles' interface is from slipping: the check that the linear reduction holds.

    The reduced substructure keeps the Desai interface at its initial tangent.
    This keeps every ``stride``-th frame's coordinates of each piled pier and
    reports, at the end, the largest |tau| / tau_f over the interface and the
    run (:func:`~ttb_sim.model.foundation.reduction.interface_mobilisation`):
    for the train's increment alone, and with ``dead_load`` (N: two half-spans
    and the pier column) on the pier top added as a static state.
    """

    def __init__(self, structure: Structure, dead_load: float, stride: int = 10) -> None:
        self.piers = [p for p in structure.piled if p.operator.interface is not None]
        self.stride = stride
        self._frames = 0
        self._history: list[list[np.ndarray]] = [[] for _ in self.piers]
        self._dead = []
        for pier in self.piers:
            force = np.zeros(pier.operator.size)
            force[2] = -dead_load        # on the pier top, all of it: the soil sees the sum
            self._dead.append(np.linalg.solve(pier.operator.stiffness, force))

    def update(self, states: list[np.ndarray]) -> None:
        """Take one frame: the coordinates of every checked pier, in order."""
        if self._frames % self.stride == 0:
            for history, q in zip(self._history, states):
                history.append(q.copy())
        self._frames += 1

    def summary(self) -> dict[str, dict[str, float]]:
        """Return per pier the largest mobilisation, train only and with the dead load."""
        from ttb_sim.model.foundation.reduction import interface_mobilisation

        out = {}
        for pier, history, dead in zip(self.piers, self._history, self._dead):
            if not history:
                continue
            q = np.array(history)
            out[f'pier{pier.support + 1:02d}'] = {
                'train': interface_mobilisation(pier.operator, q),
                'with_dead_load': interface_mobilisation(pier.operator, q + dead)}
        return out
