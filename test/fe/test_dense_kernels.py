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

"""The compiled loops' small dense solve against numpy's (LAPACK gesv) as its oracle."""

from hypothesis import given, settings
from hypothesis import strategies as st
import numpy as np
import pytest

from ttb_sim.fe import compiled
from ttb_sim.fe.dense_kernels import solve_in_place


def _solvers() -> list:
    kernels = [solve_in_place]
    made = compiled.jit(solve_in_place)
    if made is not None:
        kernels.append(made)
    return kernels


@pytest.mark.parametrize('solve', _solvers(), ids=lambda f: 'numba' if hasattr(f, 'py_func')
                         else 'python')
@settings(max_examples=60, deadline=None)
@given(n=st.integers(1, 24), seed=st.integers(0, 2**32 - 1))
def test_matches_numpy_solve(solve, n: int, seed: int) -> None:
    """A random well-conditioned system (and one needing row swaps) to 1e-12 of numpy's x."""
    rng = np.random.default_rng(seed)
    a = rng.standard_normal((n, n)) + n * np.eye(n)[rng.permutation(n)]  # pivots off diagonal
    b = rng.standard_normal(n)
    expected = np.linalg.solve(a, b)
    work, x = a.copy(), b.copy()
    assert solve(work, x)
    assert np.allclose(x, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize('solve', _solvers(), ids=lambda f: 'numba' if hasattr(f, 'py_func')
                         else 'python')
def test_singular_is_reported(solve) -> None:
    """An exactly singular matrix returns False instead of dividing by zero."""
    a = np.array([[1.0, 2.0], [2.0, 4.0]])
    assert not solve(a, np.array([1.0, 1.0]))
    assert not solve(np.zeros((3, 3)), np.ones(3))


def test_needs_the_row_swap() -> None:
    """[[0, 1], [1, 0]] has a zero first pivot: partial pivoting solves it exactly."""
    x = np.array([2.0, 3.0])
    assert solve_in_place(np.array([[0.0, 1.0], [1.0, 0.0]]), x)
    assert x.tolist() == [3.0, 2.0]
