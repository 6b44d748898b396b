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

"""V25 (scour against the independent FE) and V26 (temperature) pass, and can fail."""

from __future__ import annotations

import pytest

import ttb_sim.sim.build as build
from ttb_sim.validation.cases import conditions
from ttb_sim.validation.cases.registry import CASES

COARSE = 0.886
"""Brick size at the pile (m) of the test mesh: the V25 rows on it take about 20 s."""


def judged(rows):
    """Return the rows that pass or fail (not the report rows)."""
    return [r for r in rows if r.error_kind != 'report']


def test_v25_v26_are_registered() -> None:
    """Both cases run from ``ttb-sim validate``."""
    assert CASES['V25'].run is conditions.v25_rows
    assert CASES['V26'].run is conditions.v26_rows


@pytest.mark.slow
def test_v25_scoured_head_stiffness_equals_the_independent_fe() -> None:
    """One discretisation, two codes: within 1e-6 (measured 2e-12), softer than the sound pile."""
    rows = conditions.v25_rows(depths=(4.0,), h=COARSE)
    (row,) = judged(rows)
    assert row.passed and row.error < 1e-9
    sound = conditions.head_stiffness(conditions.single_pile(h=COARSE, interface='bonded'))
    assert row.computed < 0.8 * sound  # 4 m of scour takes about 21 % of the stiffness


@pytest.mark.slow
def test_v25_fails_when_the_scour_does_not_reach_the_model(monkeypatch) -> None:
    """Damage left out of the model: the independent FE (removing by geometry) differs."""
    monkeypatch.setattr(conditions, 'damaged_substructure', lambda spec, pier, damage: spec)
    (row,) = judged(conditions.v25_rows(depths=(4.0,), h=COARSE))
    assert not row.passed and row.error > 0.2


def test_v26_frequency_follows_the_modulus_coefficient() -> None:
    """Every row within 0.1 % (measured 1.0e-6), and the shift is the one alpha_E predicts."""
    rows = conditions.v26_rows()
    assert len(rows) == len(conditions.V26_CASES) and all(r.passed for r in rows)
    assert max(r.error for r in rows) < 1e-5


def test_v26_fails_without_the_temperature(monkeypatch) -> None:
    """Girders built at the reference modulus: every row off by the predicted shift."""
    monkeypatch.setattr(build, 'conditioned_bridge', lambda scenario: scenario.bridge)
    rows = conditions.v26_rows()
    assert not any(r.passed for r in rows)
    assert min(r.error for r in rows) > 0.009  # -10 degC, alpha -0.001: sqrt(1.03) - 1 = 1.5 %
