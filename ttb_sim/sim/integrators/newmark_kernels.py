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
Compiled loops of the lean Newmark step (numba sources), each with a numpy twin.

The twins are the numpy expressions of :class:`ttb_sim.sim.integrators.newmark.Newmark`,
which runs them where numba is absent; the loops compute the same numbers
(``test/sim/test_kernels.py``).
"""

from __future__ import annotations

import numpy as np

from ttb_sim.fe.bisection import ldl_solve
from ttb_sim.sim.kernel_registry import KernelTable

HELPERS = ('history', 'effective_load', 'finish_into', 'ldl_solve', 'solve_ldl',
           'newmark_ldl_step', 'largest_magnitude')
"""Functions the kernels call (compiled first, :func:`ttb_sim.fe.compiled.jit`); the compiled
loops of the couplings call :func:`newmark_ldl_step`."""


def history(u: np.ndarray, v: np.ndarray, a: np.ndarray, a0: float, a1: float,
            h_v: np.ndarray, h_a: np.ndarray) -> None:
    """Newmark history terms into h_v, h_a: the arithmetic of the lean numpy path."""
    two_a1 = 2.0 * a1
    for i in range(u.shape[0]):
        h_v[i] = u[i] * -a1 - v[i]
        h_a[i] = u[i] * -a0 - v[i] * two_a1 - a[i]


def finish_into(u: np.ndarray, a0: float, a1: float, h_v: np.ndarray, h_a: np.ndarray,
                v: np.ndarray, a: np.ndarray) -> None:
    """Write v = a1 u + h_v and a = a0 u + h_a (the end-of-step velocity and acceleration)."""
    for i in range(u.shape[0]):
        v[i] = a1 * u[i] + h_v[i]
        a[i] = a0 * u[i] + h_a[i]


def finish(u: np.ndarray, a0: float, a1: float, h_v: np.ndarray,
           h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (a1 u + h_v, a0 u + h_a) as new vectors."""
    n = u.shape[0]
    v = np.empty(n)
    a = np.empty(n)
    finish_into(u, a0, a1, h_v, h_a, v, a)
    return v, a


def effective_load(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
                   history: np.ndarray, force: np.ndarray, out: np.ndarray) -> None:
    """
    Fill out = force - A history (A in CSR, unsigned indices).

    Each row's sum runs in scipy's order (from zero, entry by entry), so the
    result is ``force - A @ history`` bit for bit; measured twice as fast as
    scipy's mat-vec on the paper_ttbi matrices (docs/performance.md).
    """
    for i in range(out.shape[0]):
        acc = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            acc += data[p] * history[indices[p]]
        out[i] = force[i] - acc


def largest_magnitude(x: np.ndarray, peak: float) -> float:
    """
    Return max(peak, max |x|): the divergence check of a compiled loop.

    NaN as soon as an entry is NaN, as ``np.max(np.abs(x))`` gives it.
    """
    for i in range(x.shape[0]):
        value = abs(x[i])
        if value != value:
            return value
        if value > peak:
            peak = value
    return peak


def solve_ldl(lp: np.ndarray, li: np.ndarray, lx: np.ndarray, dinv: np.ndarray,
              order: np.ndarray, b: np.ndarray, work: np.ndarray, x: np.ndarray) -> None:
    """
    Solve A x = b with A's QDLDL factors, A[p][:, p] = (I + L) D (I + L)^T (``order`` = p).

    QDLDL's own loops (:func:`ttb_sim.fe.bisection.ldl_solve`), then x[p] = the
    permuted solution; ``work`` is a vector of the same size. The same operations
    as the ``qdldl`` wheel's solve, so the same bits (``test/sim/test_realtime.py``).
    """
    ldl_solve(lp, li, lx, dinv, order, b, work)
    for i in range(order.shape[0]):
        x[order[i]] = work[i]


def newmark_ldl_step(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
                     lp: np.ndarray, li: np.ndarray, lx: np.ndarray, dinv: np.ndarray,
                     order: np.ndarray, a0: float, a1: float, u: np.ndarray, v: np.ndarray,
                     a: np.ndarray, force: np.ndarray, history_buffer: np.ndarray,
                     rhs: np.ndarray, work: np.ndarray) -> None:
    """
    Advance u, v, a (in place) by one lean Newmark step under ``force`` (at t_{n+1}).

    The lean step of :class:`~ttb_sim.sim.integrators.newmark.Newmark` in one
    loop: :func:`history` into ``history_buffer`` = [h_a | h_v], the effective
    load with the stacked [M | C] (CSR ``indptr``, ``indices``, ``data``), the
    solve with the effective matrix's QDLDL factors (:func:`solve_ldl`) and
    :func:`finish_into`.
    """
    n = u.shape[0]
    h_a = history_buffer[:n]
    h_v = history_buffer[n:]
    history(u, v, a, a0, a1, h_v, h_a)
    effective_load(indptr, indices, data, history_buffer, force, rhs)
    solve_ldl(lp, li, lx, dinv, order, rhs, work, u)
    finish_into(u, a0, a1, h_v, h_a, v, a)


KERNELS = KernelTable({'effective_load': effective_load, 'history': history, 'finish': finish,
                       'newmark_ldl_step': newmark_ldl_step})
"""The lean Newmark step's kernels."""
