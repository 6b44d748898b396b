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

"""Closed forms of the pile-soil references against PHYSICS.md 9.4-9.5 values."""

import pytest

from ttb_sim.model.foundation.records import PAPER_LAYERS
from ttb_sim.validation.cases.pile_soil import v11, v12
from ttb_sim.validation.references.pile_soil import (gazetas_stiffness, layered_pile_stiffness,
                                                     quarter_wavelength_frequencies,
                                                     randolph_wroth_stiffness,
                                                     shear_column_frequencies)

T = [la.thickness for la in PAPER_LAYERS]
G = [la.G for la in PAPER_LAYERS]


def test_randolph_wroth_paper_pile_about_5e7():
    """PHYSICS 9.4: K ~ 5.0e7 N/m for E_p = 1e11 or 3.25e10 Pa (2 %)."""
    for ep in (1e11, 3.25e10):
        assert layered_pile_stiffness(T, G, 0.25, 12.0, 1.0, ep) == pytest.approx(5.0e7,
                                                                                  rel=0.02)
    # a rigid pile in homogeneous soil tends to the closed rigid-pile form
    rigid = randolph_wroth_stiffness(2e6, 0.3, 10.0, 0.5, 1e20)
    zeta = __import__('math').log(2.5 * 10 * 0.7 / 0.5)
    assert rigid == pytest.approx(2e6 * 0.5 * (4 / 0.7 + 2 * 3.141592653589793 / zeta * 20),
                                  rel=1e-6)
    assert gazetas_stiffness(5e6, 1.0, 12.0) == pytest.approx(4.98e7, rel=0.01)


def test_shear_column_frequencies():
    """PHYSICS 9.5: 0.42 and 1.25 Hz (quarter wavelength); homogeneous exact = (2n-1)Vs/4H."""
    q = quarter_wavelength_frequencies(T, [la.vs for la in PAPER_LAYERS], 2)
    assert q == pytest.approx([0.4176, 1.2527], rel=1e-3)
    f = shear_column_frequencies([20.0], [2e6], [1937.0], 3)
    vs = (2e6 / 1937.0)**0.5
    assert f == pytest.approx([vs / 80, 3 * vs / 80, 5 * vs / 80], rel=1e-9)


def test_v11_v12_rows_pass():
    """V11 (2 %) and V12 (5 %, and 1 % against the exact layered column) pass."""
    assert all(r.passed for r in v11() + v12())
