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
Compiled kernels of the lean step (numba), each with a pure-numpy twin.

A kernel is used only where a measurement showed it wins (README, Benchmark)
and only when numba imports; otherwise the lean step takes the numpy twin,
which computes the same numbers. The kernels are compiled on first use
(about a second, cached on disk where the package directory is writable).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ttb_sim.fe.compiled import jit as compiled_jit
from ttb_sim.sim import contact_kernels

ENABLED = True
"""False makes :func:`compiled` return None, so the lean step takes the numpy twins."""


PARALLEL = frozenset({'rail_predictor'})
"""Kernels compiled ``parallel`` (their loop over cars on numba's threads; each car's
arithmetic is the same on any thread, so the results do not depend on the thread count)."""


def compiled(name: str) -> Callable[..., Any] | None:
    """Return the compiled lean-step kernel ``name`` (compiled on first call), or None."""
    return jit(_KERNELS[name], parallel=name in PARALLEL)


def jit(kernel: Callable[..., Any], *, parallel: bool = False) -> Callable[..., Any] | None:
    """
    Return ``kernel`` compiled by numba (:func:`ttb_sim.fe.compiled.jit`), or None.

    None when numba is not installed or :data:`ENABLED` is False.
    """
    return compiled_jit(kernel, parallel=parallel) if ENABLED else None


def _moving_load(positions: np.ndarray, forces: np.ndarray, h: float, n_el: int,
                 length: float, dofs: np.ndarray, out: np.ndarray) -> None:
    """
    Sum the consistent load of vertical axle forces on the girder into ``out``.

    The same arithmetic as :meth:`ttb_sim.sim.lean.MovingLoad._rows` followed
    by ``np.bincount``, axle by axle.
    """
    out[:] = 0.0
    for i in range(positions.shape[0]):
        x = positions[i]
        s = x / h
        e = min(max(np.floor(s), 0.0), n_el - 1)
        element = int(e)
        xi = min(max(s - e, 0.0), 1.0)
        if x >= 0.0 and x <= length:
            weight = -forces[i]
        else:
            weight = 0.0
        xi2 = xi * xi
        xi3 = xi2 * xi
        r0 = (1.0 - 3.0 * xi2 + 2.0 * xi3) * weight
        r1 = ((xi3 - 2.0 * xi2 + xi) * -h) * weight
        r2 = (3.0 * xi2 - 2.0 * xi3) * weight
        r3 = ((xi3 - xi2) * -h) * weight
        out[dofs[element, 0]] += r0
        out[dofs[element, 1]] += r1
        out[dofs[element, 2]] += r2
        out[dofs[element, 3]] += r3


def _history(u: np.ndarray, v: np.ndarray, a: np.ndarray, a0: float, a1: float,
             h_v: np.ndarray, h_a: np.ndarray) -> None:
    """Newmark history terms into h_v, h_a: the arithmetic of the lean numpy path."""
    two_a1 = 2.0 * a1
    for i in range(u.shape[0]):
        h_v[i] = u[i] * -a1 - v[i]
        h_a[i] = u[i] * -a0 - v[i] * two_a1 - a[i]


def _finish(u: np.ndarray, a0: float, a1: float, h_v: np.ndarray,
            h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (a1 u + h_v, a0 u + h_a) as new vectors."""
    n = u.shape[0]
    v = np.empty(n)
    a = np.empty(n)
    for i in range(n):
        v[i] = a1 * u[i] + h_v[i]
        a[i] = a0 * u[i] + h_a[i]
    return v, a


def _effective_load(indptr: np.ndarray, indices: np.ndarray, data: np.ndarray,
                    history: np.ndarray, force: np.ndarray, out: np.ndarray) -> None:
    """
    Fill out = force - A history (A in CSR, unsigned indices).

    Each row's sum runs in scipy's order (from zero, entry by entry), so the
    result is ``force - A @ history`` bit for bit; measured twice as fast as
    scipy's mat-vec on the paper_ttbi matrices (README, Benchmark).
    """
    for i in range(out.shape[0]):
        acc = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            acc += data[p] * history[indices[p]]
        out[i] = force[i] - acc


_KERNELS: dict[str, Callable[..., Any]] = {
    'effective_load': _effective_load, 'moving_load': _moving_load, 'history': _history,
    'finish': _finish,
    'rail_rows': contact_kernels.rail_rows, 'rail_values': contact_kernels.rail_values,
    'rail_load': contact_kernels.rail_load, 'contact_newton': contact_kernels.contact_newton,
    'rail_predictor': contact_kernels.rail_predictor,
    'rail_irregularity': contact_kernels.rail_irregularity,
    'contact_setup': contact_kernels.contact_setup, 'rail_check': contact_kernels.rail_check}
