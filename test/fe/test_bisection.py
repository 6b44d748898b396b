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

"""The solve by halves: a valid cut of long matrices, none of others, the direct solve's x."""

import numpy as np
import pytest
import scipy.sparse as sp
from ttb_sim.fe import bisection as bs
from ttb_sim.fe import compiled
from ttb_sim.fe import factorization as fz

pytest.importorskip('numba')
pytest.importorskip('qdldl')


def _ladder(n_sections: int, width: int = 8, seed: int = 0) -> sp.csr_matrix:
    """
    Return a long, thin SPD matrix like a Newmark track matrix.

    ``width`` unknowns per cross-section, coupled within the section and to the
    next two sections, dominated by a mass-like diagonal.
    """
    rng = np.random.default_rng(seed)
    n = n_sections * width
    rows, cols, vals = [], [], []
    for shift in range(1, 3 * width):
        i = np.arange(n - shift)
        keep = rng.random(i.size) < 0.6
        rows.append(i[keep])
        cols.append(i[keep] + shift)
        vals.append(-rng.random(keep.sum()))
    r, c, v = (np.concatenate(x) for x in (rows, cols, vals))
    off = sp.coo_matrix((v, (r, c)), shape=(n, n))
    off = off + off.T
    diagonal = np.asarray(abs(off).sum(axis=1)).ravel() + 10.0 + rng.random(n)
    return sp.csr_matrix(off + sp.diags(diagonal))


def test_cut_separates_two_balanced_halves():
    a = _ladder(800)
    cut = bs.level_bisection(a)
    assert cut is not None
    every = np.concatenate([cut.first, cut.second, cut.separator])
    assert np.array_equal(np.sort(every), np.arange(a.shape[0]))   # each unknown once
    assert a[cut.first][:, cut.second].nnz == 0                     # the halves never touch
    assert cut.separator.size <= 3 * 8                              # one cross-section band
    share = [a[p].nnz / a.nnz for p in (cut.first, cut.second)]
    assert min(share) >= bs.MIN_SHARE - 0.01


def test_no_cut_of_a_disconnected_or_bulky_matrix():
    a = _ladder(100)
    assert bs.level_bisection(sp.block_diag([a, a])) is None
    # A 3-D grid has no small separator near its middle.
    line = sp.diags([-1.0, 2.5, -1.0], [-1, 0, 1], shape=(14, 14))
    eye = sp.eye(14)
    grid = (sp.kron(sp.kron(line, eye), eye) + sp.kron(sp.kron(eye, line), eye)
            + sp.kron(sp.kron(eye, eye), line))
    assert bs.level_bisection(grid) is None


@pytest.mark.parametrize('seed', [0, 1])
def test_split_solve_is_the_direct_solve_to_round_off(seed):
    a = _ladder(700, seed=seed)
    split = fz.factorize(a, method='qdldl', split=True)
    plain = fz.factorize(a, method='qdldl')
    assert isinstance(split, bs.BisectedFactorization)
    assert not isinstance(plain, bs.BisectedFactorization)
    rng = np.random.default_rng(seed)
    b = rng.standard_normal(a.shape[0])
    x = split.solve(b)
    exact = plain.solve(b)
    assert np.max(np.abs(x - exact)) <= 1e-13 * np.max(np.abs(exact))
    assert np.max(np.abs(a @ x - b)) <= 1e-12 * np.max(np.abs(b))
    many = rng.standard_normal((a.shape[0], 3))
    assert np.allclose(split.solve(many), plain.solve(many), rtol=0, atol=1e-13)


def test_one_thread_or_two_give_the_same_bits():
    a = _ladder(700)
    split = fz.factorize(a, method='qdldl', split=True)
    b = np.random.default_rng(4).standard_normal(a.shape[0])
    parallel = split.solve(b)
    with compiled.PARALLEL_LOCK:   # busy: the serial compilation of the kernel runs
        serial = split.solve(b)
    assert np.array_equal(parallel, serial)
    assert np.array_equal(split.solve(b), parallel)


def test_small_or_superlu_matrices_are_not_split():
    a = _ladder(100)                       # 800 < SPLIT_MIN_SIZE unknowns
    assert not isinstance(fz.factorize(a, method='qdldl', split=True),
                          bs.BisectedFactorization)
    big = _ladder(700)
    assert not isinstance(fz.factorize(big, method='superlu', split=True),
                          bs.BisectedFactorization)
