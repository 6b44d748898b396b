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
A sparse solve split into two independent halves and their separator, for two cores.

A track on a bridge is a long, thin structure: cutting it across at one
place (the rails, the slab and the girder there) splits its matrix into two
halves that do not touch, joined only through a small separator S::

    [A11  0   A1s] [x1]   [b1]
    [ 0  A22  A2s] [x2] = [b2]
    [As1 As2  Ass] [xs]   [bs]

Each half is factorised on its own; with W_i = A_ii^-1 A_is and the Schur
complement Ss = Ass - As1 W1 - As2 W2 (small, dense, factorised once) a solve is

    y_i = A_ii^-1 b_i                    (the two halves at the same time)
    xs = Ss^-1 (bs - As1 y1 - As2 y2)
    x_i = y_i - W_i xs

which is block Gaussian elimination: exact, up to round-off. The Newmark
effective matrix of the time step is dominated by its mass term, so its
inverse is local and so is W_i (its columns fall below round-off of their
largest a few metres from the cut; entries below :data:`W_DROP` of their
column's largest are dropped, so the last line costs little).

Both halves and the last two lines run in one compiled kernel (numba), the
halves' triangular solves (on QDLDL's LDL^T factors of each half) on two
threads. Without numba the matrix is not split.

The cut is found from the matrix graph alone (:func:`level_bisection`):
breadth-first levels from a far end of the structure, the smallest level near
the middle, then only the nodes of it that touch the far side. A matrix whose
graph has no small separator near its middle (a 3-D block, a disconnected
one) is not split.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.csgraph as csgraph

from ttb_sim.fe.compiled import jit, sparse_arrays

MIN_SHARE = 0.4
"""Least share of the matrix entries in each half: the separator is sought where both
halves have at least this much, so that the two solves take about as long."""
MAX_SEPARATOR = 400
"""Largest separator accepted (unknowns); a larger one means a graph that is not long and
thin (the dense Schur complement and the couplings W would cost more than they save)."""
MAX_SEPARATOR_SHARE = 0.02
"""Largest separator accepted as a share of the unknowns (a track: 0.06 % of the reduced
window, 0.2 % of the whole paper_ttbi model; a 3-D block several per cent)."""
W_DROP = 1e-17
"""Entries of W_i = A_ii^-1 A_is below this fraction of their column's largest are dropped
(below the round-off of the column's largest entry)."""
HELPERS = ('ldl_solve', '_finish_half')
"""Functions the kernel calls (:func:`ttb_sim.fe.compiled.jit` compiles them first)."""
prange = range
"""The kernel's parallel loop; numba's ``prange`` once the parallel kernel is compiled."""


@dataclass(frozen=True)
class Bisection:
    """Two halves of the unknowns that share no matrix entry, and their separator."""

    first: np.ndarray
    """Unknowns of the first half (increasing)."""
    second: np.ndarray
    """Unknowns of the second half (increasing)."""
    separator: np.ndarray
    """Unknowns that join them (increasing)."""


def level_bisection(matrix: sp.spmatrix | sp.sparray) -> Bisection | None:
    """
    Split the unknowns of a symmetric sparse matrix at a small separator near the middle.

    Breadth-first levels are taken from a far end (the last node reached from
    node 0); each level separates the levels before it from those after. Among
    the levels with at least :data:`MIN_SHARE` of the unknowns on each side the
    smallest is taken, reduced to the nodes that touch the next level (the rest
    join the first half).

    Returns
    -------
    Bisection or None
        None when the graph is disconnected, too small to split, or has no
        separator of at most :data:`MAX_SEPARATOR` unknowns and
        :data:`MAX_SEPARATOR_SHARE` of them there.

    """
    n = matrix.shape[0]
    if n < 3:
        return None
    graph = sp.csr_matrix(matrix, copy=True)
    graph.data = np.ones_like(graph.data)
    depth = csgraph.shortest_path(graph, unweighted=True, indices=0, directed=False)
    if not np.all(np.isfinite(depth)):
        return None
    end = int(np.argmax(depth))
    level = csgraph.shortest_path(graph, unweighted=True, indices=end,
                                  directed=False).astype(np.int64)
    counts = np.bincount(level)
    # The halves' shares in matrix entries (the solves' work grows with them).
    weight = np.bincount(level, weights=np.diff(graph.indptr))
    before = np.cumsum(weight) - weight
    after = graph.nnz - before - weight
    least = MIN_SHARE * graph.nnz
    candidates = np.flatnonzero((before >= least) & (after >= least))
    if candidates.size == 0:
        return None
    cut = int(candidates[np.argmin(counts[candidates])])
    # Keep in the separator only the nodes of the cut level with a neighbour beyond it.
    coo = graph.tocoo()
    beyond = level[coo.col] == cut + 1
    touching = np.zeros(n, dtype=bool)
    touching[coo.row[beyond]] = True
    separator = np.flatnonzero((level == cut) & touching)
    if not 0 < separator.size <= min(MAX_SEPARATOR, MAX_SEPARATOR_SHARE * n):
        return None
    first = np.flatnonzero((level < cut) | ((level == cut) & ~touching))
    second = np.flatnonzero(level > cut)
    return Bisection(first, second, separator)


class BisectedFactorization:
    """
    Solve A x = b as two halves at the same time and their separator (module docstring).

    Parameters
    ----------
    matrix : scipy sparse matrix
        Symmetric (to round-off), square.
    bisection : Bisection
        The halves and separator (:func:`level_bisection`).
    factorize_block : callable
        Factorises one half (a sparse matrix) with QDLDL: returns an object with
        ``solve(rhs)``, ``method`` and ``factors()`` (L strictly lower, D, the
        permutation P, as the ``qdldl`` wheel gives them).

    """

    def __init__(self, matrix: sp.spmatrix | sp.sparray, bisection: Bisection,
                 factorize_block: Callable[[sp.csr_matrix], Any]) -> None:
        kernel = jit(bisected_solve, parallel=True)
        if kernel is None:
            raise RuntimeError('BisectedFactorization needs numba')
        self._kernel = kernel
        csr = sp.csr_matrix(matrix)
        self.bisection = bisection
        sep = bisection.separator
        self._n = csr.shape[0]
        schur = csr[sep][:, sep].toarray()
        self._halves: list[tuple[np.ndarray, ...]] = []
        self._work: list[np.ndarray] = []
        self.couplings_nnz = 0
        """Non-zeros kept in W_1 and W_2."""
        blocks = [factorize_block(csr[part][:, part])
                  for part in (bisection.first, bisection.second)]
        self.method: str = blocks[0].method
        for part, block in zip((bisection.first, bisection.second), blocks):
            lower, diagonal, permutation = block.factors()
            permutation = np.asarray(permutation, dtype=np.int64)
            order = part[permutation]
            couple = sp.csr_matrix(csr[sep][:, order])      # (ns, n_i), factor order
            w = np.asarray(block.solve(csr[part][:, sep].toarray()),
                           dtype=float).reshape(part.size, sep.size)[permutation]
            schur -= couple @ w
            scale = np.max(np.abs(w), axis=0, keepdims=True)
            w[np.abs(w) < W_DROP * scale] = 0.0
            w_csr = sp.csr_matrix(w)
            self.couplings_nnz += w_csr.nnz
            self._halves.append((*sparse_arrays(sp.csc_matrix(lower)),
                                 1.0 / np.asarray(diagonal, dtype=np.float64),
                                 order.astype(np.uint64), *sparse_arrays(w_csr),
                                 *sparse_arrays(couple)))
            self._work.append(np.empty(part.size))
        self._sep = sep.astype(np.uint64)
        self._schur_inverse = np.linalg.inv(0.5 * (schur + schur.T))

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Return x with A x = rhs, for rhs of shape (n,) or (n, k)."""
        b = np.asarray(rhs, dtype=np.float64)
        if b.ndim == 2:
            return np.column_stack([self.solve(b[:, j]) for j in range(b.shape[1])]
                                   ).reshape(b.shape)
        b = np.ascontiguousarray(b)
        x = np.empty(self._n)
        self._kernel(*self._halves[0], *self._halves[1], self._sep, self._schur_inverse, b,
                     self._work[0], self._work[1], x)
        return x


def ldl_solve(lp: np.ndarray, li: np.ndarray, lx: np.ndarray, dinv: np.ndarray,
              order: np.ndarray, b: np.ndarray, work: np.ndarray) -> None:
    """Solve (I + L) D (I + L)^T work = b[order] (L strictly lower, CSC): QDLDL's loops."""
    n = dinv.shape[0]
    for i in range(n):
        work[i] = b[order[i]]
    for j in range(n):
        wj = work[j]
        for p in range(lp[j], lp[j + 1]):
            work[li[p]] -= lx[p] * wj
    for i in range(n):
        work[i] *= dinv[i]
    for j in range(n - 1, -1, -1):
        acc = work[j]
        for p in range(lp[j], lp[j + 1]):
            acc -= lx[p] * work[li[p]]
        work[j] = acc


def _finish_half(wp: np.ndarray, wi: np.ndarray, wx: np.ndarray, order: np.ndarray,
                 xs: np.ndarray, work: np.ndarray, x: np.ndarray) -> None:
    """Scatter x[order] = work - W xs (W in CSR, factor order)."""
    for i in range(order.shape[0]):
        acc = work[i]
        for p in range(wp[i], wp[i + 1]):
            acc -= wx[p] * xs[wi[p]]
        x[order[i]] = acc


def bisected_solve(lp1: np.ndarray, li1: np.ndarray, lx1: np.ndarray, dinv1: np.ndarray,
                   order1: np.ndarray, wp1: np.ndarray, wi1: np.ndarray, wx1: np.ndarray,
                   cp1: np.ndarray, ci1: np.ndarray, cx1: np.ndarray,
                   lp2: np.ndarray, li2: np.ndarray, lx2: np.ndarray, dinv2: np.ndarray,
                   order2: np.ndarray, wp2: np.ndarray, wi2: np.ndarray, wx2: np.ndarray,
                   cp2: np.ndarray, ci2: np.ndarray, cx2: np.ndarray,
                   sep: np.ndarray, schur_inverse: np.ndarray, b: np.ndarray,
                   work1: np.ndarray, work2: np.ndarray, x: np.ndarray) -> None:
    """
    Solve A x = b by halves (module docstring): the two halves on two threads.

    Per half i: its LDL^T factors (L CSC, 1/D, ``order`` = the unknown of each
    factor row), W_i (CSR, rows in factor order) and A_si (CSR, columns in
    factor order); ``work1`` and ``work2`` are scratch of the halves' sizes.
    """
    for k in prange(2):
        if k == 0:
            ldl_solve(lp1, li1, lx1, dinv1, order1, b, work1)
        else:
            ldl_solve(lp2, li2, lx2, dinv2, order2, b, work2)
    ns = sep.shape[0]
    residual = np.empty(ns)
    for s in range(ns):
        acc = b[sep[s]]
        for p in range(cp1[s], cp1[s + 1]):
            acc -= cx1[p] * work1[ci1[p]]
        for p in range(cp2[s], cp2[s + 1]):
            acc -= cx2[p] * work2[ci2[p]]
        residual[s] = acc
    xs = np.zeros(ns)
    for s in range(ns):
        acc = 0.0
        for t in range(ns):
            acc += schur_inverse[s, t] * residual[t]
        xs[s] = acc
        x[sep[s]] = acc
    for k in prange(2):
        if k == 0:
            _finish_half(wp1, wi1, wx1, order1, xs, work1, x)
        else:
            _finish_half(wp2, wi2, wx2, order2, xs, work2, x)
