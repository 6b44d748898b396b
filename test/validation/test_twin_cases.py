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


"""V28, V29: the rows judge a recovered parameter and a flat one, and can fail."""

from ttb_sim.validation.cases import twin
from ttb_sim.validation.cases.registry import CASES


def summary(median, q05, q95, ratio, identified):
    return {'parameters': {'k': {'median': median, 'q05': q05, 'q95': q95,
                                 'interval_vs_prior': ratio, 'identified': identified}}}


def test_the_cases_are_registered():
    assert CASES['V28'].run is twin.v28_rows and CASES['V29'].run is twin.v29_rows


def test_a_recovered_parameter_passes_and_a_missed_one_fails():
    good = twin.recovered_rows('V28', 'x', summary(3.05, 2.8, 3.3, 0.1, True), 'k', 3.0, 0.15)
    assert all(r.passed for r in good)
    biased = twin.recovered_rows('V28', 'x', summary(3.6, 3.4, 3.9, 0.1, True), 'k', 3.0, 0.15)
    assert [r.passed for r in biased] == [False, False]
    narrow = twin.recovered_rows('V28', 'x', summary(3.1, 3.05, 3.2, 0.1, True), 'k', 3.0, 0.15)
    assert [r.passed for r in narrow] == [True, False]   # overconfident: truth outside


def test_a_blind_key_must_be_reported_flat():
    assert twin.flat_row('V28', 'x', summary(0, 0, 1, 0.95, False), 'k').passed
    assert not twin.flat_row('V28', 'x', summary(0, 0, 1, 0.3, True), 'k').passed
    assert not twin.flat_row('V28', 'x', summary(0, 0, 1, 0.95, True), 'k').passed
