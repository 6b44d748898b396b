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


"""The forward model: a passage's feature vector at parameter values, one definition."""

import numpy as np
import pytest
from ttb_sim.config import from_mapping, load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io.passage import recorded_scenario
from ttb_sim.twin import FeatureSpec, ForwardModel, sensor_features

SET = ['sensor_layouts=[span:1]', 'output.rate_hz=1000', 'solver.dt=0.0005',
       'solver.duration=0.5']
GRID = FeatureSpec(psd_fmin_hz=2.0, psd_fmax_hz=90.0, psd_points=12, psd_segment_s=0.25)


@pytest.fixture(scope='module')
def model():
    return ForwardModel('moving_force_beam', ['train.speed_kmh', 'bridge.bending_stiffness'],
                        overrides=SET, sensors=['span01_acc_mid', 'span01_strain_mid'],
                        features=GRID, rms=True)


def test_the_vector_is_the_features_of_the_recorded_bag(model, tmp_path):
    theta = [220.0, 4.0e11]
    features = model.simulate(theta, bag=tmp_path / 'bag')
    x = model.vector.of(features)
    assert x.shape == (len(model.feature_names),)
    assert np.array_equal(model(theta), x)   # same case, same bits
    scenario = load_scenario('moving_force_beam', SET, model.values(theta))
    chosen = [s for s in scenario.all_sensors if s.name in ('span01_acc_mid', 'span01_strain_mid')]
    again = sensor_features(tmp_path / 'bag', chosen, GRID)
    assert np.array_equal(model.vector.of(again), x)
    # the bag carries its scenario: the same model is built from the bag alone
    assert from_mapping(recorded_scenario(tmp_path / 'bag')) == scenario


def test_the_features_follow_the_parameters(model):
    rows = model(np.array([[220.0, 4.0e11], [220.0, 2.0e11]]))
    assert rows.shape == (2, len(model.feature_names))
    rms = [model.feature_names.index('rms.span01_strain_mid.x')]
    # half the bending stiffness: about twice the mid-span strain of the static deflection
    assert rows[1, rms] / rows[0, rms] == pytest.approx(2.0, rel=0.25)


def test_bad_uses_are_refused(model):
    with pytest.raises(ValueError, match='takes 2 values'):
        model([1.0])
    with pytest.raises(ScenarioError, match='no sensor'):
        ForwardModel('moving_force_beam', ['train.speed_kmh'], overrides=SET, sensors=['x'])
    with pytest.raises(ScenarioError, match='has no sensors'):
        ForwardModel('moving_force_beam', ['train.speed_kmh'])
    with pytest.raises(ScenarioError, match='train.speed_kmh'):
        model.simulate([-5.0, 4.0e11])
