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
Sparse direct factorisations behind one function, :func:`factorize`.

A constant matrix (a Newmark effective matrix, a static stiffness) is factorised
once and then solved for many right-hand sides. The methods:

``superlu``
    scipy's SuperLU LU with its default COLAMD column order: general (no
    symmetry used), the validated reference.
``superlu_sym``
    SuperLU in symmetric mode: minimum-degree order on A + A^T, diagonal
    pivots. Pure scipy; about a third of the fill of ``superlu`` on the track.
``cholmod``
    CHOLMOD's supernodal Cholesky (fill-reducing AMD order) through the
    ``cholespy`` wheel, which bundles its own single-threaded reference BLAS.
    The fastest solve in isolation and with many right-hand sides.
``qdldl``
    QDLDL's LDL^T with AMD order through the ``qdldl`` wheel: cheap to
    factorise, one right-hand side at a time; the fastest inside the time
    step (docs/performance.md).

The symmetric methods read one triangle and need a symmetric positive
definite (``cholmod``) or quasi-definite (``qdldl``, ``superlu_sym``) matrix;
:func:`factorize` checks symmetry to round-off. When the package of a method is
not installed, :func:`factorize` falls back to the other wheel, else to
``superlu_sym``, with a warning, so a plain scipy installation runs every
variant.

Every method is deterministic: the same matrix and right-hand side give the
same bits on every call and every run.
"""

from __future__ import annotations

import importlib.util
import logging
from typing import Any, Callable, Protocol

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ttb_sim.errors import FEError
from ttb_sim.fe import compiled
from ttb_sim.fe.bisection import BisectedFactorization, level_bisection

log = logging.getLogger(__name__)

METHODS = ('superlu', 'superlu_sym', 'cholmod', 'qdldl')
"""Names accepted by :func:`factorize`."""
FALLBACKS = ('qdldl', 'cholmod', 'superlu_sym')
"""Symmetric methods in order of preference when the requested one's package is missing."""
SYMMETRY_TOLERANCE = 1e-12
"""Largest |A - A^T| accepted by the symmetric methods, relative to max |A|."""
_PACKAGES = {'cholmod': 'cholespy', 'qdldl': 'qdldl'}
SPLIT_METHODS = ('qdldl',)
"""Methods whose factors ``split`` reads (QDLDL's L, D and order, from the ``qdldl`` wheel)."""
SPLIT_MIN_SIZE = 4000
"""Fewest unknowns that ``split`` divides (the track models have 20 000-48 000; moving forces
on girders alone, about 1 300, gain nothing from a second core)."""


class Factorization(Protocol):
    """A factorised square matrix that solves A x = b."""

    method: str
    """The method actually used (after any fallback)."""

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Return x with A x = rhs, for rhs of shape (n,) or (n, k)."""


def available(method: str) -> bool:
    """Tell whether a method's package is installed (scipy's are always)."""
    package = _PACKAGES.get(method)
    return package is None or importlib.util.find_spec(package) is not None


def resolve(method: str) -> str:
    """
    Return the method that :func:`factorize` will use for a requested one.

    Raises
    ------
    FEError
        For an unknown method name (the message lists the allowed ones).

    """
    if method not in METHODS:
        message = f'unknown factorisation method {method!r}; allowed: {", ".join(METHODS)}'
        raise FEError(message)
    if available(method):
        return method
    return next(m for m in FALLBACKS if available(m))


def factorize(matrix: sp.spmatrix | sp.sparray, *, method: str = 'superlu',
              split: bool = False) -> Factorization:
    """
    Factorise a sparse square matrix once for repeated solves.

    Parameters
    ----------
    matrix : scipy sparse matrix, shape (n, n)
        The matrix; symmetric (to round-off) for every method but ``superlu``.
    method : str
        One of :data:`METHODS`. A method whose package is missing falls back
        to the first available of :data:`FALLBACKS` (logged as a warning).
    split : bool
        Split a long, thin matrix at a small separator near its middle and
        solve the two halves on two threads (:mod:`ttb_sim.fe.bisection`;
        exact to round-off), when the method is one of :data:`SPLIT_METHODS`,
        numba is installed and the matrix has at least :data:`SPLIT_MIN_SIZE`
        unknowns and such a separator; otherwise as without.

    Returns
    -------
    Factorization
        An object with ``solve(rhs)`` for rhs of shape (n,) or (n, k) and the
        ``method`` actually used.

    Raises
    ------
    FEError
        For an unknown method, a non-square matrix, or a matrix that is not
        symmetric for a symmetric method.

    """
    used = resolve(method)
    if used != method:
        log.warning('%s (package %s) is not installed; factorising with %s instead',
                    method, _PACKAGES[method], used)
    shape = matrix.shape
    if len(shape) != 2 or shape[0] != shape[1]:
        raise FEError(f'factorize needs a square matrix, got shape {shape}')
    if used == 'superlu':
        return _SuperLU(sla.splu(sp.csc_matrix(matrix)), used)
    csc = sp.csc_matrix(matrix)
    _check_symmetric(csc, used)
    if split and used in SPLIT_METHODS and shape[0] >= SPLIT_MIN_SIZE and compiled.available():
        halves = level_bisection(csc)
        if halves is not None:
            log.debug('solving %d unknowns as two halves of %d and %d and a separator of %d',
                      shape[0], halves.first.size, halves.second.size, halves.separator.size)
            return BisectedFactorization(csc, halves,
                                         lambda block: factorize(block, method=used))
    if used == 'superlu_sym':
        lu = sla.splu(csc, permc_spec='MMD_AT_PLUS_A', diag_pivot_thresh=0.0,
                      options={'SymmetricMode': True})
        return _SuperLU(lu, used)
    if used == 'cholmod':
        return _Cholmod(csc)
    return _Qdldl(csc)


def _check_symmetric(matrix: sp.csc_matrix, method: str) -> None:
    scale = float(abs(matrix).max()) if matrix.nnz else 0.0
    asymmetry = float(abs(matrix - matrix.T).max()) if matrix.nnz else 0.0
    if asymmetry > SYMMETRY_TOLERANCE * scale:
        message = (f'method {method!r} needs a symmetric matrix; max |A - A^T| = '
                   f'{asymmetry:.3g} against max |A| = {scale:.3g}')
        raise FEError(message)


class _SuperLU:
    """SuperLU factors (scipy), general or symmetric mode."""

    def __init__(self, lu: Any, method: str) -> None:
        self._lu = lu
        self.method = method
        self.nnz = int(lu.L.nnz + lu.U.nnz)
        """Non-zeros of the factors L + U."""

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Return x with A x = rhs, for rhs of shape (n,) or (n, k)."""
        return self._lu.solve(rhs)


class _Cholmod:
    """CHOLMOD supernodal Cholesky of the lower triangle, through cholespy."""

    method = 'cholmod'

    def __init__(self, matrix: sp.csc_matrix) -> None:
        import cholespy

        lower = sp.tril(matrix, format='csc')
        lower.sort_indices()
        self._n = matrix.shape[0]
        self._solver = cholespy.CholeskySolverD(
            self._n, lower.indptr.astype(np.int32), lower.indices.astype(np.int32),
            np.ascontiguousarray(lower.data, dtype=np.float64), cholespy.MatrixType.CSC)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Return x with A x = rhs, for rhs of shape (n,) or (n, k)."""
        b = np.ascontiguousarray(rhs, dtype=np.float64)
        x = np.empty_like(b)
        self._solver.solve(b, x)
        return x


class _Qdldl:
    """QDLDL's LDL^T with AMD order, through the qdldl wheel."""

    method = 'qdldl'

    def __init__(self, matrix: sp.csc_matrix) -> None:
        import qdldl

        self._solver = qdldl.Solver(sp.triu(matrix, format='csc'), upper=True)
        self._solve: Callable[[np.ndarray], np.ndarray] = self._solver.solve

    def factors(self) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray]:
        """Return (L strictly lower, D, p) with A[p][:, p] = (I + L) diag(D) (I + L)^T."""
        lower, diagonal, permutation = self._solver.factors()
        return sp.csc_matrix(lower), np.asarray(diagonal), np.asarray(permutation)

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Return x with A x = rhs, for rhs of shape (n,) or (n, k)."""
        b = np.asarray(rhs, dtype=np.float64)
        if b.ndim == 1:
            return self._solve(b)
        if b.shape[1] == 0:
            return np.zeros(b.shape)
        return np.column_stack([self._solve(np.ascontiguousarray(b[:, j]))
                                for j in range(b.shape[1])]).reshape(b.shape)
