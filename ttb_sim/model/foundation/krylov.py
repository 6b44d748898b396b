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
The reduction basis of a tied pile-soil model: static modes and second-order Krylov vectors.

The soil-pile-cap interior is the static (constraint) modes of the master,
Psi = -K_ii^-1 K_ib, plus a basis V of second-order block Krylov vectors of the
master loads B: at each real shift s >= 0 the pencil Z = K + s C + s^2 M is
symmetric positive definite, is factorised once (CHOLMOD), and the sequence
r_1 = Z^-1 B, r_j = -Z^-1 ((C + 2 s M) r_{j-1} + M r_{j-2}) (the SOAR
recurrence of Bai & Su 2005, orthogonalised as it goes) spans the response.
With ``shift_axis='imaginary'`` the shift is s = i w, solved through the LDL^T
factors of the real 2n form of the complex symmetric Z. Each mirror-symmetry
class of the master loads is solved on its own part of the unknowns
(:func:`mirror_parts`, :mod:`.mirror_classes`). The vectors of all
shifts, less their master part, are mass-orthonormalised with deflation
(:mod:`.reduction` describes the whole reduction).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import math
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ttb_sim.fe.complex_solve import (factorize_complex, factorize_positive_definite,
                                      pardiso_available, resolve_method)
from ttb_sim.fe.factorization import available, factorize, resolve
from ttb_sim.model.foundation.mirror_classes import (class_coordinates, invariant,
                                                     symmetry_classes)
from ttb_sim.model.foundation.records import ReductionParameters
from ttb_sim.model.foundation.tied import TiedSubstructure

LOG = logging.getLogger(__name__)

Solve = Callable[[np.ndarray], np.ndarray]

FACTORIZATION = 'cholmod'
"""Factorisation of the positive definite pencils (the static stiffness and the real shifts)
without MKL PARDISO (falls back as :func:`factorize` says)."""


def positive_definite_method() -> str:
    """
    Return the factorisation of the positive definite pencils: ``pardiso`` or FACTORIZATION's.

    PARDISO's Cholesky when the ``pardiso`` extra is installed: 14 times faster
    than CHOLMOD on a 61 k-unknown class of a 0.5 m block
    (:func:`~ttb_sim.fe.complex_solve.factorize_positive_definite`).
    """
    return 'pardiso' if pardiso_available() else resolve(FACTORIZATION)


def _positive_definite_solve(a: sp.csr_matrix) -> Solve:
    """Return a solve of the symmetric positive definite a (:func:`positive_definite_method`)."""
    if positive_definite_method() == 'pardiso':
        return factorize_positive_definite(a).solve
    return factorize(a, method=FACTORIZATION).solve


@dataclass(frozen=True)
class MirrorPart:
    """
    One mirror-symmetry class of the master: its components, coordinates P and matrices.

    ``stiffness``, ``damping`` and ``mass`` are P^T K P, P^T C P and P^T M P,
    restricted once for every shift (:func:`mirror_parts`).
    """

    components: tuple[int, ...]
    coordinates: sp.csr_matrix
    stiffness: sp.csr_matrix
    damping: sp.csr_matrix
    mass: sp.csr_matrix

    def lifted(self, solve: Solve) -> Solve:
        """Return the whole-space solve x = P (P^T Z P)^-1 P^T r of a class's loads r."""
        p = self.coordinates
        return lambda rhs: p @ solve(p.T @ rhs)


def reduction_basis(tied: TiedSubstructure, reduction: ReductionParameters,
                    progress: Callable[[int], None] | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the static modes Psi (n_x, 6) and the interior Krylov basis V (n_x - 6, r).

    Psi has the identity on the master and the static interior response
    -K_ii^-1 K_ib below it; V is mass-orthonormal (V^T M_ii V = I) and zero
    on the master. See the module docstring. ``progress(done)`` is called
    after each shift with the number of shifts finished (the static one first).
    """
    report = progress if progress is not None else (lambda done: None)
    c, m = tied.damping, tied.mass
    n = tied.size
    weight = m.diagonal()
    b = np.zeros((n, 6))
    b[:6] = np.eye(6)
    parts = mirror_parts(tied)
    x0 = np.empty((n, 6))
    blocks: list[np.ndarray] = []
    for part in parts:  # one factorisation in memory at a time
        static = part.lifted(_positive_definite_solve(part.stiffness))
        cols = list(part.components)
        x0[:, cols] = static(b[:, cols])
        if 0.0 in reduction.shifts:
            blocks += _soar(static, c, m, weight, b[:, cols], reduction.levels,
                            reduction.tolerance)
        del static
    psi = np.empty((n, 6))
    psi[:6] = np.eye(6)
    psi[6:] = np.linalg.solve(x0[:6].T, x0[6:].T).T
    del x0
    done = 0
    if 0.0 in reduction.shifts:
        done += 1
        report(done)
    for f in reduction.shifts:
        w = 2 * math.pi * float(f)
        if w == 0:
            continue
        for part in parts:
            blocks += _shift_blocks(tied, part, w, reduction, weight, b)
        LOG.debug('reduction: %d Krylov blocks after the shift at %g Hz', len(blocks), f)
        done += 1
        report(done)
    w_all = np.hstack(blocks)
    del blocks
    interior = w_all[6:] - psi[6:] @ w_all[:6]
    del w_all
    return psi, _orthonormal(interior, weight[6:], reduction.tolerance)


def mirror_parts(tied: TiedSubstructure) -> list[MirrorPart]:
    """
    Return the master's mirror-symmetry classes that K, C and M keep apart.

    Each class is solved on its own part of the unknowns (about a quarter of
    them for a centred group: about a sixteenth of the work of a factorisation
    of the whole, which is what the class split is for). A model whose matrices
    break the mirror is solved whole (one part of all six components).
    """
    matrices = (tied.stiffness, tied.damping, tied.mass)
    whole = [MirrorPart(tuple(range(6)), sp.identity(tied.size, format='csr'), *matrices)]
    classes = [(comps, class_coordinates(tied.model, tied.kept, comps, planes))
               for comps, planes in symmetry_classes(tied.model, tied.transform)]
    if len(classes) == 1:
        return whole
    if not all(invariant(matrices, p) for _, p in classes):
        LOG.info("reduction: the matrices break the mesh's mirror symmetry; solving the "
                 'whole system at each shift')
        return whole
    return [MirrorPart(comps, p, *((p.T @ a @ p).tocsr() for a in matrices))
            for comps, p in classes]


def _shift_blocks(tied: TiedSubstructure, part: MirrorPart, w: float,
                  reduction: ReductionParameters, weight: np.ndarray,
                  b: np.ndarray) -> list[np.ndarray]:
    """Return one class's Krylov blocks at the shift w (rad/s) on ``reduction``'s axis."""
    c, m = tied.damping, tied.mass
    cols = list(part.components)
    if reduction.shift_axis == 'real':
        pencil = _symmetric(part.stiffness + w * part.damping + (w * w) * part.mass)
        solve = part.lifted(_positive_definite_solve(pencil))
        return _soar(solve, (c + 2 * w * m).tocsr(), m, weight, b[:, cols],
                     reduction.levels, reduction.tolerance)
    solve = part.lifted(_complex_solver(part.stiffness, part.damping, part.mass, w))
    found = _soar(solve, (c + 2j * w * m).tocsr(), m, weight, b[:, cols].astype(complex),
                  reduction.levels, reduction.tolerance)
    return [piece for q in found for piece in (q.real, q.imag)]


def _symmetric(a: sp.spmatrix) -> sp.csr_matrix:
    a = sp.csr_matrix(a)
    return ((a + a.T) * 0.5).tocsr()


def _complex_solver(k: sp.csr_matrix, c: sp.csr_matrix, m: sp.csr_matrix,
                    w: float) -> Callable[[np.ndarray], np.ndarray]:
    """
    Return a solve of Z(i w) x = r, Z = K - w^2 M + i w C (complex symmetric).

    By MKL PARDISO's complex symmetric factorisation when it is installed (the
    ``pardiso`` extra: measured about 30x faster here); otherwise through the
    real symmetric indefinite form [[A, B], [B, -A]] [x_r; -x_i] = [r_r; r_i]
    with A = K - w^2 M, B = w C, factorised by LDL^T (QDLDL, AMD order; SuperLU
    in symmetric mode without the qdldl wheel).
    """
    if resolve_method('auto') == 'pardiso':
        factor = factorize_complex(_symmetric(k + (1j * w) * c - (w * w) * m), 'pardiso')
        return factor.solve
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
