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


"""Priors and designs: each family's draws follow its distribution; designs are seeded."""

import numpy as np
import pytest
from scipy import stats
from ttb_sim.errors import ScenarioError
from ttb_sim.twin import draw_cases, parse_prior

N = 1024


@pytest.mark.parametrize('sampler', ['sobol', 'lhs', 'random'])
@pytest.mark.parametrize('family, args, reference', [
    ('uniform', [2.0, 5.0], stats.uniform(loc=2.0, scale=3.0)),
    ('normal', [15.0, 8.0], stats.norm(loc=15.0, scale=8.0)),
    ('lognormal', [15.2, 0.3], stats.lognorm(s=0.3, scale=np.exp(15.2))),
])
def test_draws_follow_the_prior(sampler, family, args, reference):
    prior = parse_prior('k', {family: args})
    values = [c['k'] for c in draw_cases([prior], N, sampler, seed=7)]
    # Kolmogorov-Smirnov at 1 % (space-filling designs are far closer than random ones)
    assert stats.kstest(values, reference.cdf).pvalue > 0.01


def test_choice_draws_each_value_equally_often():
    prior = parse_prior('k', {'choice': ['a', 'b', 'c', 'd']})
    values = [c['k'] for c in draw_cases([prior], 1024, 'sobol', seed=1)]
    assert {v: values.count(v) for v in 'abcd'} == dict.fromkeys('abcd', 256)


def test_a_latin_hypercube_puts_one_point_in_each_stratum_of_each_key():
    priors = [parse_prior('a', {'uniform': [0, 1]}), parse_prior('b', {'uniform': [0, 1]})]
    cases = draw_cases(priors, 50, 'lhs', seed=3)
    for key in 'ab':
        strata = sorted(int(c[key] * 50) for c in cases)
        assert strata == list(range(50))


@pytest.mark.parametrize('sampler', ['sobol', 'lhs', 'random'])
def test_the_same_seed_draws_the_same_cases_bit_for_bit(sampler):
    priors = [parse_prior('a', {'normal': [0, 1]}), parse_prior('b', {'choice': [1, 2, 3]})]
    first = draw_cases(priors, 33, sampler, seed=11)
    assert draw_cases(priors, 33, sampler, seed=11) == first
    assert draw_cases(priors, 33, sampler, seed=12) != first


@pytest.mark.parametrize('sampler', ['sobol', 'random'])
def test_a_larger_design_keeps_the_first_cases(sampler):
    priors = [parse_prior('a', {'uniform': [0, 1]})]
    assert draw_cases(priors, 16, sampler, seed=5)[:8] == draw_cases(priors, 8, sampler, 5)


@pytest.mark.parametrize('value, words', [
    ({'uniform': [1, 1]}, 'a < b'),
    ({'normal': [0, -1]}, 'sd must be positive'),
    ({'lognormal': [0, 0]}, 'sigma must be positive'),
    ({'uniform': [0, float('inf')]}, 'two finite numbers'),
    ({'uniform': [0]}, 'two finite numbers'),
    ({'beta': [1, 2]}, 'unknown family'),
    ({'uniform': [0, 1], 'normal': [0, 1]}, 'give one family'),
    ({'choice': []}, '1 to 1000 values'),
    ([0, 1], 'give one family'),
])
def test_a_bad_prior_names_the_key_and_what_is_allowed(value, words):
    with pytest.raises(ScenarioError) as caught:
        parse_prior('train.speed_kmh', value)
    assert 'priors.train.speed_kmh' in str(caught.value) and words in str(caught.value)
