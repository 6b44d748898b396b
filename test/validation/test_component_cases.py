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
Tests of the component validation cases V4, V5, V8, V9, V10 (VALIDATION.md).

Every case must pass; the row builders must also fail when the computed value
or the reference is wrong, so that a passing table means something.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from ttb_sim.model.irregularity.spectra import SPECTRA
import ttb_sim.model.vehicle as car
from ttb_sim.validation.cases import components as cc
from ttb_sim.validation.rows import Row

TITLES = {
    'V4': 'car of Table 1, eigen-analysis',
    'V5': 'Hertz contact at static wheel load',
    'V8': 'synthesis from each spectrum (Chinese HSR four components, Sato, '
          'German low/high, FRA 1-6)',
    'V9': 'Welch PSD of a synthesised profile',
    'V10': 'Chinese HSR vertical, 2-200 m',
}


@pytest.fixture(scope='module')
def rows() -> dict[str, list[Row]]:
    return {case.case_id: case.run() for case in cc.COMPONENT_CASES}


def test_case_ids_and_titles():
    """One case per id, in VALIDATION.md order, with its VALIDATION.md title."""
    assert {c.case_id: c.title for c in cc.COMPONENT_CASES} == TITLES
    assert [c.case_id for c in cc.COMPONENT_CASES] == list(TITLES)


@pytest.mark.parametrize('case_id', list(TITLES))
def test_every_row_passes(rows, case_id):
    """Every row of every case is finite, carries its case id and passes its tolerance."""
    assert rows[case_id]
    for row in rows[case_id]:
        assert row.case == case_id
        assert math.isfinite(row.computed) and math.isfinite(row.error), row
        assert row.error == pytest.approx(abs(row.computed / row.reference - 1.0), rel=1e-9,
                                          abs=1e-15)
        assert row.passed, row


def test_row_counts_and_tolerances(rows):
    """V4 four modes (1 %), V5 two (1 %), V8 and V9 one row per family (2 %, 20 %), V10 two."""
    assert [len(rows[c]) for c in TITLES] == [4, 2, len(SPECTRA), len(SPECTRA), 2]
    assert len(SPECTRA) <= 12
    expected = {'V4': 0.01, 'V5': 0.01, 'V8': 0.02, 'V9': 0.20, 'V10': 0.02}
    for case_id, tolerance in expected.items():
        assert all(r.tolerance == tolerance for r in rows[case_id])
    assert [r.quantity.split('.')[0] for r in rows['V8']] == list(SPECTRA)
    assert [r.quantity.split('.')[0] for r in rows['V9']] == list(SPECTRA)


def test_v4_values(rows):
    """V4 against PHYSICS.md 3.1 typed again: 0.840, 0.952, 4.78, 6.27 Hz (1 %)."""
    computed = [r.computed for r in rows['V4']]
    assert computed == pytest.approx([0.840, 0.952, 4.78, 6.27], rel=0.01)
    named = cc.vertical_modes()
    assert [len(named[g]) for g in ('car_body_bounce', 'car_body_pitch', 'bogie_pitch',
                                    'bogie_bounce', 'mixed')] == [1, 1, 2, 2, 0]
    assert named['bogie_pitch'] == pytest.approx([4.78] * 2, rel=0.01)
    assert named['bogie_bounce'] == pytest.approx([6.27] * 2, rel=0.01)


def test_v5_values(rows):
    """V5 against PHYSICS.md 2.1 typed again: 77 um, 1.52e9 N/m (1 %)."""
    compression, stiffness = rows['V5']
    assert compression.computed == pytest.approx(77.0, rel=0.01)
    assert compression.unit == 'um'
    assert stiffness.computed == pytest.approx(1.52e9, rel=0.01)


def test_v8_checks_every_component_with_twenty_seeds():
    """All 37 components (Chinese 4, Sato 1, German 2 x 4, FRA 6 x 4), 20 seeds each."""
    checks = cc.variance_checks()
    assert list(checks) == list(SPECTRA)
    assert sum(len(c) for c in checks.values()) == 4 + 1 + 2 * 4 + 6 * 4
    for family, family_checks in checks.items():
        assert [c.component for c in family_checks] == list(SPECTRA[family].components)
        assert all(c.seeds == 20 and abs(c.relative_error) < 0.02 for c in family_checks)


def test_v10_values(rows):
    """V10 against PHYSICS.md 1.1 typed again: 1.22 mm (2 %)."""
    assert [r.computed for r in rows['V10']] == pytest.approx([1.22, 1.22], rel=0.02)


# --- the rows must be able to fail -------------------------------------------------------------

def test_v4_fails_on_a_wrong_reference_or_car():
    """A 2 % wrong bounce reference fails that row only; a stiffer air spring fails V4."""
    wrong = dict(cc.V4_REFERENCE, car_body_bounce=0.840 * 1.02)
    assert [r.passed for r in cc.v4_rows(reference=wrong)] == [False, True, True, True]
    stiff = car.CarParameters(secondary_stiffness_z=0.5e6)
    assert not all(r.passed for r in cc.v4_rows(stiff))


def test_v5_fails_on_a_wrong_reference_or_tread():
    """Conical tread (94 um, 1.25e9 N/m) fails both rows; a 2 % wrong reference fails."""
    assert [r.passed for r in cc.v5_rows(tread='conical')] == [False, False]
    assert [r.passed for r in cc.v5_rows(compression_reference=77e-6 * 1.02)] == [False, True]
    assert [r.passed for r in cc.v5_rows(stiffness_reference=1.52e9 * 0.98)] == [True, False]


def test_v8_row_fails_on_a_wrong_variance():
    """A check 3 % off its PSD integral fails; 1 % passes; the worst component is reported."""
    good = cc.variance_checks(seeds=1)['chinese_hsr']
    off = [dataclasses.replace(good[0], sample_variance=1.03 * good[0].target_variance),
           dataclasses.replace(good[2], sample_variance=1.01 * good[2].target_variance)]
    row = cc.variance_row(off)
    assert not row.passed and row.quantity == 'chinese_hsr.vertical (worst)'
    assert row.error == pytest.approx(0.03)
    assert cc.variance_row(off[1:]).passed


def test_v9_row_fails_on_a_wrong_ratio_or_profile():
    """A 1.25 band ratio fails; a profile scaled by 1.2 (PSD x 1.44) fails; no band fails."""
    assert not cc.octave_row('sato', {'vertical': [1.0, 1.25, 0.98]}).passed
    assert cc.octave_row('sato', {'vertical': [1.0, 1.15, 0.9]}).passed
    scaled = cc.octave_ratios('sato', 'vertical', scale=1.2)
    assert scaled == pytest.approx(1.44 * cc.octave_ratios('sato', 'vertical'), rel=1e-9)
    assert not cc.octave_row('sato', {'vertical': scaled}).passed
    assert not cc.octave_row('sato', {'vertical': []}).passed


def test_v9_octave_bands():
    """Octave bands from 2/lambda_max to 1/lambda_min: 5 for Chinese, 3 Sato, 6 FRA."""
    assert len(cc.octave_ratios('chinese_hsr', 'gauge')) == 5
    assert len(cc.octave_ratios('sato', 'vertical')) == 3
    assert np.all(np.abs(cc.octave_ratios('fra6', 'gauge') - 1.0) < 0.2)
    assert len(cc.octave_ratios('fra6', 'gauge')) == 6


def test_v10_fails_on_another_band_or_reference():
    """The 1-50 m band (0.39 mm) fails against 1.22 mm; a 3 % wrong reference fails."""
    assert not any(r.passed for r in cc.v10_rows(1.0, 50.0))
    assert not any(r.passed for r in cc.v10_rows(reference_mm=1.22 * 1.03))
