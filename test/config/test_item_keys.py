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


"""Keys into one entry of a list-valued key: ``soil.layers[1].E``, ``damage.girders[0].loss``."""

import pytest
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError

GIRDER = 'damage.girders=[{span: 1, start: 6, length: 4, loss: 0.4}]'


def test_a_field_of_a_default_record_is_set_and_the_others_kept():
    sound = load_scenario('single_pile').soil.layers
    soft = load_scenario('single_pile', ['soil.layers[1].E=9.0e+6']).soil.layers
    assert soft[1].E == 9.0e6
    assert soft[1].nu == sound[1].nu and soft[1].thickness == sound[1].thickness
    assert soft[0] == sound[0] and soft[2:] == sound[2:]


def test_a_field_of_a_given_record_is_set():
    base = load_scenario('live_coupled', [GIRDER])
    changed = load_scenario('live_coupled', [GIRDER, 'damage.girders[0].loss=0.25'])
    assert base.damage.girders[0].loss == 0.4
    assert changed.damage.girders[0].loss == 0.25
    assert changed.damage.girders[0].length == base.damage.girders[0].length


def test_an_entry_of_a_list_of_numbers_is_set():
    scales = ['environment.soil_modulus_scale=[1.0, 1.0, 1.0]',
              'environment.soil_modulus_scale[2]=1.5']
    assert load_scenario('live_coupled', scales).environment.soil_modulus_scale == (1.0, 1.0, 1.5)


@pytest.mark.parametrize('override, words', [
    ('damage.girders[0].loss=0.3', 'has no entries'),
    ('soil.layers[7].E=9e6', 'index 0 to 2'),
    ('soil.layers[0].G=9e6', "unknown key 'G'"),
    ('soil.layers[0]=9e6', 'is a record; set one of its keys'),
    ('train.speed_kmh[0]=300', 'is not a list'),
    ('environment.soil_modulus_scale[0].E=1', 'list of values, not of records'),
    ('soil.layers[0].nu=0.7', 'soil.layers[0].nu'),
])
def test_a_bad_item_key_names_the_key_and_what_is_allowed(override, words):
    with pytest.raises(ScenarioError) as caught:
        load_scenario('single_pile', [override])
    assert words in str(caught.value)
    assert override.split('=')[0] in str(caught.value)
