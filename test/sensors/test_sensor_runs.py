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
Sensors in ``ttb-sim run``: refusals, topics, the truth they sample, labels, repeatability.

Errors come before anything is written; the bag's sensor and label topics are read back by
ttb_sim's reader and by the independent mcap readers.
"""

import json
from pathlib import Path

from mcap_ros2.reader import read_ros2_messages
import numpy as np
import pytest
from scipy import signal
from ttb_sim.cli import main
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io import read_bag
import yaml

SPAN = {'train': {'vehicle': 'moving_force', 'speed_kmh': 200.0, 'axle_offsets': [0.0, 2.5],
                  'axle_load': 156960.0},
        'bridge': {'n_spans': 2, 'span_length': 20.0},
        'bearings': {'model': 'rigid'}, 'foundation': {'model': 'rigid'},
        'solver': {'free_vibration_periods': 1.0}, 'output': {'rate_hz': 1000.0}}

SENSORS = [
    {'name': 'mid_u', 'type': 'displacement', 'at': 'girder@10.0', 'axes': ['x', 'y', 'z'],
     'rate_hz': 500.0, 'passband': 0.9},
    {'name': 'mid_a', 'type': 'accelerometer', 'at': 'span01/x=10.0', 'axes': ['x', 'z'],
     'rate_hz': 200.0, 'noise_density': 1e-4, 'resolution': 1e-5},
    {'name': 'sg', 'type': 'strain', 'at': 'girder@25.0', 'fibre': [0.0, -1.2],
     'rate_hz': 100.0, 'dropout_probability': 0.2, 'dropout_mean_length': 0.02},
    {'name': 'gap', 'type': 'displacement', 'at': 'girder@10.0', 'relative_to': 'girder@10.0',
     'rate_hz': 100.0},
    {'name': 'tilt', 'type': 'inclinometer', 'at': 'girder@0.5', 'rate_hz': 250.0,
     'clock_offset': 0.002},
    {'name': 'geo', 'type': 'geophone', 'at': 'girder@30.0', 'rate_hz': 100.0},
]


def scenario_file(tmp_path: Path, sensors, **sections) -> Path:
    data = {'name': 'sensed', 'description': 'two spans with sensors', **SPAN, **sections,
            'sensors': sensors}
    path = tmp_path / 'sensed.yaml'
    path.write_text(yaml.safe_dump(data), encoding='utf-8')
    return path


@pytest.fixture(scope='module')
def sensed_bag(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp('sensed')
    out = tmp / 'bag'
    assert main(['run', str(scenario_file(tmp, SENSORS)), '--out', str(out)]) == 0
    return out


@pytest.mark.parametrize('entry, message', [
    ({'type': 'sonar'}, r"sensors\[0\]\.type = 'sonar'"),
    ({'at': 'girder@abc'}, r"position 'abc' is not a finite number"),
    ({'at': 'deck@3'}, r"allowed forms are 'spanNN/x=X'"),
    ({'type': 'strain', 'at': 'car01'}, r'a strain cannot be at .car01. \(a car\)'),
    ({'type': 'wheel_force', 'at': 'girder@3'}, r'a wheel_force cannot be at'),
    ({'rate_hz': 300.0}, r'rate_hz = 300 does not divide the frame rate 1000 Hz'),
    ({'axes': ['z', 'z']}, r"axes = \['z', 'z'\]"),
    ({'axes': 'z'}, r'expected a list of strings'),
    ({'at': 'span03/x=3'}, r'span 3 does not exist; the bridge has 2'),
    ({'at': 'span01/x=21'}, r'x = 21 m is off the span; allowed 0 to 20 m'),
    ({'relative_to': 'girder@1', 'type': 'accelerometer'}, r'relative_to is for type '),
    ({'dropout_probability': 1.0}, r'dropout_probability = 1\.0 is out of range'),
    ({'name': '9lives'}, r"name = '9lives'"),
])
def test_bad_sensors_are_refused_naming_the_key(tmp_path, entry, message):
    sensor = {'name': 'one', 'type': 'accelerometer', 'at': 'girder@3.0', 'rate_hz': 100.0,
              **entry}
    with pytest.raises(ScenarioError, match=message):
        load_scenario(str(scenario_file(tmp_path, [sensor])))


def test_repeated_names_and_missing_places_are_refused_before_any_bag(tmp_path, capsys):
    two = [{'name': 'a', 'at': 'girder@3.0'}, {'name': 'a', 'at': 'girder@4.0'}]
    with pytest.raises(ScenarioError, match=r"sensors\[1\]\.name = 'a' is used twice"):
        load_scenario(str(scenario_file(tmp_path, two)))
    for sensor, message in (({'name': 'w', 'at': 'girder@99.0'}, 'x is not on the girder'),
                            ({'name': 'p', 'at': 'pier02/pile01'}, 'pier 2 is not piled'),
                            ({'name': 'c', 'at': 'car03'}, 'the model has no cars')):
        out = tmp_path / f'bag_{sensor["name"]}'
        assert main(['run', str(scenario_file(tmp_path, [sensor])), '--out', str(out)]) == 2
        assert message in capsys.readouterr().err and not out.exists()


def test_a_car_the_train_does_not_have_is_refused(tmp_path, capsys):
    out = tmp_path / 'bag'
    assert main(['run', 'sprung_mass_beam', '--out', str(out), '--set',
                 'sensors=[{name: c, at: car03}]', '--set', 'output.rate_hz=1000']) == 2
    assert 'car 3 does not exist; the model has 1 (1 to 1)' in capsys.readouterr().err
    assert not out.exists()


def test_sensor_topics_types_and_rates(sensed_bag):
    bag = read_bag(sensed_bag)
    rates = {s['name']: s['rate_hz'] for s in SENSORS}
    for name, rate in rates.items():
        topic = bag[f'/ttb_sim/sensors/{name}']
        steps = np.diff(topic.stamp_ns)
        assert steps.min() == round(1e9 / rate)
    assert bag['/ttb_sim/sensors/mid_a'].msgtype == 'sensor_msgs/msg/Imu'
    assert bag['/ttb_sim/sensors/tilt'].stamp_ns[0] == 2_000_000   # its clock offset
    gaps = np.diff(bag['/ttb_sim/sensors/sg'].stamp_ns) > round(1e9 / 100.0)
    assert gaps.any()                                              # its dropouts


def test_displacement_sensor_samples_the_filtered_truth(sensed_bag):
    bag = read_bag(sensed_bag)
    truth = bag['/ttb_sim/bridge/span01/midspan'].fields['vector']   # girder@10 is mid-span 1
    sensed = bag['/ttb_sim/sensors/mid_u'].fields['vector']
    summary = json.loads((sensed_bag / 'summary.json').read_text())
    mid_u = next(s for s in summary['sensors'] if s['name'] == 'mid_u')
    cheb = signal.cheby2(mid_u['anti_alias']['order'], 80.0,
                         signal.cheb2ord(225.0, 250.0, 0.1, 80.0, fs=1000.0)[1],
                         output='sos', fs=1000.0)
    zi = signal.sosfilt_zi(cheb)[:, :, None] * truth[0][None, None, :]
    expected = signal.sosfilt(cheb, truth, axis=0, zi=zi)[0][::2]
    assert np.allclose(sensed, expected, rtol=0, atol=1e-12 * np.abs(truth).max())
    assert np.abs(truth[:, 2]).max() > 1e-4
    assert np.all(bag['/ttb_sim/sensors/gap'].fields['vector'] == 0.0)


def test_imu_covariance_is_the_noise_variance(sensed_bag):
    summary = json.loads((sensed_bag / 'summary.json').read_text())
    mid_a = next(s for s in summary['sensors'] if s['name'] == 'mid_a')
    variance = mid_a['noise_std'] ** 2 + 1e-5 ** 2 / 12
    for msg in read_ros2_messages(str(next(sensed_bag.glob('*.mcap'))),
                                  topics=['/ttb_sim/sensors/mid_a']):
        cov = np.asarray(msg.ros_msg.linear_acceleration_covariance)
        assert cov[0] == pytest.approx(variance) and cov[8] == pytest.approx(variance)
        assert cov[4] == -1.0 and msg.ros_msg.orientation_covariance[0] == -1.0
        assert msg.ros_msg.linear_acceleration.y == 0.0
        break


def test_labels_in_summary_topic_and_metadata(sensed_bag):
    summary = json.loads((sensed_bag / 'summary.json').read_text())
    labels = summary['labels']
    assert labels['scenario'] == 'sensed' and labels['train']['speed_kmh'] == 200.0
    assert set(labels['seeds']['sensors']) == {s['name'] for s in SENSORS}
    messages = list(read_ros2_messages(str(next(sensed_bag.glob('*.mcap'))),
                                       topics=['/ttb_sim/labels']))
    assert len(messages) == 1 and json.loads(messages[0].ros_msg.data) == labels
    metadata = yaml.safe_load((sensed_bag / 'metadata.yaml').read_text())
    info = metadata['rosbag2_bagfile_information']
    assert json.loads(info['custom_data']['ttb_sim.labels']) == labels
    assert '/ttb_sim/labels' in summary['bag']['topics']


@pytest.mark.parametrize('name, sets, cars, axles', [
    ('moving_force_beam', [], 1, 1),                               # one force by hand
    ('moving_force_beam', ['train.axle_offsets=[0, 2.5, 17.5]'], 3, 3),   # one car per axle
    ('ten_span_train', [], 8, 32),                                 # the car layout
    ('sprung_mass_beam', [], 1, 1),
    ('live_train', [], 4, 16),
])
def test_labels_count_the_cars_the_model_runs(name, sets, cars, axles):
    """Not ``train.n_cars`` (8 by default): the cars the model carries a passenger load for."""
    from ttb_sim.config.labels import run_labels
    from ttb_sim.model.vehicle.train import MovingForces
    from ttb_sim.sim.build import build_vehicle
    scenario = load_scenario(name, sets + ['train.passenger_load=1000'])
    train = run_labels(scenario)['train']
    assert (train['n_cars'], train['n_axles']) == (cars, axles)
    vehicle = build_vehicle(scenario)
    assert vehicle.axles.count == axles
    t = scenario.train
    if isinstance(vehicle, MovingForces):   # m g per car, spread over its forces
        carried = (vehicle.loads.sum() - axles * t.axle_load) / 9.81
    else:                                   # m per car, spread over its sprung masses
        carried = vehicle.sprung_mass.sum() - axles * t.sprung_mass
    assert carried == pytest.approx(cars * 1000.0, rel=1e-3)


def test_same_scenario_same_bits(tmp_path, sensed_bag):
    out = tmp_path / 'again'
    assert main(['run', str(scenario_file(tmp_path, SENSORS)), '--out', str(out)]) == 0
    first, second = read_bag(sensed_bag), read_bag(out)
    for s in SENSORS:
        a, b = first[f'/ttb_sim/sensors/{s["name"]}'], second[f'/ttb_sim/sensors/{s["name"]}']
        assert np.array_equal(a.stamp_ns, b.stamp_ns)
        for field in a.fields:
            assert np.array_equal(a.fields[field], b.fields[field])


def test_labels_carry_the_damage_and_environment_state(tmp_path):
    out = tmp_path / 'damaged'
    assert main(['run', 'moving_force_beam', '--out', str(out), '--set',
                 'damage.girders=[{span: 1, start: 14, length: 4, loss: 0.3}]',
                 '--set', 'environment.temperature=-5', '--set',
                 'train.passenger_load=5000']) == 0
    labels = json.loads((out / 'summary.json').read_text())['labels']
    assert labels['damage']['girders'] == [{'span': 1, 'start': 14.0, 'length': 4.0,
                                            'loss': 0.3}]
    assert labels['environment']['temperature'] == -5.0
    assert labels['train']['passenger_load'] == 5000.0
    metadata = yaml.safe_load((out / 'metadata.yaml').read_text())
    stored = metadata['rosbag2_bagfile_information']['custom_data']['ttb_sim.labels']
    assert json.loads(stored) == labels
