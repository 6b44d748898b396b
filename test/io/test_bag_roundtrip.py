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

"""Bags from `ttb-sim run`: readable by rosbags and by the independent mcap readers."""

import json
from pathlib import Path

from mcap_ros2.reader import read_ros2_messages
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import get_typestore, Stores
from ttb_sim.cli import main
from ttb_sim.validation.references.structural import Beam, fryba_peak

ALPHA = 0.45


def _run(tmp_path: Path, name: str, *extra: str) -> Path:
    out = tmp_path / name
    assert main(['run', 'moving_force_beam', '--out', str(out), *extra]) == 0
    return out


def _rosbags_messages(path: Path) -> dict[str, list]:
    store = get_typestore(Stores.ROS2_JAZZY)
    out: dict[str, list] = {}
    with AnyReader([path], default_typestore=store) as reader:
        for conn, stamp, raw in reader.messages():
            out.setdefault(conn.topic, []).append((stamp, conn.msgtype,
                                                   reader.deserialize(raw, conn.msgtype)))
    return out


@pytest.fixture(scope='module')
def mcap_bag(tmp_path_factory) -> Path:
    tmp = tmp_path_factory.mktemp('bag')
    beam = Beam(20.0, 2e10, 10000.0)
    speed_kmh = ALPHA * 2 * beam.f1 * beam.length * 3.6
    return _run(tmp, 'run1', '--set', 'bridge.span_length=20', '--set',
                'bridge.bending_stiffness=2e10', '--set', 'bridge.mass_per_length=10000',
                '--speed-kmh', str(speed_kmh))


def test_contract_topics_and_types(mcap_bag: Path):
    msgs = _rosbags_messages(mcap_bag)
    assert msgs['/ttb_sim/bridge/span01/midspan'][0][1] == 'geometry_msgs/msg/Vector3Stamped'
    assert msgs['/ttb_sim/train/odometry'][0][1] == 'nav_msgs/msg/Odometry'
    assert msgs['/clock'][0][1] == 'rosgraph_msgs/msg/Clock'
    assert msgs['/ttb_sim/bearings/pier01/left'][0][1] == 'geometry_msgs/msg/WrenchStamped'
    assert (mcap_bag / 'metadata.yaml').is_file()
    assert (mcap_bag / 'summary.json').is_file()


def test_midspan_peak_matches_fryba_with_both_readers(mcap_bag: Path):
    """V1 through a bag: peak of the midspan topic within 1 % of Fryba's series."""
    beam = Beam(20.0, 2e10, 10000.0)
    speed = ALPHA * 2 * beam.f1 * beam.length
    reference = fryba_peak(beam, 156960.0, speed)
    z_rosbags = [m.vector.z for _, _, m in _rosbags_messages(mcap_bag)[
        '/ttb_sim/bridge/span01/midspan']]
    mcap_file = next(mcap_bag.glob('*.mcap'))
    z_mcap, stamps = [], []
    for m in read_ros2_messages(str(mcap_file), topics=['/ttb_sim/bridge/span01/midspan']):
        z_mcap.append(m.ros_msg.vector.z)
        stamps.append(m.ros_msg.header.stamp.sec * 10**9 + m.ros_msg.header.stamp.nanosec)
    assert z_mcap == z_rosbags
    assert -min(z_mcap) == pytest.approx(reference, rel=0.01)
    assert np.all(np.diff(stamps) > 0)  # stamps are simulation time, increasing


def test_summary_json(mcap_bag: Path):
    summary = json.loads((mcap_bag / 'summary.json').read_text())
    assert summary['status'] == 'ok'
    assert summary['scenario']['name'] == 'moving_force_beam'
    assert summary['real_time_factor'] > 0
    peak = summary['peaks']['/ttb_sim/bridge/span01/midspan']['z']['min']
    z = [m.vector.z for _, _, m in _rosbags_messages(mcap_bag)['/ttb_sim/bridge/span01/midspan']]
    assert peak == min(z)


def test_same_command_same_data(tmp_path: Path):
    a = _rosbags_messages(_run(tmp_path, 'a', '--duration', '0.2'))
    b = _rosbags_messages(_run(tmp_path, 'b', '--duration', '0.2'))
    store = get_typestore(Stores.ROS2_JAZZY)
    assert a.keys() == b.keys()
    for topic in a:
        ser_a = [(s, store.serialize_cdr(m, t)) for s, t, m in a[topic]]
        ser_b = [(s, store.serialize_cdr(m, t)) for s, t, m in b[topic]]
        assert ser_a == ser_b, topic


def test_sqlite3_storage(tmp_path: Path):
    out = _run(tmp_path, 'sq', '--storage', 'sqlite3', '--duration', '0.1')
    assert list(out.glob('*.db3'))
    msgs = _rosbags_messages(out)
    assert len(msgs['/ttb_sim/bridge/span01/midspan']) > 10


def test_sprung_mass_imu_topic(tmp_path: Path):
    out = tmp_path / 'sm'
    assert main(['run', 'sprung_mass_beam', '--out', str(out)]) == 0
    msgs = _rosbags_messages(out)
    acc = [m.linear_acceleration.z for _, _, m in msgs['/ttb_sim/train/car01/body/imu']]
    assert max(abs(a) for a in acc) == pytest.approx(0.148, rel=0.05)
    assert msgs['/ttb_sim/train/car01/body/imu'][0][1] == 'sensor_msgs/msg/Imu'
