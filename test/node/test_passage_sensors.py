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

"""The live node's sensors and labels, without ROS: what a tick carries and the bag records."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from ttb_sim.config import from_mapping, load_scenario, Scenario
from ttb_sim.config.labels import labels_json, LABELS_KEY
from ttb_sim.io import read_bag
from ttb_sim.io.passage import recorded_scenario
from ttb_sim.io.sensor_topics import extra_topics
from ttb_sim.node.parameters import initial_values, parameter_table
from ttb_sim.node.passage import PassageController
from ttb_sim.node.shell import open_bag
import yaml

SENSORS = ('sensors=[{name: mid, type: accelerometer, at: "girder@16.0", rate_hz: 100, '
           'noise_density: 1.0e-4}, {name: sg, type: strain, at: "girder@8.0", '
           'fibre: [0, -1.5], rate_hz: 50}]')


@pytest.fixture(scope='module')
def sensed() -> Scenario:
    return load_scenario('moving_force_beam', [SENSORS, 'output.rate_hz=1000'])


def controller(scenario: Scenario, recorder=None, **values) -> PassageController:
    given = {'real_time_factor': 0.0, 'loop': False, 'publish_rate_hz': 10.0, **values}
    return PassageController(scenario, initial_values(parameter_table(scenario), given),
                             recorder=recorder)


def ticks_until_idle(c: PassageController) -> list:
    out = []
    for _ in range(1000):
        if c.state != 'running':
            break
        out.append(c.advance(budget=5.0, max_frames=200))
    return out


def test_ticks_carry_every_sample_and_the_labels_once(sensed):
    c = controller(sensed)
    ticks = ticks_until_idle(c)
    assert ticks[0].labels and not any(t.labels for t in ticks[1:])
    samples = [s for t in ticks for s in t.samples]
    c.close()
    mid = [s for s in samples if s.index == 1]
    # every frame is computed for the sensors although 10 Hz are published
    assert c.sim.output_every == c._base_every
    assert len(mid) == pytest.approx(c.sim.duration * 100, abs=2)
    assert np.all(np.diff([s.stamp_ns for s in mid]) == 10_000_000)
    assert c.sensing is not None and c.sensing.labels['scenario'] == 'moving_force_beam'


def test_a_speed_change_relabels(sensed):
    c = controller(sensed)
    c.advance(budget=5.0, max_frames=10)
    c.apply('train.speed_kmh', 250)
    tick = c.advance(budget=5.0, max_frames=10)
    assert tick.labels and c.sensing.labels['train']['speed_kmh'] == 250.0
    c.close()


def test_the_node_bag_holds_sensors_and_labels_like_a_run(sensed, tmp_path: Path):
    c = controller(sensed)
    bag = tmp_path / 'bag'
    c.recorder = open_bag(bag, 'mcap', c.layout, '/ttb_sim', extra_topics(sensed.all_sensors))
    c.advance(budget=5.0, max_frames=50)
    c.apply('train.speed_kmh', 250)
    ticks_until_idle(c)
    c.close()
    arrays = read_bag(bag)
    frames = len(arrays['/ttb_sim/bridge/span01/midspan'].stamp_ns)
    assert frames == c.recorded
    assert len(arrays['/ttb_sim/sensors/mid'].stamp_ns) == (frames + 9) // 10   # 1 in 10
    store = get_typestore(Stores.ROS2_JAZZY)
    with AnyReader([bag], default_typestore=store) as reader:
        labels = [json.loads(reader.deserialize(raw, conn.msgtype).data)
                  for conn, _, raw in reader.messages()
                  if conn.topic == '/ttb_sim/labels']
    assert [lab['train']['speed_kmh'] for lab in labels] == [200.0, 250.0]
    metadata = yaml.safe_load((bag / 'metadata.yaml').read_text())   # the last labels
    stored = metadata['rosbag2_bagfile_information']['custom_data'][LABELS_KEY]
    assert stored == labels_json(labels[-1]) and json.loads(stored) == c.sensing.labels
    # and the scenario it last ran, as ttb-sim run's bags: identify rebuilds the model
    scenario = from_mapping(recorded_scenario(bag))
    assert scenario == c.passage_scenario() and scenario.train.speed_kmh == 250.0
    assert scenario.all_sensors == sensed.all_sensors


def test_without_sensors_nothing_changes(tmp_path: Path):
    beam = load_scenario('moving_force_beam')
    c = controller(beam)
    ticks = ticks_until_idle(c)
    assert not any(t.samples for t in ticks)
    assert c.sim.output_every > c._base_every      # frames only at the publishing rate
    c.close()


def test_damage_and_temperature_switch_per_passage_and_relabel(sensed):
    c = controller(sensed)
    ok, reason = c.check_rates({'damage': '{girders: [{span: 2, start: 7, length: 2, '
                                          'loss: 0.3}]}'})
    assert not ok and 'span' in reason
    ok, reason = c.check_rates({'damage': '[1, 2]'})
    assert not ok and 'expected a mapping' in reason
    state = {'damage': '{girders: [{span: 1, start: 14, length: 4, loss: 0.3}]}',
             'environment.temperature': -10.0}
    assert c.check_rates(state) == (True, '')
    first = c.sim.structure.stiffness.copy()
    for name, value in state.items():
        c.apply(name, value)
    assert c.sensing.labels['damage']['girders'] == []          # from the next passage
    c.reset()
    tick = c.advance(budget=5.0, max_frames=5)
    assert tick.labels
    assert c.sensing.labels['damage']['girders'][0]['loss'] == 0.3
    assert c.sensing.labels['environment']['temperature'] == -10.0
    assert abs(c.sim.structure.stiffness - first).max() > 0     # the model changed
    c.close()
