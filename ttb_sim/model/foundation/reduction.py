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
   cap top (u_i = u_m + theta x r_i), and a pier column of beam elements
   (:func:`~.operator.pier_column`, Rayleigh C = a0 M + a1 K) standing on
   that master; the column's top node is q[:6].
3. The reduction. The column and the master stay physical. The soil-pile-cap
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
   w, but far dearer to factorise.) The vectors
   of all shifts, less their master part (so that V vanishes on the master),
   are mass-orthonormalised with deflation. The damping is projected, not
   diagonalised (the boundary dashpots make it far from proportional). The
   projection is Galerkin, so the reduced matrices are symmetric, M and K
   positive definite, and the static flexibility is the unreduced one to
   round-off (Psi is in the basis and K-orthogonal to V).

q = [column nodes from the top down to the one above the master (6 each),
master (6), generalised coordinates of V]. Outputs are the model's
observation operators through the basis: pile-head mean displacements and
soil points, and (:class:`~.operator.InterfaceRows`) the interface tractions
at the initial tangent with their Mohr-Coulomb strength, so that
:func:`interface_mobilisation` can show a run stayed linear.

The operator of a given set of inputs is cached on disk (``$TTB_SIM_CACHE``
or ``~/.cache/ttb_sim``) under a hash of every input; the build is
deterministic, so a cache hit gives the same bits as a fresh build. A
corrupt or unwritable cache is logged and bypassed.
"""

from __future__ import annotations

import contextlib
from dataclasses import dataclass
import hashlib
import json
import logging
import math
import os
from pathlib import Path
import time
from typing import Any, Callable, Iterator, Optional

import numpy as np
import scipy
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ttb_sim.fe.beam import BeamSection, NODE_DOFS
from ttb_sim.fe.factorization import available, factorize, resolve
from ttb_sim.fe.mesh import node_dofs
from ttb_sim.model.foundation.operator import (FoundationOperator, InterfaceRows,
                                               pier_column)
from ttb_sim.model.foundation.records import (FoundationError, ReductionParameters,
                                              Substructure)
from ttb_sim.model.foundation.soil_mesh import CAP, planned_nodes
from ttb_sim.model.foundation.substructure import build, PileSoilModel

LOG = logging.getLogger(__name__)

BUILD_SECONDS_PER_DOF = 509.0 / (81_648 * 5)
"""CPU seconds per DOF and shift of a reduction, measured on the paper mesh (81 648 DOFs, five
shifts, 509 s on this 2-core machine): the order of magnitude the first-build notice gives."""

FORMAT = 2
"""Version of the reduction and of its cache files; part of the cache key."""
FACTORIZATION = 'cholmod'
"""Factorisation of the shifted pencils (falls back as :func:`factorize` says)."""


@dataclass(frozen=True)
class TiedSubstructure:
    """
    The linear pile-soil model with the cap top tied to a 6-DOF master (sparse).

    Coordinates x = [master (ux, uy, uz, rx, ry, rz), free DOFs not on the cap
    top]; the full displacement is u = ``transform`` @ x.

    Attributes
    ----------
    model : PileSoilModel
        The finite-element substructure.
    transform : csr (n_dofs, n_x)
        u = T x.
    mass, damping, stiffness : csr (n_x, n_x)
        T^T M T, T^T C T, T^T K T (K with the interface at its initial tangent).
    master : array (3,)
        Master position: the group centre on the cap top (m).

    """

    model: PileSoilModel
    transform: sp.csr_matrix
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    master: np.ndarray

    @property
    def size(self) -> int:
        """Number of coordinates n_x."""
        return int(self.transform.shape[1])


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


def check_spec(spec: Substructure) -> None:
    """
    Refuse a substructure that cannot carry a reduced pier.

    Raises
    ------
    FoundationError
        No piles, the cap disabled, or a boundary without static support.

    """
    if spec.piles is None:
        raise FoundationError('piles = none: a piled pier needs piles (set piles.rows and '
                              'piles.cols)')
    if not spec.cap.enabled:
        raise FoundationError('cap.enabled = False: the pier stands on the cap top; allowed '
                              'for a piled pier: cap.enabled = true')
    if spec.soil.boundary == 'lysmer':
        raise FoundationError("soil.boundary = 'lysmer' leaves the block without static "
                              "support; allowed for a piled pier: 'viscoelastic' or 'fixed'")


def tie_cap(model: PileSoilModel) -> TiedSubstructure:
    """Return the linear model with the cap top tied rigidly to a master at its centre."""
    spec = model.spec
    check_spec(spec)
    assert spec.piles is not None
    nodes = model.mesh.nodes
    top = spec.cap.thickness
    cap_nodes = np.unique(model.mesh.cells[model.cell_kind == CAP])
    tied = cap_nodes[np.abs(nodes[cap_nodes, 2] - top) <= 1e-9 * max(1.0, top)]
    master = np.array([spec.piles.centre[0], spec.piles.centre[1], top], dtype=float)
    n_dofs = model.n_dofs
    on_top = np.zeros(n_dofs, dtype=bool)
    on_top[node_dofs(tied[:, None]).ravel()] = True
    kept = np.flatnonzero(model.free & ~on_top)
    r = nodes[tied] - master
    one = np.ones(len(tied))
    # u = u_m + theta x r: (theta_y r_z - theta_z r_y, theta_z r_x - theta_x r_z,
    # theta_x r_y - theta_y r_x)
    terms = [(0, 0, one), (0, 4, r[:, 2]), (0, 5, -r[:, 1]),
             (1, 1, one), (1, 5, r[:, 0]), (1, 3, -r[:, 2]),
             (2, 2, one), (2, 3, r[:, 1]), (2, 4, -r[:, 0])]
    rows = [kept] + [3 * tied + axis for axis, _, _ in terms]
    cols = [6 + np.arange(len(kept))] + [np.full(len(tied), c) for _, c, _ in terms]
    vals = [np.ones(len(kept))] + [v for _, _, v in terms]
    transform = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                      np.concatenate(cols))),
                              shape=(n_dofs, 6 + len(kept)))
    k = model.linear_stiffness() + model.initial_interface_stiffness()
    c = model.linear_damping()
    m = sp.diags(model.mass)
    t_t = transform.T.tocsr()

    def project(a: sp.spmatrix) -> sp.csr_matrix:
        out = (t_t @ a @ transform).tocsr()
        return ((out + out.T) * 0.5).tocsr()

    return TiedSubstructure(model, transform, project(m), project(c), project(k), master)


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
        op = _load(path)
        if op is not None:
            LOG.info('reduced pile-soil substructure read from the cache %s', path)
            return op
    nodes = planned_nodes(spec)
    # one line the user sees (the CLI shows warnings): the paper mesh takes minutes, once
    LOG.warning('reducing the pile-soil substructure of %d nodes (%d DOFs) with %d shifts x '
                '%d levels: about %.0f min of CPU the first time%s', nodes, 3 * nodes,
                len(reduction.shifts), reduction.levels,
                BUILD_SECONDS_PER_DOF * 3 * nodes * len(reduction.shifts) / 60.0,
                f', then read from {path.parent}' if path is not None else '')
    start = time.process_time()
    with _one_blas_thread():
        op = _build(spec, pier_height, pier_elements, pier_section, pier_rayleigh, reduction)
    LOG.info('reduced pile-soil substructure: %d full DOFs -> %d coordinates in %.1f s of CPU',
             op.summary['full_dofs'], op.size, time.process_time() - start)
    if path is not None:
        _save(path, op)
    return op


def _build(spec: Substructure, pier_height: float, pier_elements: int,
           pier_section: BeamSection, pier_rayleigh: tuple[float, float],
           reduction: ReductionParameters) -> FoundationOperator:
    tied = tie_cap(build(spec))
    psi, v = reduction_basis(tied, reduction)
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
               'f_max': model.summary['f_max'], 'factorization': resolve(FACTORIZATION)}
    return FoundationOperator(mass=mass, damping=damping, stiffness=stiffness,
                              pile_heads=heads, pile_positions=positions,
                              soil_points=points, soil_point_names=model.soil_points.names,
                              soil_point_positions=soil_positions,
                              depth=float(pier_height + spec.cap.thickness), summary=summary,
                              interface=_interface_rows(tied, phi, lead),
                              pile_rotations=rotations)


def reduction_basis(tied: TiedSubstructure, reduction: ReductionParameters
                    ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the static modes Psi (n_x, 6) and the interior Krylov basis V (n_x - 6, r).

    Psi has the identity on the master and the static interior response
    -K_ii^-1 K_ib below it; V is mass-orthonormal (V^T M_ii V = I) and zero
    on the master. See the module docstring.
    """
    k, c, m = tied.stiffness, tied.damping, tied.mass
    n = tied.size
    weight = m.diagonal()
    b = np.zeros((n, 6))
    b[:6] = np.eye(6)
    static = factorize(k, method=FACTORIZATION)
    x0 = static.solve(b)
    psi = np.empty((n, 6))
    psi[:6] = np.eye(6)
    psi[6:] = np.linalg.solve(x0[:6].T, x0[6:].T).T
    del x0
    blocks: list[np.ndarray] = []
    if 0.0 in reduction.shifts:
        blocks += _soar(static.solve, c, m, weight, b, reduction.levels, reduction.tolerance)
    del static  # one factorisation in memory at a time
    for f in reduction.shifts:
        w = 2 * math.pi * float(f)
        if w == 0:
            continue
        if reduction.shift_axis == 'real':
            solver = factorize(_symmetric(k + w * c + (w * w) * m), method=FACTORIZATION)
            blocks += _soar(solver.solve, (c + 2 * w * m).tocsr(), m, weight, b,
                            reduction.levels, reduction.tolerance)
            del solver
        else:
            solve = _complex_solver(k, c, m, w)
            found = _soar(solve, (c + 2j * w * m).tocsr(), m, weight, b.astype(complex),
                          reduction.levels, reduction.tolerance)
            del solve
            blocks += [part for q in found for part in (q.real, q.imag)]
        LOG.debug('reduction: %d Krylov blocks after the shift at %g Hz', len(blocks), f)
    w_all = np.hstack(blocks)
    del blocks
    interior = w_all[6:] - psi[6:] @ w_all[:6]
    del w_all
    return psi, _orthonormal(interior, weight[6:], reduction.tolerance)


def _symmetric(a: sp.spmatrix) -> sp.csr_matrix:
    a = sp.csr_matrix(a)
    return ((a + a.T) * 0.5).tocsr()


def _complex_solver(k: sp.csr_matrix, c: sp.csr_matrix, m: sp.csr_matrix,
                    w: float) -> Callable[[np.ndarray], np.ndarray]:
    """
    Return a solve of Z(i w) x = r, Z = K - w^2 M + i w C (complex symmetric).

    Through the real symmetric indefinite form [[A, B], [B, -A]] [x_r; -x_i] =
    [r_r; r_i] with A = K - w^2 M, B = w C, factorised by LDL^T (QDLDL, AMD
    order; SuperLU in symmetric mode without the qdldl wheel).
    """
    a = _symmetric(k - (w * w) * m)
    bb = _symmetric(w * c)
    big = sp.bmat([[a, bb], [bb, -a]], format='csc')
    lu = factorize(big, method='qdldl' if available('qdldl') else 'superlu_sym')
    n = a.shape[0]

    def solve(rhs: np.ndarray) -> np.ndarray:
        x = lu.solve(np.vstack([rhs.real, rhs.imag]))
        return x[:n] - 1j * x[n:]

    return solve


def _soar(solve: Callable[[np.ndarray], np.ndarray], d1: sp.csr_matrix, m: sp.csr_matrix,
          weight: np.ndarray, b: np.ndarray, levels: int, tol: float) -> list[np.ndarray]:
    """Return the blocks of the second-order Krylov sequence (weight-orthonormal)."""
    q, p = _block(solve(b), np.zeros_like(b), [], [], weight, tol)
    qs, ps = [q], [p]
    for _ in range(levels - 1):
        if qs[-1].shape[1] == 0:
            break
        r = solve(-(d1 @ qs[-1] + m @ ps[-1]))
        q, p = _block(r, qs[-1].copy(), qs, ps, weight, tol)
        qs.append(q)
        ps.append(p)
    return [q for q in qs if q.shape[1]]


def _block(r: np.ndarray, s: np.ndarray, qs: list[np.ndarray], ps: list[np.ndarray],
           weight: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormalise r against qs and within itself; apply the same to s against ps."""
    norms = np.sqrt(np.einsum('i,ij,ij->j', weight, r.conj(), r).real)
    for _ in range(2):
        for qb, pb in zip(qs, ps):
            h = qb.conj().T @ (weight[:, None] * r)
            r -= qb @ h
            s -= pb @ h
    root = np.sqrt(weight)
    qq, rr, piv = sla.qr(root[:, None] * r, mode='economic', pivoting=True)
    d = np.abs(np.diag(rr))
    keep = 0
    while keep < len(d) and d[keep] > tol * max(norms[piv[keep]], 1e-300):
        keep += 1
    t_inv = sla.solve_triangular(rr[:keep, :keep], np.eye(keep))
    return qq[:, :keep] / root[:, None], s[:, piv[:keep]] @ t_inv


def _orthonormal(w: np.ndarray, weight: np.ndarray, tol: float) -> np.ndarray:
    """
    Return a weight-orthonormal basis of the columns of w, dropping dependent ones.

    The columns come from vectors of unit weighted norm (their master part
    removed), so a direction is kept when what is left of it outside the
    others is above ``tol``.
    """
    root = np.sqrt(weight)
    if w.shape[1] == 0:
        return np.zeros((len(weight), 0))
    qq, rr, _ = sla.qr(root[:, None] * w, mode='economic', pivoting=True)
    keep = int(np.count_nonzero(np.abs(np.diag(rr)) > tol))
    return qq[:, :keep] / root[:, None]


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
                          rows(model.soil_points.operator))


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


# --------------------------------------------------------------------------- cache

def cache_directory() -> Path:
    """Return the cache directory: ``$TTB_SIM_CACHE`` or ``~/.cache/ttb_sim``."""
    env = os.environ.get('TTB_SIM_CACHE', '')
    return Path(env) if env else Path.home() / '.cache' / 'ttb_sim'


def cache_key(spec: Substructure, pier_height: float, pier_elements: int,
              pier_section: BeamSection, pier_rayleigh: tuple[float, float],
              reduction: ReductionParameters) -> str:
    """Return the SHA-256 of every input of :func:`pile_soil_operator` (and the code)."""
    digest = hashlib.sha256()
    text = repr((FORMAT, resolve(FACTORIZATION), np.__version__, scipy.__version__, spec,
                 float(pier_height), int(pier_elements),
                 tuple(float(v) for v in pier_rayleigh), reduction))
    digest.update(text.encode())
    for name in ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x'):
        digest.update(np.ascontiguousarray(getattr(pier_section, name), dtype=float).tobytes())
    return digest.hexdigest()


_ARRAYS = ('mass', 'damping', 'stiffness', 'pile_heads', 'pile_positions', 'soil_points',
           'soil_point_positions', 'pile_rotations')
_INTERFACE = ('normal', 'shear', 'sigma_n0', 'cohesion', 'tan_delta')


def _save(path: Path, op: FoundationOperator) -> None:
    arrays: dict[str, Any] = {name: getattr(op, name) for name in _ARRAYS}
    arrays['soil_point_names'] = np.array(op.soil_point_names, dtype=str)
    arrays['depth'] = np.array(op.depth)
    arrays['summary'] = np.array(json.dumps(op.summary))
    if op.interface is not None:
        arrays.update({f'interface_{n}': getattr(op.interface, n) for n in _INTERFACE})
    tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(tmp, 'wb') as handle:
            np.savez(handle, **arrays)
        os.replace(tmp, path)
        LOG.info('reduced pile-soil substructure cached in %s', path)
    except OSError as err:
        LOG.warning('could not write the cache %s (%s); continuing without it', path, err)
        with contextlib.suppress(OSError):
            tmp.unlink()


def _load(path: Path) -> Optional[FoundationOperator]:
    try:
        with np.load(path, allow_pickle=False) as data:
            got = {name: data[name] for name in data.files}
        n = got['mass'].shape[0]
        iface = None
        if 'interface_normal' in got:
            iface = InterfaceRows(**{name: got[f'interface_{name}'] for name in _INTERFACE})
            if iface.normal.shape[1] != n or iface.shear.shape != (2 * iface.n_points, n):
                raise FoundationError('interface rows of the wrong shape')
        op = FoundationOperator(**{name: got[name] for name in _ARRAYS},
                                soil_point_names=tuple(str(s) for s in got['soil_point_names']),
                                depth=float(got['depth']),
                                summary=json.loads(str(got['summary'])), interface=iface)
        square = all(getattr(op, a).shape == (n, n) for a in ('mass', 'damping', 'stiffness'))
        if (not square or op.pile_heads.shape != (3 * op.n_piles, n)
                or op.soil_points.shape != (3 * len(op.soil_point_names), n)):
            raise FoundationError('arrays of inconsistent shapes')
        return op
    except Exception as err:  # noqa: B902 - any unreadable cache file means: rebuild
        LOG.warning('the cache file %s is unreadable (%s); rebuilding', path,
                    f'{type(err).__name__}: {err}')
        return None


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
