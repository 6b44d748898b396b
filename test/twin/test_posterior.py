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


"""Identification on a model with a known answer: recovered, flat when blind, seeded."""

import numpy as np
import pytest
from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.errors import ScenarioError
from ttb_sim.twin import Features, FeatureSpec, FeatureVector
from ttb_sim.twin.identify import identify, IdentifySettings, noise_psd
from ttb_sim.twin.priors import parse_prior

SPEC = FeatureSpec(psd_fmin_hz=1.0, psd_fmax_hz=40.0, psd_points=40, psd_segment_s=1.0)
SENSOR = SensorConfig(name='acc', type='accelerometer', at='girder@16', rate_hz=100.0,
                      noise_density=1e-3)
RECORD_S = 20.0


class Oscillator:
    """A forward model with a closed form: a damped resonance at f0 = theta[0] Hz."""

    keys = ('f0', 'blind')
    spec = SPEC
    sensors = [SENSOR]
    vector = FeatureVector(('acc.z',), SPEC.frequencies())

    @property
    def feature_names(self):
        return self.vector.names

    def values(self, theta):
        return list(zip(self.keys, np.atleast_1d(theta).astype(float)))

    def psd(self, theta):
        f = SPEC.frequencies()
        f0 = theta[0]   # theta[1] changes nothing: the data carry no information on it
        return 1e-3 / ((1 - (f / f0) ** 2) ** 2 + (0.1 * f / f0) ** 2)

    def __call__(self, theta):
        return np.log10(self.psd(np.asarray(theta, float)))


def observed(truth, seed=1):
    """Return the data: an ambient resonance plus noise, scattered as Welch's estimate."""
    model = Oscillator()
    p = model.psd([truth, 0.0]) + noise_psd(SENSOR)
    k = 2 * RECORD_S / SPEC.psd_segment_s - 1
    rng = np.random.default_rng(seed)
    scatter = rng.chisquare(2 * k, p.shape) / (2 * k)
    return Features({}, {'acc.z': p * scatter}, SPEC.frequencies())


PRIORS = [parse_prior('f0', {'uniform': [5.0, 15.0]}), parse_prior('blind', {'normal': [0, 1]})]


@pytest.fixture(scope='module')
def fit():
    return identify(Oscillator(), PRIORS, observed(9.3), RECORD_S,
                    IdentifySettings(design=24, steps=3000, seed=4, response='ambient'))


def test_the_resonance_is_recovered_and_the_blind_key_reported_flat(fit):
    summary = fit.summary()
    f0 = summary['parameters']['f0']
    assert f0['q05'] <= 9.3 <= f0['q95'] and abs(f0['median'] - 9.3) < 0.2
    assert f0['identified']
    blind = summary['parameters']['blind']
    assert not blind['identified'] and blind['interval_vs_prior'] > 0.8
    assert 'not identified' in blind['note']
    d = summary['diagnostics']
    assert 0.2 < d['acceptance_fraction'] < 0.9 and d['converged']
    assert abs(summary['check_at_median']['theta']['f0'] - f0['median']) < 1e-12


def test_the_same_seed_gives_the_same_chain_bit_for_bit(fit):
    again = identify(Oscillator(), PRIORS, observed(9.3), RECORD_S,
                     IdentifySettings(design=24, steps=3000, seed=4, response='ambient'))
    assert np.array_equal(again.chain, fit.chain)
    other = identify(Oscillator(), PRIORS, observed(9.3), RECORD_S,
                     IdentifySettings(design=24, steps=3000, seed=5, response='ambient'))
    assert not np.array_equal(other.chain, fit.chain)


def test_a_choice_prior_and_bad_settings_are_refused():
    with pytest.raises(ScenarioError, match='uniform, normal or lognormal'):
        identify(Oscillator(), [PRIORS[0], parse_prior('blind', {'choice': [1, 2]})],
                 observed(9.3), RECORD_S, IdentifySettings(design=4, steps=100))
    with pytest.raises(ScenarioError, match='--steps 5'):
        IdentifySettings(steps=5)
    with pytest.raises(ScenarioError, match='--response'):
        IdentifySettings(response='random')
    with pytest.raises(ScenarioError, match='--discrepancy'):
        IdentifySettings(discrepancy=-1.0)
