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

"""Fixtures shared across the test tree."""

from typing import Callable

import pytest
from scipy import integrate


def _quad_variance(comp, lam_min: float, lam_max: float) -> float:
    """Integrate a spectrum component's G over [1/lam_max, 1/lam_min] with quad (m^2)."""
    n_lo, n_hi = 1.0 / lam_max, 1.0 / lam_min
    inner = [b for b in comp.breakpoints if n_lo < b < n_hi] or None
    value, _ = integrate.quad(lambda n: float(comp.psd(n)), n_lo, n_hi, points=inner,
                              limit=400, epsabs=0.0, epsrel=1e-10)
    return value


@pytest.fixture
def quad_variance() -> Callable[..., float]:
    """
    Return the band variance of a PSD by scipy quad, independent of the synthesis code.

    The synthesis integrates each FFT bin with Gauss-Legendre quadrature; this is
    the reference its variance is checked against (V8, V10).
    """
    return _quad_variance


@pytest.fixture(autouse=True, scope='session')
def _substructure_cache(tmp_path_factory):
    """Keep the reduced substructures the tests build in one session-wide cache, not ~/.cache."""
    import os
    previous = os.environ.get('TTB_SIM_CACHE')
    os.environ['TTB_SIM_CACHE'] = str(tmp_path_factory.mktemp('ttb_sim_cache'))
    yield
    if previous is None:
        os.environ.pop('TTB_SIM_CACHE', None)
    else:
        os.environ['TTB_SIM_CACHE'] = previous
