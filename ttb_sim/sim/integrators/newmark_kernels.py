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

from ttb_sim.sim.kernel_registry import KernelTable


def history(u: np.ndarray, v: np.ndarray, a: np.ndarray, a0: float, a1: float,
            h_v: np.ndarray, h_a: np.ndarray) -> None:
    """Newmark history terms into h_v, h_a: the arithmetic of the lean numpy path."""
    two_a1 = 2.0 * a1
    for i in range(u.shape[0]):
        h_v[i] = u[i] * -a1 - v[i]
        h_a[i] = u[i] * -a0 - v[i] * two_a1 - a[i]


def finish(u: np.ndarray, a0: float, a1: float, h_v: np.ndarray,
           h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (a1 u + h_v, a0 u + h_a) as new vectors."""
    n = u.shape[0]
    v = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        v[i] = a1 * u[i] + h_v[i]
        a[i] = a0 * u[i] + h_a[i]
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


KERNELS = KernelTable({'effective_load': effective_load, 'history': history, 'finish': finish})
"""The lean Newmark step's kernels."""
