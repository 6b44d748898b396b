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
Linear interiors condensed out of a Newmark step, exactly, in complex modal coordinates.

A reduced pile-soil substructure solved with the girders (``solver.coupling:
monolithic``) puts dense blocks of some hundred coordinates into the global
system: its mass, damping and stiffness are full matrices, so every step pays
for them in the [M | C] mat-vec and in both triangular solves (two thirds of a
``live_coupled`` step). Those coordinates meet the rest of the bridge only
through the pier top; inside, the system is linear and time-invariant, and so
its Newmark step can be taken in closed form.

Let the interior x (n coordinates) meet the boundary b (the pier top) through
M_ib, C_ib, K_ib:

    M_ii x'' + C_ii x' + K_ii x = -g,    g = M_ib b'' + C_ib b' + K_ib b.

In first-order form y = [x; x'], y' = A y + E g with A = [[0, I], [-M_ii^-1
K_ii, -M_ii^-1 C_ii]] and E = [0; -M_ii^-1]. Newmark's average acceleration
is the trapezoidal rule on this form (substituting v_{n+1} into the
displacement update gives u + h v + h^2 (a + a') / 4). With A = W diag(lambda)
W^-1 and eta = W^-1 y the rule decouples mode by mode:

    eta' = rho eta + sigma (e + e'),   e = W^-1 E g,
    rho = (1 + h lambda / 2) / (1 - h lambda / 2),   sigma = (h / 2) / (1 - h lambda / 2).

The force of the interior on the boundary at the end of the step,
F = M_bi x'' + C_bi x' + K_bi x, is then P W eta' - M_bi M_ii^-1 g' with
P = [K_bi - M_bi M_ii^-1 K_ii, C_bi - M_bi M_ii^-1 C_ii]; with g' affine in the
boundary's unknown displacement (Newmark's b'' = a0 b + h_a, b' = a1 b + h_v),
the boundary equation gains

* a constant matrix on the boundary, the Schur complement -S_bi S_ii^-1 S_ib of
  the effective matrix S = K + a1 C + a0 M (symmetric: the kept system is
  factorised by LDL^T as before, now without the interiors), and
* a load, -Re(P W (rho eta + sigma e)) - D (M_ib h_a + C_ib h_v), with
  D = P W diag(sigma) W^-1 E - M_bi M_ii^-1 (kernel :func:`interior_load`),

and after the solve each mode takes e' from the boundary's new state
(:func:`interior_finish`). For a real system the modes come in conjugate pairs:
one of each pair is kept, its contributions doubled. A step then costs
O(modes x boundary) instead of O(n^2); the interior's own coordinates are
recovered only when a frame needs them (:meth:`ModalInteriors.expand`).

It is Newmark's step on the whole system in another order of operations, so
it equals the ``qdldl`` variant's frames to round-off amplified by the
condition of W, which is checked at build time: above :data:`CONDITION_LIMIT`
the interiors stay in the global system (``test/sim/test_condensed.py`` holds
the closed form, the Schur complement and the whole step against the full
system).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
from typing import Sequence

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

log = logging.getLogger(__name__)

CONDITION_LIMIT = 1e8
"""Largest condition number of a substructure's modal matrix W condensed (module docstring):
round-off grows with it (1-norm; 2.2e3 on ``live_coupled``'s piers)."""
PAIR_TOLERANCE = 1e-9
"""Relative imaginary part below which an eigenvalue counts as real."""


@dataclass(frozen=True)
class InteriorModes:
    """
    The modal form of one interior (module docstring), one mode of each conjugate pair.

    Attributes
    ----------
    interior, boundary : int arrays
        Free-DOF indices of the interior and of the boundary it meets.
    rho, sigma : complex (m,)
        The trapezoidal step of each mode.
    p_hat : complex (m, nb)
        P W: the boundary force of each mode's amplitude (times 2 for a mode that
        stands for a conjugate pair, as every row below).
    e_hat : complex (m, 3, nb)
        W^-1 E applied to M_ib, C_ib, K_ib: each mode's input from the boundary's
        acceleration, velocity and displacement.
    d_m, d_c : float (nb, nb)
        D M_ib and D C_ib (the boundary load's part in the boundary's own history).
    schur : float (nb, nb)
        -S_bi S_ii^-1 S_ib, added to the kept system's effective matrix.
    w_state : complex (3 n, m)
        The interior displacement, velocity and acceleration of each mode's amplitude
        (rows of W, and of W diag(lambda) for the acceleration; weights applied),
        stacked for one product a frame.
    input_acceleration : float (n, 3 nb)
        [M_ii^-1 M_ib, M_ii^-1 C_ib, M_ii^-1 K_ib]: the acceleration's direct part.
    w_inv : complex (m, 2n)
        Rows of W^-1: the modal amplitudes of a state [x; x'].
    condition : float
        Condition number (1-norm) of W in the scaled coordinates it was found in.

    """

    interior: np.ndarray
    boundary: np.ndarray
    rho: np.ndarray
    sigma: np.ndarray
    p_hat: np.ndarray
    e_hat: np.ndarray
    d_m: np.ndarray
    d_c: np.ndarray
    schur: np.ndarray
    w_state: np.ndarray
    w_inv: np.ndarray
    condition: float
    input_acceleration: np.ndarray

    def amplitudes(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Return the modal amplitudes eta of the interior state in u, v (free DOFs)."""
        i = self.interior
        return self.w_inv @ np.concatenate([u[i], v[i]])

    def inputs(self, u: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Return e = W^-1 E g for the boundary state in u, v, a (free DOFs)."""
        b = self.boundary
        return np.einsum('kqj,qj->k', self.e_hat, np.stack([a[b], v[b], u[b]]))

    def interior_state(self, eta: np.ndarray, u: np.ndarray, v: np.ndarray,
                       a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return the interior's x, x', x'' from its modal amplitudes.

        x'' = Re(W_a eta) - M_ii^-1 g with g from the boundary's state in u, v, a
        (free DOFs): the equation of motion, which Newmark's step satisfies.
        """
        b, n = self.boundary, self.interior.size
        xva = (self.w_state @ eta).real
        xva[2 * n:] -= self.input_acceleration @ np.concatenate([a[b], v[b], u[b]])
        return xva[:n], xva[n:2 * n], xva[2 * n:]


def _dense(matrix: sp.csr_matrix, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    return np.asarray(matrix[rows][:, cols].todense())


def interior_modes(mass: sp.csr_matrix, damping: sp.csr_matrix, stiffness: sp.csr_matrix,
                   interior: np.ndarray, boundary: np.ndarray,
                   dt: float) -> InteriorModes:
    """Return the modal form of one interior meeting the rest only at ``boundary``."""
    i, b = interior, boundary
    m_ii, c_ii, k_ii = (_dense(x, i, i) for x in (mass, damping, stiffness))
    coupling = np.stack([_dense(x, i, b) for x in (mass, damping, stiffness)])
    m_bi, c_bi, k_bi = (_dense(x, b, i) for x in (mass, damping, stiffness))
    n = i.size
    m_inv = sla.inv(m_ii)
    w, w_inv, lam, condition = _modes(m_ii, c_ii, k_ii)
    e_matrix = np.vstack([np.zeros((n, n)), -m_inv])
    e_full = w_inv @ e_matrix                                   # (2n, n)
    p_matrix = np.hstack([k_bi - m_bi @ m_inv @ k_ii, c_bi - m_bi @ m_inv @ c_ii])
    p_full = p_matrix @ w                                       # (nb, 2n)
    half = 0.5 * dt
    rho = (1.0 + half * lam) / (1.0 - half * lam)
    sigma = half / (1.0 - half * lam)
    d = ((p_full * sigma) @ e_full).real - m_bi @ m_inv          # (nb, n)
    a0, a1 = 4.0 / dt**2, 2.0 / dt
    s_ii = k_ii + a1 * c_ii + a0 * m_ii
    s_ib = coupling[2] + a1 * coupling[1] + a0 * coupling[0]
    schur = -s_ib.T @ sla.solve(s_ii, s_ib, assume_a='pos')
    scale = np.maximum(np.abs(lam), 1.0)
    real = np.abs(lam.imag) <= PAIR_TOLERANCE * scale
    keep = real | (lam.imag > 0.0)
    if 2 * int(np.count_nonzero((lam.imag > 0.0) & ~real)) + int(np.count_nonzero(real)) != 2 * n:
        raise ValueError("the interior's eigenvalues do not come in conjugate pairs")
    weight = np.where(real[keep], 1.0, 2.0)
    e_kept = e_full[keep]
    return InteriorModes(
        interior=i, boundary=b, rho=rho[keep], sigma=sigma[keep],
        p_hat=np.ascontiguousarray((p_full[:, keep] * weight).T),
        e_hat=np.ascontiguousarray(np.stack([e_kept @ coupling[q] for q in range(3)], axis=1)),
        d_m=d @ coupling[0], d_c=d @ coupling[1], schur=0.5 * (schur + schur.T),
        w_state=np.vstack([w[:n, keep] * weight, w[n:, keep] * weight,
                           w[n:, keep] * (weight * lam[keep])]),
        w_inv=np.ascontiguousarray(w_inv[keep]), condition=condition,
        input_acceleration=np.hstack([m_inv @ coupling[q] for q in range(3)]))


def _modes(m_ii: np.ndarray, c_ii: np.ndarray, k_ii: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """
    Return (W, W^-1, lambda, condition) of A = [[0, I], [-M^-1 K, -M^-1 C]].

    The eigenvectors are found in scaled coordinates: x = L^-T z (M = L L^T) and
    the velocity divided by s = sqrt(omega_min omega_max), the geometric mean of
    the undamped interior's extreme frequencies. The masses of a reduced pier span
    nine decades (mass-normalised Krylov vectors beside the pier column's nodes):
    unscaled, W's 2-norm condition is 5.3e6 on ``live_coupled``'s piers; scaled, 607 (the
    best power of ten, s = 100, gives 570). ``condition`` is the scaled W's, in the
    1-norm (from the inverse the condensation needs anyway); it bounds the round-off.
    """
    n = m_ii.shape[0]
    lower = np.linalg.cholesky(m_ii)
    k_t = sla.solve_triangular(lower, sla.solve_triangular(lower, k_ii, lower=True).T,
                               lower=True)
    c_t = sla.solve_triangular(lower, sla.solve_triangular(lower, c_ii, lower=True).T,
                               lower=True)
    omega_sq = np.abs(sla.eigvalsh(0.5 * (k_t + k_t.T)))
    scale = float(np.sqrt(np.sqrt(max(omega_sq.min(), 1e-12) * max(omega_sq.max(), 1e-12))))
    a_t = np.block([[np.zeros((n, n)), scale * np.eye(n)], [-k_t / scale, -c_t]])
    lam, w_t = sla.eig(a_t)
    w_t_inv = sla.inv(w_t)
    condition = float(np.linalg.norm(w_t, 1) * np.linalg.norm(w_t_inv, 1))
    # x = L^-T z, x' = s L^-T z'; back: z = L^T x, z' = L^T x' / s
    w = np.vstack([sla.solve_triangular(lower.T, w_t[:n], lower=False),
                   scale * sla.solve_triangular(lower.T, w_t[n:], lower=False)])
    w_inv = np.hstack([w_t_inv[:, :n] @ lower.T, (w_t_inv[:, n:] @ lower.T) / scale])
    return w, w_inv, lam, condition


def _split_block(pattern: sp.csr_matrix, block: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (interior, boundary) of a block: its DOFs without / with couplings outside it."""
    inside = np.zeros(pattern.shape[0], dtype=bool)
    inside[block] = True
    coo = pattern[block].tocoo()
    touches = np.zeros(block.size, dtype=bool)
    touches[coo.row[~inside[coo.col]]] = True
    return np.sort(block[~touches]), np.sort(block[touches])


@dataclass(frozen=True)
class ModalInteriors:
    """
    Every condensed interior of a system and the kept system they leave (module docstring).

    Attributes
    ----------
    keep : int array
        Free DOFs of the kept system, in order.
    modes : tuple of InteriorModes
    stiffness_correction : sparse (k, k)
        The Schur complements on the kept DOFs, to add to the kept stiffness (it
        enters the effective matrix only).

    """

    keep: np.ndarray
    modes: tuple[InteriorModes, ...]
    stiffness_correction: sp.csr_matrix

    @property
    def kept_index(self) -> np.ndarray:
        """Index of each free DOF in the kept system (-1 for an interior one)."""
        n = self.keep.size + sum(m.interior.size for m in self.modes)
        index = np.full(n, -1, dtype=np.intp)
        index[self.keep] = np.arange(self.keep.size)
        return index

    def kept_matrices(self, mass: sp.csr_matrix, damping: sp.csr_matrix,
                      stiffness: sp.csr_matrix
                      ) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix]:
        """Return the kept system's M, C and K (K with the Schur complements added)."""
        k = self.keep
        return (sp.csr_matrix(mass[k][:, k]), sp.csr_matrix(damping[k][:, k]),
                sp.csr_matrix(stiffness[k][:, k] + self.stiffness_correction))

    def packed(self) -> tuple[np.ndarray, ...]:
        """
        Return the arrays the kernels read, every interior's modes end to end.

        (start (P + 1,), boundary (P, nb) kept indices, rho, sigma, p_hat,
        e_hat, d_m (P, nb, nb), d_c).
        """
        index = self.kept_index
        counts = [m.rho.size for m in self.modes]
        start = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        nb = self.modes[0].boundary.size if self.modes else 0
        boundary = np.array([index[m.boundary] for m in self.modes],
                            dtype=np.int64).reshape(len(self.modes), nb)

        def cat(name: str, shape: tuple[int, ...], dtype: type) -> np.ndarray:
            parts = [getattr(m, name) for m in self.modes]
            return (np.ascontiguousarray(np.concatenate(parts)) if parts
                    else np.zeros(shape, dtype=dtype))

        return (start, boundary, cat('rho', (0,), complex), cat('sigma', (0,), complex),
                cat('p_hat', (0, nb), complex),
                cat('e_hat', (0, 3, nb), complex),
                np.array([m.d_m for m in self.modes]).reshape(len(self.modes), nb, nb),
                np.array([m.d_c for m in self.modes]).reshape(len(self.modes), nb, nb))

    def amplitudes(self, u: np.ndarray, v: np.ndarray, a: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """Return (eta, e) of every interior, end to end, from full free-DOF state vectors."""
        if not self.modes:
            return np.zeros(0, complex), np.zeros(0, complex)
        eta = np.concatenate([m.amplitudes(u, v) for m in self.modes])
        e = np.concatenate([m.inputs(u, v, a) for m in self.modes])
        return eta, e

    def expand(self, kept: Sequence[np.ndarray], eta: np.ndarray,
               full: Sequence[np.ndarray]) -> None:
        """Write the kept state and the interiors' x, x', x'' into the full state vectors."""
        for values, out in zip(kept, full):
            out[self.keep] = values
        offset = 0
        for m in self.modes:
            part = eta[offset:offset + m.rho.size]
            offset += m.rho.size
            states = m.interior_state(part, *full)
            for values, out in zip(states, full):
                out[m.interior] = values


def condense_interiors(mass: sp.spmatrix, damping: sp.spmatrix, stiffness: sp.spmatrix,
                       blocks: Sequence[np.ndarray], dt: float) -> ModalInteriors | None:
    """
    Return the interiors of ``blocks`` condensed (module docstring), or None.

    Each block (free-DOF indices of one substructure) is split into the DOFs
    coupled to anything outside it (its boundary) and the rest (its interior).
    None when there is nothing to condense, when the boundaries differ in size,
    or when a modal matrix's condition exceeds :data:`CONDITION_LIMIT` (logged):
    the caller then keeps the whole system.
    """
    mass, damping, stiffness = (sp.csr_matrix(x) for x in (mass, damping, stiffness))
    pattern = (abs(mass) + abs(damping) + abs(stiffness)).tocsr()
    modes = []
    for block in blocks:
        interior, boundary = _split_block(pattern, np.asarray(block, dtype=np.intp))
        if interior.size == 0:
            continue
        try:
            mode = interior_modes(mass, damping, stiffness, interior, boundary, dt)
        except (ValueError, np.linalg.LinAlgError) as exc:
            log.warning('a substructure interior stays in the global system: %s', exc)
            return None
        if mode.condition > CONDITION_LIMIT:
            log.warning('a substructure interior stays in the global system: its modal '
                        'matrix has condition %.3g > %.3g', mode.condition, CONDITION_LIMIT)
            return None
        modes.append(mode)
    if not modes or len({m.boundary.size for m in modes}) != 1:
        return None
    n = mass.shape[0]
    removed = np.concatenate([m.interior for m in modes])
    keep = np.setdiff1d(np.arange(n), removed)
    index = np.full(n, -1, dtype=np.intp)
    index[keep] = np.arange(keep.size)
    rows, cols, values = [], [], []
    for m in modes:
        kb = index[m.boundary]
        rows.append(np.repeat(kb, kb.size))
        cols.append(np.tile(kb, kb.size))
        values.append(m.schur.ravel())
    correction = sp.csr_matrix((np.concatenate(values), (np.concatenate(rows),
                                                         np.concatenate(cols))),
                               shape=(keep.size, keep.size))
    log.info('condensed %d substructure interiors (%d coordinates, %d modes kept; '
             'modal matrix condition up to %.3g)', len(modes), removed.size,
             sum(m.rho.size for m in modes), max(m.condition for m in modes))
    return ModalInteriors(keep=keep, modes=tuple(modes), stiffness_correction=correction)
