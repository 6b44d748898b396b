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

"""Complex symmetric sparse solves against dense numpy, and their refusals."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe.complex_solve import (factorize_complex, factorize_positive_definite,
                                      pardiso_available)


def dynamic_stiffness(n: int = 300, seed: int = 3, w_zero: bool = False) -> sp.csr_matrix:
    """
    Return K - w^2 M + i w C of a damped chain: complex symmetric, indefinite real part.

    ``w_zero``: K alone, real symmetric positive definite.
    """
    rng = np.random.default_rng(seed)
    k = sp.diags([-np.ones(n - 1), 2.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1]) * 1e3
    k = k + sp.diags(rng.uniform(0, 10, n))
    m = sp.diags(rng.uniform(0.5, 1.5, n))
    c = 0.02 * k + 0.1 * m
    if w_zero:
        return k.tocsr()
    w = 30.0   # above the lowest natural frequencies: K - w^2 M is indefinite
    return (k - w * w * m + 1j * w * c).tocsr()


@pytest.mark.parametrize('method', [
    'superlu',
    pytest.param('pardiso', marks=pytest.mark.skipif(
        not pardiso_available(), reason='MKL PARDISO not installed (pip install '
        'ttb_sim[pardiso]); SuperLU serves every solve without it')),
])
def test_solves_match_dense_numpy(method: str) -> None:
    z = dynamic_stiffness()
    rhs = np.random.default_rng(0).normal(size=(z.shape[0], 2)) + 1j
    x = factorize_complex(z, method).solve(rhs)
    exact = np.linalg.solve(z.toarray(), rhs)
    # a well-conditioned 300 x 300 system: round-off of a pivoted LDL^T or LU
    assert np.abs(x - exact).max() < 1e-9 * np.abs(exact).max()
    one = factorize_complex(z, method).solve(rhs[:, 0])
    assert one.shape == (z.shape[0],)
    np.testing.assert_allclose(one, exact[:, 0], rtol=0, atol=1e-9 * np.abs(exact).max())


def test_solves_repeat_bit_for_bit() -> None:
    z = dynamic_stiffness()
    rhs = np.ones(z.shape[0], dtype=complex)
    assert np.array_equal(factorize_complex(z).solve(rhs), factorize_complex(z).solve(rhs))


def test_refusals() -> None:
    z = dynamic_stiffness(20)
    with pytest.raises(FEError, match='one of auto, pardiso, superlu'):
        factorize_complex(z, 'mumps')
    with pytest.raises(FEError, match='not symmetric'):
        factorize_complex(z + sp.csr_matrix(([1.0], ([0], [5])), shape=z.shape))
    with pytest.raises(FEError, match='square'):
        factorize_complex(sp.csr_matrix((3, 4)))


NEEDS_PARDISO = pytest.mark.skipif(not pardiso_available(), reason='MKL PARDISO not installed '
                                   "(pip install 'ttb_sim[pardiso]'); the reduction's positive "
                                   'definite pencils go to CHOLMOD without it')


@NEEDS_PARDISO
def test_positive_definite_factor_matches_dense_numpy_and_repeats() -> None:
    """The Cholesky of PARDISO (type 2) of a stiffness-like SPD matrix: round-off, same bits."""
    z = dynamic_stiffness(w_zero=True)
    rhs = np.random.default_rng(1).normal(size=(z.shape[0], 3))
    x = factorize_positive_definite(z).solve(rhs)
    exact = np.linalg.solve(z.toarray(), rhs)
    assert x.dtype == np.float64
    assert np.abs(x - exact).max() < 1e-10 * np.abs(exact).max()
    assert np.array_equal(x, factorize_positive_definite(z).solve(rhs))


@NEEDS_PARDISO
def test_positive_definite_factor_refuses_an_indefinite_matrix() -> None:
    k = sp.diags([1.0, -1.0, 2.0]).tocsr()
    with pytest.raises(FEError, match='not positive definite'):
        factorize_positive_definite(k)
