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

"""V21 and V22 through ``ttb-sim validate``'s registry: every row passes, with its tolerance."""

from __future__ import annotations

from ttb_sim.validation.cases.registry import CASES, run_cases


def test_v21_v22_are_registered_and_pass():
    rows = run_cases(['V21', 'V22'])
    assert {r.case for r in rows} == {'V21', 'V22'}
    assert len(rows) == 5
    for row in rows:
        assert row.passed, row
    assert [r.tolerance for r in rows] == [1e-3, 1e-3, 0.01, 0.01, 0.01]
    assert 'Parseval' in CASES['V21'].title
