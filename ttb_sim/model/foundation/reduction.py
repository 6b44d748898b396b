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
The reduced-order pier-cap-pile-soil substructure of one piled pier.

:func:`pile_soil_operator` turns the 3-D finite-element substructure of
:mod:`.substructure` into a small dense :class:`~.operator.FoundationOperator`:

1. The *linear* model: K = soil + structure + boundary + interface at its
   initial (geostatic) tangent, C = soil + structure + boundary damping,
   M = lumped mass, on the free DOFs.
2. The cap top face tied rigidly to a 6-DOF master at the group centre on the
   cap top (u_i = u_m + theta x r_i; :func:`~.tied.tie_cap`), and a pier column of beam elements
   (:func:`~.operator.pier_column`, Rayleigh C = a0 M + a1 K) standing on
   that master; the column's top node is q[:6].
3. The reduction (:func:`~.krylov.reduction_basis`). The column and the master
   stay physical. The soil-pile-cap
   interior is the static (constraint) modes of the master, Psi = -K_ii^-1 K_ib,
   plus a basis V of second-order block Krylov vectors of the master loads
   B: at each real shift s >= 0 the pencil Z = K + s C + s^2 M is symmetric
   positive definite, is factorised once (CHOLMOD), and the sequence
   r_1 = Z^-1 B, r_j = -Z^-1 ((C + 2 s M) r_{j-1} + M r_{j-2}) (the moments
   of (K + sigma C + sigma^2 M)^-1 B about sigma = s, the SOAR recurrence of
   Bai & Su 2005, orthogonalised as it goes) spans the response. (With
   ``shift_axis='imaginary'`` the shift is s = i w: Z = K - w^2 M + i w C,
   complex symmetric, solved through the LDL^T factors of its real 2n form,
   and the real and imaginary parts of the vectors enter the basis; exact at
   w, but far dearer to factorise.) A group centred in a mirror-symmetric
   block splits the master loads into symmetry classes (uz; ux, ry; uy, rx;
   rz), each factorised and recurred on its own quarter of the unknowns
   (:func:`~.krylov.mirror_parts`; exact, and about a sixteenth of the work of
   a factorisation of the whole each). The vectors
   of all shifts, less their master part (so that V vanishes on the master),
   are mass-orthonormalised with deflation. The damping is projected, not
   diagonalised (the boundary dashpots make it far from proportional). The
   projection is Galerkin, so the reduced matrices are symmetric, M and K
   positive definite, and the static flexibility is the unreduced one to
   round-off (Psi is in the basis and K-orthogonal to V).

q = [column nodes from the top down to the one above the master (6 each),
master (6), generalised coordinates of V]. Outputs are the model's
observation operators through the basis: pile-head mean displacements, soil
points, the piles' axial strain per element layer (of interior pile DOFs, which
q does not hold: recovered through the rows of Psi and V), and
(:class:`~.operator.InterfaceRows`) the interface tractions at the initial
tangent with their Mohr-Coulomb strength, so that :func:`interface_mobilisation`
can show a run stayed linear.

The operator of a given set of inputs is cached on disk (``$TTB_SIM_CACHE``
or ``~/.cache/ttb_sim``) under a hash of every input (:mod:`.operator_cache`);
the build is deterministic, so a cache hit gives the same bits as a fresh
build. A corrupt or unwritable cache is logged and bypassed.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
import logging
import math
import time
from typing import Any, Callable, Iterator, Optional

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ttb_sim.fe.beam import BeamSection, NODE_DOFS
from ttb_sim.model.foundation.krylov import positive_definite_method, reduction_basis
from ttb_sim.model.foundation.operator import (FoundationOperator, InterfaceRows,
                                               pier_column)
from ttb_sim.model.foundation.operator_cache import (cache_directory, cache_key,
                                                     load_operator, save_operator)
from ttb_sim.model.foundation.records import (FoundationError, ReductionParameters,
                                              Substructure)
from ttb_sim.model.foundation.soil_mesh import planned_nodes
from ttb_sim.model.foundation.substructure import build
from ttb_sim.model.foundation.tied import check_spec, tie_cap, TiedSubstructure

LOG = logging.getLogger(__name__)

SHIFT_SECONDS = 1.2
"""CPU seconds of one shift (the CHOLMOD factorisations of the four symmetry classes and their
Krylov solves) at :data:`SHIFT_DOFS` DOFs, measured on this 2-core machine (the live mesh:
17 478 tied DOFs, 2.0-2.9 s for two shifts; a mesh without mirror symmetry costs about three
times as much)."""
SHIFT_DOFS = 18_000
SHIFT_EXPONENT = 2.05
"""Growth of a shift's cost with the DOFs of a 3-D mesh (measured: 1.0-1.45 s a shift at 17 478
tied DOFs, 27 s at the paper mesh's 79 887; imaginary shifts with PARDISO cost about a quarter
of this estimate: 65 s a shift at 257 070 DOFs)."""


PARDISO_SPEEDUP = 3.4
"""How much faster a build is with MKL PARDISO's Cholesky (the ``pardiso`` extra) in place of
CHOLMOD: the paper pier 133 -> 38.6 s of wall time, side by side under the same load."""


def build_seconds(dofs: int, shifts: int, pardiso: bool = False) -> float:
    """
    Return the estimated CPU seconds of reducing a substructure of ``dofs`` with ``shifts``.

    ``pardiso``: the positive definite pencils go to PARDISO (:data:`PARDISO_SPEEDUP`).
    """
    seconds = SHIFT_SECONDS * shifts * (dofs / SHIFT_DOFS) ** SHIFT_EXPONENT
    return seconds / PARDISO_SPEEDUP if pardiso else seconds


PROGRESS_FIELD = 'build_progress'
"""Attribute of a progress record: (fraction done, CPU seconds left or None), for a watcher
such as the node's ``/diagnostics`` (:class:`ttb_sim.node.logs.ProgressWatcher`)."""


class BuildProgress:
    """
    Report a reduction's progress, shift by shift: percent done, CPU so far, time left.

    The lines go to this module's logger at WARNING when the whole build is
    estimated to take more than :data:`NOTICE_SECONDS` (so a terminal shows them
    without ``--verbose``, and the node forwards them to its log and
    ``/diagnostics``), at INFO otherwise. :attr:`fraction` and :attr:`remaining`
    hold the last report for a caller that polls (the node's build status).
    """

    NOTICE_SECONDS = 20.0

    def __init__(self, total: int, estimate: float) -> None:
        self.total = max(int(total), 1)
        self.level = logging.WARNING if estimate > self.NOTICE_SECONDS else logging.INFO
        self.fraction = 0.0
        self.remaining: float | None = None
        self._start = time.process_time()

    def __call__(self, done: int) -> None:
        """Take the news that ``done`` of the shifts are finished."""
        spent = time.process_time() - self._start
        self.fraction = min(done / self.total, 1.0)
        self.remaining = spent * (self.total - done) / done if done else None
        left = '' if self.remaining is None or done == self.total else (
            f', about {_duration(self.remaining)} left')
        LOG.log(self.level, 'reducing the pile-soil substructure: %d of %d shifts done '
                '(%.0f %%), %s of CPU so far%s', done, self.total, 100 * self.fraction,
                _duration(spent), left,
                extra={PROGRESS_FIELD: (self.fraction, self.remaining)})


def _duration(seconds: float) -> str:
    """Return seconds as '42 s' or '3.5 min'."""
    return f'{seconds:.0f} s' if seconds < 90 else f'{seconds / 60:.1f} min'


@dataclass(frozen=True)
class SparseOperator:
    """
    The unreduced linear pier on its pile-soil model, in the layout of the reduced one.

    q = [column nodes above the master, master, free DOFs not on the cap top]:
    the same first 6 (pier top) and the same output meaning as the
    :class:`~.operator.FoundationOperator` of :func:`pile_soil_operator`, for
    checking it.
    """

    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    pile_heads: sp.csr_matrix
    soil_points: sp.csr_matrix
    pile_strain: Optional[sp.csr_matrix] = None


def pile_soil_operator(spec: Substructure, pier_height: float, pier_elements: int,
                       pier_section: BeamSection, pier_rayleigh: tuple[float, float],
                       reduction: ReductionParameters, *, cache: bool = True
                       ) -> FoundationOperator:
    """
    Return the reduced linear pier-cap-pile-soil substructure of one piled pier.

    Parameters
    ----------
    spec : Substructure
        Soil, piles, cap (enabled), interface, observation points.
    pier_height : float
        Pier column from the cap top to the bearing level (m).
    pier_elements : int
        Beam elements of the column.
    pier_section : BeamSection
        Column section, one entry per element.
    pier_rayleigh : (a0, a1)
        Column damping C = a0 M + a1 K.
    reduction : ReductionParameters
        Shifts, levels and deflation tolerance of the Krylov basis.
    cache : bool
        Read and write the on-disk cache (``$TTB_SIM_CACHE`` or
        ``~/.cache/ttb_sim``).

    Returns
    -------
    FoundationOperator
        q[:6] the pier top; rows for pile heads, soil points and the interface.

    Raises
    ------
    FoundationError
        No piles, the cap disabled, a boundary without static support, or
        anything :func:`~.substructure.build` refuses.

    """
    check_spec(spec)
    if len(pier_section.ea) != pier_elements:
        raise FoundationError(f'pier_section has {len(pier_section.ea)} elements, pier_elements '
                              f'= {pier_elements}')
    key = cache_key(spec, pier_height, pier_elements, pier_section, pier_rayleigh, reduction)
    path = cache_directory() / f'pile_soil_{key[:32]}.npz' if cache else None
    if path is not None and path.exists():
        op = load_operator(path)
        if op is not None:
            LOG.info('reduced pile-soil substructure read from the cache %s', path)
            return op
    nodes = planned_nodes(spec)
    estimate = build_seconds(3 * nodes, len(reduction.shifts),
                             pardiso=positive_definite_method() == 'pardiso')
    progress = BuildProgress(len(reduction.shifts), estimate)
    # a line the user sees when it takes a while (the CLI shows warnings), once
    LOG.log(progress.level, 'reducing the pile-soil substructure of %d nodes (%d DOFs) with '
            '%d shifts x %d levels: about %s of CPU the first time%s', nodes, 3 * nodes,
            len(reduction.shifts), reduction.levels, _duration(estimate),
            f', then read from {path.parent}' if path is not None else '')
    start = time.process_time()
    with _one_blas_thread():
        op = _build(spec, pier_height, pier_elements, pier_section, pier_rayleigh, reduction,
                    progress)
    LOG.info('reduced pile-soil substructure: %d full DOFs -> %d coordinates in %.1f s of CPU',
             op.summary['full_dofs'], op.size, time.process_time() - start)
    if path is not None:
        save_operator(path, op)
    return op


def _build(spec: Substructure, pier_height: float, pier_elements: int,
           pier_section: BeamSection, pier_rayleigh: tuple[float, float],
           reduction: ReductionParameters, progress: Callable[[int], None] | None = None
           ) -> FoundationOperator:
    tied = tie_cap(build(spec))
    psi, v = reduction_basis(tied, reduction, progress)
    phi = np.hstack([psi, np.vstack([np.zeros((6, v.shape[1])), v])])
    m_r = _galerkin(tied.mass, phi)
    c_r = _galerkin(tied.damping, phi)
    k_r = _galerkin(tied.stiffness, phi)
    column = _column(pier_height, pier_elements, pier_section, pier_rayleigh)
    mass, damping, stiffness = (_stack(a, b) for a, b in zip(column, (m_r, c_r, k_r)))
    mass, damping, stiffness = (0.5 * (a + a.T) for a in (mass, damping, stiffness))
    n = mass.shape[0]
    lead = n - phi.shape[1]
    model = tied.model
    heads = _rows(model.head_displacement, tied, phi, lead)
    rotations = _rows(model.head_rotation, tied, phi, lead)
    points = _rows(model.soil_points.operator, tied, phi, lead)
    strain = _rows(model.pile_strain, tied, phi, lead)   # interior pile DOFs via the basis
    assert spec.piles is not None
    centre = np.array(spec.piles.centre, dtype=float)
    positions = np.array(spec.piles.centres(), dtype=float) - centre
    soil_positions = model.soil_points.positions.copy()
    soil_positions[:, :2] -= centre
    summary = {'model': 'reduced pile-soil substructure', 'dofs': int(n),
               'full_dofs': int(model.free.sum()), 'tied_dofs': tied.size,
               'basis': int(v.shape[1]), 'column_dofs': int(lead + 6),
               'shifts_hz': [float(f) for f in reduction.shifts],
               'levels': reduction.levels, 'nodes': model.mesh.n_nodes,
               'interface_elements': model.summary['interface_elements'],
               'f_max': model.summary['f_max'], 'factorization': positive_definite_method()}
    return FoundationOperator(mass=mass, damping=damping, stiffness=stiffness,
                              pile_heads=heads, pile_positions=positions,
                              soil_points=points, soil_point_names=model.soil_points.names,
                              soil_point_positions=soil_positions,
                              depth=float(pier_height + spec.cap.thickness), summary=summary,
                              interface=_interface_rows(tied, phi, lead),
                              pile_rotations=rotations, pile_strain=strain,
                              pile_layer_depths=model.pile_layer_depths.copy())


def _galerkin(a: sp.csr_matrix, phi: np.ndarray) -> np.ndarray:
    out = phi.T @ (a @ phi)
    return 0.5 * (out + out.T)


def _column(height: float, elements: int, section: BeamSection,
            rayleigh: tuple[float, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    m, k, _ = pier_column(height, elements, section)
    return m, rayleigh[0] * m + rayleigh[1] * k, k


def _stack(column: np.ndarray, sub: np.ndarray) -> np.ndarray:
    """Add the column (top first, base node last) and the substructure sharing the master."""
    lead = column.shape[0] - NODE_DOFS
    n = lead + sub.shape[0]
    out = np.zeros((n, n))
    out[:column.shape[0], :column.shape[0]] += column
    out[lead:, lead:] += sub
    return out


def _rows(op: sp.csr_matrix, tied: TiedSubstructure, phi: np.ndarray, lead: int) -> np.ndarray:
    sub = (op @ tied.transform) @ phi
    return np.hstack([np.zeros((sub.shape[0], lead)), sub])


def _interface_rows(tied: TiedSubstructure, phi: np.ndarray,
                    lead: int) -> Optional[InterfaceRows]:
    model = tied.model
    iface, law = model.interface, model.law
    if iface is None or law is None:
        return None
    k = iface.n_elements
    rel = ((iface.relative @ tied.transform) @ phi).reshape(k, 4, 3, -1)
    modulus = law.initial_tangent() / iface.thickness[:, None, None]
    stress = rel * modulus[..., None]
    pad = np.zeros((4 * k, lead))
    normal = np.hstack([pad, stress[:, :, 0].reshape(4 * k, -1)])
    shear = np.hstack([np.zeros((8 * k, lead)), stress[:, :, 1:].reshape(8 * k, -1)])
    shape = (k, 4)
    return InterfaceRows(normal=normal, shear=shear,
                         sigma_n0=np.broadcast_to(law.sigma_n0, shape).ravel().copy(),
                         cohesion=np.broadcast_to(law.cohesion, shape).ravel().copy(),
                         tan_delta=np.broadcast_to(law.tan_delta, shape).ravel().copy())


def interface_mobilisation(op: FoundationOperator, q_history: np.ndarray) -> float:
    """
    Return the largest |tau| / tau_f over the interface Gauss points and the history.

    tau is the shear traction the initial tangent gives for q, tau_f the
    Mohr-Coulomb strength c + p tan(delta) at the normal compression
    p = sigma_n0 - sigma_n (not below 0). Values well below the failure ratio
    R_f (0.9) mean the interface stayed near its initial tangent; 1 or more
    means it would have slipped (the linear reduced model is then not valid).

    Parameters
    ----------
    op : FoundationOperator
        With ``interface`` rows (from :func:`pile_soil_operator`).
    q_history : array (n_t, n) or (n,)
        Generalised coordinates (the dead-load state included if it matters).

    Raises
    ------
    FoundationError
        When ``op`` has no interface rows or q has the wrong size.

    """
    rows = op.interface
    if rows is None:
        raise FoundationError('this foundation operator has no interface rows')
    q = np.atleast_2d(np.asarray(q_history, dtype=float))
    if q.shape[1] != op.size:
        raise FoundationError(f'q_history has {q.shape[1]} coordinates, the operator {op.size}')
    worst = 0.0
    for start in range(0, len(q), 1024):
        chunk = q[start:start + 1024]
        sigma = chunk @ rows.normal.T
        tau = np.hypot(*(chunk @ rows.shear.T).reshape(len(chunk), -1, 2).transpose(2, 0, 1))
        strength = rows.cohesion + np.maximum(rows.sigma_n0 - sigma, 0.0) * rows.tan_delta
        with np.errstate(divide='ignore', invalid='ignore'):
            ratio = np.where(strength > 0, tau / strength, np.where(tau > 0, np.inf, 0.0))
        worst = max(worst, float(ratio.max(initial=0.0)))
    return worst


def unreduced_operator(spec: Substructure, pier_height: float, pier_elements: int,
                       pier_section: BeamSection, pier_rayleigh: tuple[float, float]
                       ) -> SparseOperator:
    """Return the unreduced linear pier and substructure (sparse), for checks."""
    tied = tie_cap(build(spec))
    column = _column(pier_height, pier_elements, pier_section, pier_rayleigh)
    lead = column[0].shape[0] - NODE_DOFS
    n = lead + tied.size

    def stack(col: np.ndarray, sub: sp.csr_matrix) -> sp.csr_matrix:
        a = sp.lil_matrix((n, n))
        a[:col.shape[0], :col.shape[0]] = col
        return (a.tocsr() + sp.block_diag([sp.csr_matrix((lead, lead)), sub])).tocsr()

    mass, damping, stiffness = (stack(a, b) for a, b in zip(column, (tied.mass, tied.damping,
                                                                     tied.stiffness)))
    model = tied.model

    def rows(op: sp.csr_matrix) -> sp.csr_matrix:
        sub = (op @ tied.transform).tocsr()
        return sp.hstack([sp.csr_matrix((sub.shape[0], lead)), sub]).tocsr()

    return SparseOperator(mass, damping, stiffness, rows(model.head_displacement),
                          rows(model.soil_points.operator), rows(model.pile_strain))


def dynamic_flexibility(mass: Any, damping: Any, stiffness: Any, frequencies: np.ndarray,
                        dofs: np.ndarray = np.arange(NODE_DOFS)) -> np.ndarray:
    """
    Return H(f) = [K - w^2 M + i w C]^-1 restricted to ``dofs``, shape (n_f, d, d).

    Dense matrices are solved densely, sparse ones with a complex sparse LU.
    """
    out = np.zeros((len(frequencies), len(dofs), len(dofs)), dtype=complex)
    n = mass.shape[0]
    rhs = np.zeros((n, len(dofs)), dtype=complex)
    rhs[dofs, np.arange(len(dofs))] = 1.0
    for i, f in enumerate(frequencies):
        w = 2 * math.pi * float(f)
        z = stiffness - (w * w) * mass + (1j * w) * damping
        if sp.issparse(z):
            x = spla.splu(sp.csc_matrix(z)).solve(rhs)
        else:
            x = np.linalg.solve(z, rhs)
        out[i] = x[dofs]
    return out


@contextlib.contextmanager
def _one_blas_thread() -> Iterator[None]:
    """Build with one BLAS thread: the same bits on every machine load, fewer spinning threads."""
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        yield
        return
    with threadpool_limits(limits=1, user_api='blas'):
        yield


def substructure_block(op: FoundationOperator, pier_height: float, pier_elements: int,
                       pier_section: BeamSection, pier_rayleigh: tuple[float, float]
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the reduced substructure under the column: (M, C, K, head rows, soil-point rows).

    The coordinates are [master (6), the basis's]: ``op`` (of
    :func:`pile_soil_operator` with the same column) less its column, the model
    the time stepping uses, seen from the cap's master as
    :func:`~.master_response.master_response` sees the unreduced one.
    """
    column = _column(pier_height, pier_elements, pier_section, pier_rayleigh)
    lead = column[0].shape[0] - NODE_DOFS
    if op.size <= lead + NODE_DOFS or op.summary.get('column_dofs') != lead + NODE_DOFS:
        raise FoundationError(f'the operator has {op.summary.get("column_dofs")} column DOFs, '
                              f'the column given {lead + NODE_DOFS}')
    blocks = []
    for full, col in zip((op.mass, op.damping, op.stiffness), column):
        sub = np.array(full[lead:, lead:], dtype=float)
        sub[:NODE_DOFS, :NODE_DOFS] -= col[lead:, lead:]
        blocks.append(sub)
    return (blocks[0], blocks[1], blocks[2], np.asarray(op.pile_heads)[:, lead:],
            np.asarray(op.soil_points)[:, lead:])
