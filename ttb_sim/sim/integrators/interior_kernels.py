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
The two kernels of a Newmark step with condensed interiors (:mod:`.condensed`).

Inside a step, between the kept system's effective load and its solve,
:func:`interior_load` adds each interior's force on its boundary; after the
step's end state, :func:`interior_finish` advances each interior's modes. The
arrays are those of :meth:`~.condensed.ModalInteriors.packed`; with no
interior (start = [0]) both do nothing. Their numpy twin is the whole-system
Newmark step itself (``test/sim/test_condensed.py``).
"""

from __future__ import annotations

import numpy as np

from ttb_sim.sim.kernel_registry import KernelTable


def interior_load(start: np.ndarray, boundary: np.ndarray, rho: np.ndarray,
                  sigma: np.ndarray, p_hat: np.ndarray,
                  d_m: np.ndarray, d_c: np.ndarray, eta: np.ndarray, e: np.ndarray,
                  pre: np.ndarray, h_a: np.ndarray, h_v: np.ndarray,
                  load: np.ndarray) -> None:
    """
    Take each interior's force on its boundary off the effective load ``load``.

    pre = rho eta + sigma e (kept for :func:`interior_finish`), then
    load[b] -= Re(p_hat^T pre) + d_m h_a[b] + d_c h_v[b].
    """
    nb = boundary.shape[1]
    for p in range(start.shape[0] - 1):
        for k in range(start[p], start[p + 1]):
            pre[k] = rho[k] * eta[k] + sigma[k] * e[k]
        for j in range(nb):
            acc = 0.0
            for k in range(start[p], start[p + 1]):
                acc += (p_hat[k, j] * pre[k]).real
            for m in range(nb):
                dof = boundary[p, m]
                acc += d_m[p, j, m] * h_a[dof] + d_c[p, j, m] * h_v[dof]
            load[boundary[p, j]] -= acc


def interior_finish(start: np.ndarray, boundary: np.ndarray, sigma: np.ndarray,
                    e_hat: np.ndarray, eta: np.ndarray, e: np.ndarray, pre: np.ndarray,
                    u: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
    """Advance each interior's modes: e = e_hat (a_b, v_b, u_b), eta = pre + sigma e."""
    nb = boundary.shape[1]
    for p in range(start.shape[0] - 1):
        for k in range(start[p], start[p + 1]):
            s = 0.0j
            for j in range(nb):
                dof = boundary[p, j]
                s += e_hat[k, 0, j] * a[dof] + e_hat[k, 1, j] * v[dof] + e_hat[k, 2, j] * u[dof]
            e[k] = s
            eta[k] = pre[k] + sigma[k] * s


KERNELS = KernelTable({'interior_load': interior_load, 'interior_finish': interior_finish})
"""The condensed interiors' kernels."""
