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
V3: sprung mass (quarter car) crossing a simply supported beam.

Reference: independent modal solution (20 modes, scipy DOP853) re-derived in
``ttb_sim.validation.references.structural``; the Yang & Yau parameters give 2.408 mm and
0.148 m/s^2 (PHYSICS.md 9.3). Tolerances: 2 % deflection, 5 % acceleration.
"""

import numpy as np
import pytest
from ttb_sim.validation.cases.registry import sprung_mass_comparison
from ttb_sim.validation.references.structural import Beam, QuarterCar, sprung_mass_modal


def test_modal_reference_reproduces_published_values():
    beam = Beam(25.0, 2.87e9 * 2.9, 2303.0)
    r = sprung_mass_modal(beam, QuarterCar(5750.0, 1595e3), 100 / 3.6, 0.9, n_modes=10)
    assert -r['midspan'].min() == pytest.approx(2.408e-3, rel=2e-3)
    assert np.abs(r['acceleration']).max() == pytest.approx(0.148, rel=5e-3)


def test_v3_yang_yau():
    r = sprung_mass_comparison()
    assert r['deflection'] == pytest.approx(r['deflection_ref'], rel=0.02)
    assert r['acceleration'] == pytest.approx(r['acceleration_ref'], rel=0.05)
    assert r['deflection'] == pytest.approx(2.408e-3, rel=0.02)


@pytest.mark.parametrize('overrides', [
    ['train.speed_kmh=250', 'train.suspension_damping=3e4', 'train.unsprung_mass=700'],
    ['bridge.span_length=40', 'bridge.bending_stiffness=5e10', 'bridge.mass_per_length=8000',
     'train.sprung_mass=20000', 'train.suspension_stiffness=8e5', 'train.speed_kmh=180',
     'bridge.damping_ratio=0.02'],
    ['train.speed_kmh=60', 'train.suspension_stiffness=5e6', 'train.sprung_mass=3000'],
])
def test_v3_arbitrary_parameters(overrides):
    r = sprung_mass_comparison(overrides)
    assert r['deflection'] == pytest.approx(r['deflection_ref'], rel=0.02)
    assert r['acceleration'] == pytest.approx(r['acceleration_ref'], rel=0.05)
