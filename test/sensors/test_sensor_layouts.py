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

"""The built-in sensor layouts: what they expand to, what they refuse, a run with them."""

import json

import pytest

from ttb_sim.cli import main
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError


def test_span_layout_instruments_a_girder_and_its_bearings_on_piers():
    s = load_scenario('ten_span_train', ['sensor_layouts=[span:1, span:5]',
                                         'output.rate_hz=1000'])
    names = [c.name for c in s.all_sensors]
    assert names[:2] == ['span01_acc_q1', 'span01_strain_q1']
    assert 'span01_bearing_start' not in names          # support 1 is an abutment
    assert {'span01_bearing_end', 'span05_bearing_start', 'span05_bearing_end'} <= set(names)
    mid = next(c for c in s.all_sensors if c.name == 'span05_acc_mid')
    assert mid.at == 'girder@144' and mid.measured_axes == 'yz'
    lvdt = next(c for c in s.all_sensors if c.name == 'span05_bearing_end')
    assert lvdt.relative_to == 'pier06/top' and lvdt.at == 'girder@159.95'
    strain = next(c for c in s.all_sensors if c.name == 'span05_strain_q3')
    assert strain.fibre == (0.0, -1.5) and strain.at == 'girder@152'


def test_rigid_supports_get_no_bearing_lvdts():
    s = load_scenario('moving_force_beam', ['sensor_layouts=[span:1]', 'output.rate_hz=1000'])
    assert not any('bearing' in c.name for c in s.all_sensors)


def test_pier_layout_names_piles_geophones_and_settlement():
    s = load_scenario('paper_ttbcpsi', ['sensor_layouts=[pier:7]'])
    names = [c.name for c in s.all_sensors]
    assert names == ['pier07_pile05_acc', 'pier07_pile08_acc', 'pier07_pile14_acc',
                     'pier07_geo_1', 'pier07_geo_2', 'pier07_geo_3', 'pier07_settlement',
                     'pier07_top_acc']


@pytest.mark.parametrize('entry, message', [
    ('span:11', 'span 11 does not exist; the bridge has 10'),
    ('deck:1', "expected 'kind:number'"),
    ('span:one', "expected 'kind:number'"),
])
def test_bad_layouts_are_refused(entry, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario('ten_span_train', [f'sensor_layouts=[{entry}]', 'output.rate_hz=1000'])


def test_layout_names_must_not_repeat_a_sensor():
    with pytest.raises(ScenarioError, match="sensors\\[0\\].name = 'span01_acc_mid' is used"):
        load_scenario('ten_span_train', ['sensor_layouts=[span:1]', 'output.rate_hz=1000',
                                         'sensors=[{name: span01_acc_mid, at: "girder@3"}]'])


def test_layout_rates_must_divide_the_frame_rate():
    with pytest.raises(ScenarioError, match='rate_hz = 200 does not divide the frame rate 500'):
        load_scenario('ten_span_train', ['sensor_layouts=[span:1]'])


def test_a_run_with_a_span_layout(tmp_path):
    out = tmp_path / 'bag'
    assert main(['run', 'ten_span_train', '--out', str(out), '--duration', '0.5', '--set',
                 'sensor_layouts=[span:2]', '--set', 'output.rate_hz=1000']) == 0
    summary = json.loads((out / 'summary.json').read_text())
    counts = {s['name']: s['samples_published'] for s in summary['sensors']}
    assert counts['span02_acc_mid'] == 101 and counts['span02_strain_mid'] == 51
    assert counts['span02_bearing_end'] == 26
    assert '/ttb_sim/sensors/span02_tilt_end' in summary['bag']['topics']
