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
V7: Newmark average acceleration on an undamped SDOF.

Reference: second-order convergence (observed order 2 +/- 0.1) and no energy
drift (relative drift < 1e-6 over 1e4 steps), VALIDATION.md V7.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.validation.cases.registry import newmark_energy_drift, newmark_order, newmark_sdof


def test_order_two():
    assert newmark_order() == pytest.approx(2.0, abs=0.1)


def test_energy_drift_below_1e6():
    assert newmark_energy_drift() < 1e-6


def test_period_error_matches_theory():
    # Average acceleration: the discrete frequency is 2 atan(w dt / 2) / dt.
    omega, dt, n = 2 * np.pi, 0.05, 400
    u, _ = newmark_sdof(omega, dt, n)
    omega_h = 2 * np.arctan(omega * dt / 2) / dt
    assert np.allclose(u, np.cos(omega_h * dt * np.arange(n + 1)), atol=1e-9)


def test_forced_static_limit():
    # A slowly applied constant load settles to F / k with damping.
    k, c, m = 4.0, 2.0, 1.0
    nm = Newmark(sp.csr_matrix([[m]]), sp.csr_matrix([[c]]), sp.csr_matrix([[k]]), 0.01)
    u = v = a = np.zeros(1)
    for _ in range(3000):
        u, v, a = nm.step(u, v, a, np.array([1.0]))
    assert u[0] == pytest.approx(0.25, rel=1e-6)
