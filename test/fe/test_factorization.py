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

"""Sparse factorisations: every method solves like a dense solve, refuses what it cannot do."""

import logging

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from ttb_sim.fe import factorization as fz


def _spd(n: int = 60) -> sp.csc_matrix:
    """Return a beam-like SPD matrix: a 1-D Laplacian plus a consistent-mass-like term."""
    lap = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    mass = sp.diags([1.0, 4.0, 1.0], [-1, 0, 1], shape=(n, n)) / 6.0
    return sp.csc_matrix(1e6 * lap + 1e3 * mass)


@pytest.mark.parametrize('method', fz.METHODS)
def test_solves_like_dense_to_1e12(method):
    a = _spd()
    rng = np.random.default_rng(3)
    b = rng.standard_normal((a.shape[0], 3))
    f = fz.factorize(a, method=method)
    exact = np.linalg.solve(a.toarray(), b)
    x = f.solve(b)
    assert x.shape == b.shape
    assert np.max(np.abs(x - exact)) <= 1e-12 * np.max(np.abs(exact))
    one = f.solve(b[:, 0])
    assert one.shape == (a.shape[0],)
    assert np.max(np.abs(one - exact[:, 0])) <= 1e-12 * np.max(np.abs(exact))
    assert f.solve(np.zeros((a.shape[0], 0))).shape == (a.shape[0], 0)


@pytest.mark.parametrize('method', fz.METHODS)
def test_deterministic_bit_for_bit(method):
    a = _spd()
    b = np.random.default_rng(4).standard_normal(a.shape[0])
    x1 = fz.factorize(a, method=method).solve(b)
    x2 = fz.factorize(a, method=method).solve(b)
    assert np.array_equal(x1, x2)


def test_superlu_is_scipy_splu_unchanged():
    """The reference method gives the bits of scipy's splu with its defaults."""
    a = _spd()
    b = np.random.default_rng(5).standard_normal(a.shape[0])
    assert np.array_equal(fz.factorize(a).solve(b), sla.splu(a).solve(b))


@pytest.mark.parametrize('method', ['superlu_sym', 'cholmod', 'qdldl'])
def test_symmetric_methods_refuse_an_unsymmetric_matrix(method):
    a = _spd().tolil()
    a[0, 1] = 5e5
    with pytest.raises(ValueError, match='needs a symmetric matrix'):
        fz.factorize(a.tocsc(), method=method)


def test_unknown_method_and_non_square_are_refused():
    with pytest.raises(ValueError, match="unknown factorisation method 'lu'; allowed: "):
        fz.factorize(_spd(), method='lu')
    with pytest.raises(ValueError, match='square'):
        fz.factorize(sp.csc_matrix(np.ones((2, 3))))


def test_missing_package_falls_back_to_the_other_wheel_then_scipy(monkeypatch, caplog):
    monkeypatch.setattr(fz, 'available', lambda method: method != 'cholmod')
    assert fz.factorize(_spd(), method='cholmod').method == 'qdldl'
    monkeypatch.setattr(fz, 'available', lambda method: method not in ('cholmod', 'qdldl'))
    a = _spd()
    with caplog.at_level(logging.WARNING, logger=fz.__name__):
        f = fz.factorize(a, method='cholmod')
    assert f.method == 'superlu_sym'
    assert 'cholespy' in caplog.text
    b = np.ones(a.shape[0])
    assert np.allclose(a @ f.solve(b), b, rtol=0, atol=1e-12)
