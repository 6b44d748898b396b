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
Pile and ground topics of the topic table (ARCHITECTURE.md contract), written and read back.

``~/piles/pierNN/pileMM/displacement`` (Vector3Stamped), ``~/piles/pierNN/pileMM/imu``
(Imu) and ``~/soil/points`` (PointCloud2, float32 x y z ux uy uz ax ay az), checked
through the bag writer with rosbags, the package's reader and the independent
mcap + mcap_ros2 readers. Exact equality (float32 for the cloud).
"""

import array

import numpy as np
import pytest
from rosbags.rosbag2 import Reader
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.cdr import typestore
from ttb_sim.io.reader import read_bag
from ttb_sim.io.topics import build_point_cloud, SOIL_FIELDS, topic_table
from ttb_sim.sim import Frame, Layout

LAYOUT = Layout(n_spans=1, n_supports=2, n_bodies=0, piles=((7, 3), (8, 2)), soil_points=4)


def _frame(step: int) -> Frame:
    rng = np.random.default_rng(step)
    n = LAYOUT.n_piles
    return Frame(step=step, time=step * 1e-3, head_position=0.0, speed=1.0,
                 midspan=np.zeros((1, 3)), bearings=np.zeros((2, 2, 3)),
                 body_acceleration=np.zeros((0, 3)), body_angular_velocity=np.zeros((0, 3)),
                 wheel_rail=np.zeros((0, 1, 2, 3)), observers=np.zeros((0, 3)),
                 pile_displacement=rng.normal(size=(n, 3)) * 1e-3,
                 pile_acceleration=rng.normal(size=(n, 3)),
                 pile_rotation_rate=rng.normal(size=(n, 3)) * 1e-2,
                 soil_points=rng.normal(size=(LAYOUT.soil_points, len(SOIL_FIELDS))))


def test_topic_names_follow_the_contract():
    names = [t.full_name() for t in topic_table(LAYOUT)]
    assert '/ttb_sim/piles/pier07/pile01/displacement' in names
    assert '/ttb_sim/piles/pier07/pile03/imu' in names
    assert '/ttb_sim/piles/pier08/pile02/imu' in names
    assert '/ttb_sim/piles/pier08/pile03/imu' not in names
    assert names.count('/ttb_sim/soil/points') == 1
    plain = topic_table(Layout(n_spans=1, n_supports=2, n_bodies=0))
    assert not [t for t in plain if 'piles/' in t.name or 'soil/' in t.name]


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_pile_and_soil_messages_round_trip(tmp_path, storage):
    frames = [_frame(k) for k in range(3)]
    with BagRecorder(tmp_path / 'bag', topic_table(LAYOUT), storage) as bag:
        for frame in frames:
            bag.write(frame)
    store = typestore()
    with Reader(tmp_path / 'bag') as reader:
        clouds = [store.deserialize_cdr(raw, c.msgtype) for c, _, raw in reader.messages()
                  if c.topic == '/ttb_sim/soil/points']
    assert len(clouds) == 3
    cloud = clouds[1]
    assert (cloud.height, cloud.width, cloud.point_step) == (1, 4, 48)
    assert [f.name for f in cloud.fields] == list(SOIL_FIELDS)
    # the contract's nine fields first, at their offsets; the velocities after them
    assert [(f.name, f.offset) for f in cloud.fields[:9]] == [
        (name, 4 * i) for i, name in enumerate(('x', 'y', 'z', 'ux', 'uy', 'uz', 'ax', 'ay',
                                                'az'))]
    assert {f.datatype for f in cloud.fields} == {7} and not cloud.is_bigendian
    points = np.frombuffer(cloud.data.tobytes(), dtype='<f4').reshape(4, 12)
    np.testing.assert_array_equal(points, frames[1].soil_points.astype(np.float32))
    arrays = read_bag(tmp_path / 'bag')
    disp = arrays['/ttb_sim/piles/pier08/pile02/displacement']['vector']
    np.testing.assert_array_equal(disp, np.stack([f.pile_displacement[4] for f in frames]))
    imu = arrays['/ttb_sim/piles/pier07/pile02/imu']
    np.testing.assert_array_equal(imu['linear_acceleration'],
                                  np.stack([f.pile_acceleration[1] for f in frames]))
    np.testing.assert_array_equal(imu['angular_velocity'],
                                  np.stack([f.pile_rotation_rate[1] for f in frames]))
    soil = arrays['/ttb_sim/soil/points']['points']
    np.testing.assert_array_equal(soil[2], frames[2].soil_points.astype(np.float32))


def test_mcap_reader_decodes_the_cloud_independently(tmp_path):
    mcap_reader = pytest.importorskip('mcap.reader')
    decoder = pytest.importorskip('mcap_ros2.decoder')
    frame = _frame(5)
    with BagRecorder(tmp_path / 'bag', topic_table(LAYOUT), 'mcap') as bag:
        bag.write(frame)
    path = next((tmp_path / 'bag').glob('*.mcap'))
    with path.open('rb') as fh:
        reader = mcap_reader.make_reader(fh, decoder_factories=[decoder.DecoderFactory()])
        msgs = [m for _, ch, _, m in reader.iter_decoded_messages()
                if ch.topic == '/ttb_sim/soil/points']
    assert len(msgs) == 1
    points = np.frombuffer(bytes(msgs[0].data), dtype='<f4').reshape(-1, 12)
    np.testing.assert_array_equal(points, frame.soil_points.astype(np.float32))


def test_rclpy_style_classes_get_an_array_of_bytes():
    """A non-rosbags message class (rclpy's) receives data as array('B'), as rclpy requires."""
    made = {}

    def fake(name):
        def make(**kwargs):
            made[name] = kwargs
            return kwargs
        make.__module__ = name.replace('/', '.')
        return make

    build_point_cloud(fake, 0, np.arange(24, dtype=float))
    data = made['sensor_msgs/msg/PointCloud2']['data']
    assert isinstance(data, array.array) and data.typecode == 'B' and len(data) == 96
