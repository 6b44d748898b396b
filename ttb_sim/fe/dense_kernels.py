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
A small dense solve for the compiled loops: Gaussian elimination with partial pivoting.

:func:`solve_in_place` is what ``np.linalg.solve`` does for one right-hand side
(LAPACK's ``gesv``: row pivoting on the largest magnitude, then the two
triangular sweeps), written as plain loops so that a numba kernel can call it.
Inside numba, ``np.linalg.solve`` costs about 5 s of compilation on a cold
cache (its LAPACK binding, shape checks and error messages), more than the
rest of the quarter-car loop together; these loops compile in a fraction of a
second. It is meant for the few-by-few systems of the wheel couplings (one
row per axle: the quarter cars' Woodbury system, each car's contact Newton
step); the numpy paths keep ``np.linalg.solve`` and serve as its test oracle
(to round-off: the order of the operations differs).
"""

from __future__ import annotations

import numpy as np


def solve_in_place(a: np.ndarray, b: np.ndarray) -> bool:
    """
    Overwrite ``b`` with x, A x = b, destroying ``a`` (n x n, C order); False if A is singular.

    Exactly singular pivots (0.0) are reported, not divided by; a nearly
    singular A gives what elimination gives, as LAPACK does.
    """
    n = b.shape[0]
    for k in range(n):
        pivot = k
        largest = abs(a[k, k])
        for i in range(k + 1, n):
            if abs(a[i, k]) > largest:
                largest = abs(a[i, k])
                pivot = i
        if largest == 0.0:
            return False
        if pivot != k:
            for j in range(k, n):   # left of k: multipliers never read again
                a[k, j], a[pivot, j] = a[pivot, j], a[k, j]
            b[k], b[pivot] = b[pivot], b[k]
        inverse = 1.0 / a[k, k]
        for i in range(k + 1, n):
            factor = a[i, k] * inverse
            if factor != 0.0:
                for j in range(k + 1, n):
                    a[i, j] -= factor * a[k, j]
                b[i] -= factor * b[k]
    for k in range(n - 1, -1, -1):
        acc = b[k]
        for j in range(k + 1, n):
            acc -= a[k, j] * b[j]
        b[k] = acc / a[k, k]
    return True
