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
The bag reader (io/reader.py): bags back to arrays, equal to the frames that were written.

Bags are written with the project's own recorder (both storages) while the frames
are kept, then read back and compared exactly (the values are float64 on both
sides); MCAP bags are also compared with the independent mcap + mcap_ros2 readers.
Hand-written bags cover what ``ros2 bag record`` adds: receive times apart from
the stamps, point clouds, diagnostics, types the reader does not flatten.
"""

from __future__ import annotations

from pathlib import Path
import shutil

from mcap_ros2.reader import read_ros2_messages
import numpy as np
import pytest
from rosbags.rosbag2 import StoragePlugin, Writer
from ttb_sim.config import load_scenario
from ttb_sim.errors import BagError, ScenarioError
from ttb_sim.io import cdr as cdr_module
from ttb_sim.io import reader as reader_module
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.cdr import typestore
from ttb_sim.io.reader import bag_topics, read_bag, SUPPORTED_TYPES, TopicArrays
from ttb_sim.io.topics import topic_table
from ttb_sim.sim import Frame, Simulation

NS = '/ttb_sim'


def _record(path: Path, storage: str) -> list[Frame]:
    """Write a short sprung-mass run (with one observer) and return its frames."""
    scenario = load_scenario('sprung_mass_beam', ['output.observers=["girder=girder@10.0"]'],
                             [('solver.duration', 0.05)])
    sim = Simulation(scenario)
    frames = []
    with BagRecorder(path, topic_table(sim.layout), storage) as bag:
        for frame in sim.frames():
            bag.write(frame)
            frames.append(frame)
    return frames


@pytest.fixture(scope='module')
def written(tmp_path_factory) -> tuple[dict[str, Path], list[Frame]]:
    tmp = tmp_path_factory.mktemp('reader')
    frames = _record(tmp / 'mcap', 'mcap')
    again = _record(tmp / 'sqlite3', 'sqlite3')
    assert [f.stamp_ns for f in again] == [f.stamp_ns for f in frames]
    return {'mcap': tmp / 'mcap', 'sqlite3': tmp / 'sqlite3'}, frames


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_every_topic_equals_the_frames(written, storage):
    paths, frames = written
    bag = read_bag(paths[storage])
    assert list(bag) == [
        '/clock', f'{NS}/train/odometry', f'{NS}/train/car01/body/imu',
        f'{NS}/wheel_rail/car01/axle1/left', f'{NS}/wheel_rail/car01/axle1/right',
        f'{NS}/bridge/span01/midspan', f'{NS}/bearings/pier01/left',
        f'{NS}/bearings/pier01/right', f'{NS}/bearings/pier02/left',
        f'{NS}/bearings/pier02/right', f'{NS}/observers/girder']
    stamps = np.array([f.stamp_ns for f in frames])
    for arrays in bag.values():
        assert len(arrays) == len(frames)
        np.testing.assert_array_equal(arrays.stamp_ns, stamps)
        np.testing.assert_array_equal(arrays.receive_ns, stamps)   # ttb-sim stamps = log time
    np.testing.assert_array_equal(bag['/clock'].stamp, stamps * 1e-9)
    assert bag['/clock'].fields == {}

    def stacked(name: str) -> np.ndarray:
        return np.array([getattr(f, name) for f in frames])

    midspan = bag[f'{NS}/bridge/span01/midspan']
    assert midspan.components['vector'] == ('x', 'y', 'z')
    np.testing.assert_array_equal(midspan['vector'], stacked('midspan')[:, 0])
    np.testing.assert_array_equal(bag[f'{NS}/observers/girder']['vector'],
                                  stacked('observers')[:, 0])
    imu = bag[f'{NS}/train/car01/body/imu']
    np.testing.assert_array_equal(imu['linear_acceleration'],
                                  stacked('body_acceleration')[:, 0])
    np.testing.assert_array_equal(imu['angular_velocity'],
                                  stacked('body_angular_velocity')[:, 0])
    np.testing.assert_array_equal(imu['orientation'], np.tile([0.0, 0, 0, 1], (len(frames), 1)))
    assert imu.components['orientation'] == ('x', 'y', 'z', 'w')
    for s, side in enumerate(('left', 'right')):
        wheel = bag[f'{NS}/wheel_rail/car01/axle1/{side}']
        np.testing.assert_array_equal(wheel['force'], stacked('wheel_rail')[:, 0, 0, s])
        np.testing.assert_array_equal(wheel['torque'], 0.0)
        for pier in (1, 2):
            bearing = bag[f'{NS}/bearings/pier{pier:02d}/{side}']
            np.testing.assert_array_equal(bearing['force'],
                                          stacked('bearings')[:, pier - 1, s])
    odometry = bag[f'{NS}/train/odometry']
    np.testing.assert_array_equal(odometry.component('position', 'x'),
                                  stacked('head_position'))
    np.testing.assert_array_equal(odometry.component('linear_velocity', 'x'), stacked('speed'))
    np.testing.assert_array_equal(odometry['angular_velocity'], 0.0)


def test_mcap_agrees_with_the_independent_mcap_ros2_reader(written):
    paths, _ = written
    bag = read_bag(paths['mcap'])
    mcap_file = next(paths['mcap'].glob('*.mcap'))
    seen: dict[str, list] = {}
    for m in read_ros2_messages(str(mcap_file)):
        seen.setdefault(m.channel.topic, []).append(m)
    assert set(seen) == set(bag)
    for topic, messages in seen.items():
        arrays = bag[topic]
        np.testing.assert_array_equal(arrays.receive_ns, [m.log_time_ns for m in messages])
        msgs = [m.ros_msg for m in messages]
        if topic == '/clock':
            expected = [c.clock.sec * 10**9 + c.clock.nanosec for c in msgs]
        else:
            expected = [c.header.stamp.sec * 10**9 + c.header.stamp.nanosec for c in msgs]
        np.testing.assert_array_equal(arrays.stamp_ns, expected)
        paths_by_field = reader_module._FLAT[arrays.msgtype]
        for name, path in paths_by_field.items():
            for k, axis in enumerate(arrays.components[name]):
                values = []
                for msg in msgs:
                    value = msg
                    for part in f'{path}.{axis}'.split('.'):
                        value = getattr(value, part)
                    values.append(value)
                np.testing.assert_array_equal(arrays[name][:, k], values, err_msg=topic)


def test_both_storages_read_the_same(written):
    paths, _ = written
    a, b = read_bag(paths['mcap']), read_bag(paths['sqlite3'])
    assert list(a) == list(b)
    for topic in a:
        assert a[topic].msgtype == b[topic].msgtype
        np.testing.assert_array_equal(a[topic].stamp_ns, b[topic].stamp_ns)
        for name in a[topic].fields:
            np.testing.assert_array_equal(a[topic][name], b[topic][name])


def test_the_per_message_path_gives_the_same_arrays(written, monkeypatch):
    """The layout decoder against rosbags' own deserialiser, message by message."""
    paths, _ = written
    fast = read_bag(paths['mcap'])

    def no_layout(*args, **kwargs):
        raise cdr_module.NoLayout
    monkeypatch.setattr(cdr_module, 'CdrLayout', no_layout)
    slow = read_bag(paths['mcap'])
    for topic in fast:
        np.testing.assert_array_equal(fast[topic].stamp_ns, slow[topic].stamp_ns)
        assert fast[topic].fields.keys() == slow[topic].fields.keys()
        for name in fast[topic].fields:
            np.testing.assert_array_equal(fast[topic][name], slow[topic][name])


def test_topics_by_absolute_or_relative_name(written):
    paths, _ = written
    bag = read_bag(paths['mcap'], ['bridge/span01/midspan', '/clock'])
    assert list(bag) == ['/clock', f'{NS}/bridge/span01/midspan']
    assert bag_topics(paths['mcap'])[f'{NS}/train/odometry'] == 'nav_msgs/msg/Odometry'
    arrays = bag[f'{NS}/bridge/span01/midspan']
    assert arrays.stamp[1] == pytest.approx(arrays.stamp_ns[1] * 1e-9)
    assert arrays.receive_time[1] == arrays.stamp[1]
    with pytest.raises(KeyError, match=r"no field 'force'; fields: vector"):
        arrays['force']
    with pytest.raises(KeyError, match=r"components x, y, z, not 'w'"):
        arrays.component('vector', 'w')


def test_the_storage_file_alone_reads_too(written):
    paths, _ = written
    bag = read_bag(next(paths['mcap'].glob('*.mcap')), ['/clock'])
    assert len(bag['/clock']) > 10


# -- refusals -------------------------------------------------------------------------------

def test_missing_and_ambiguous_topics_are_refused(written):
    paths, _ = written
    with pytest.raises(BagError, match=r"topic '/ttb_sim/soil/points' is not in bag .*"
                                       r'topics: /clock, /ttb_sim/train/odometry'):
        read_bag(paths['mcap'], ['/ttb_sim/soil/points'])
    with pytest.raises(BagError, match=r"topic 'left' is ambiguous in bag .*axle1/left, "):
        read_bag(paths['sqlite3'], ['left'])


def test_a_directory_that_is_not_a_bag(tmp_path: Path):
    (tmp_path / 'notes.txt').write_text('hello\n')
    with pytest.raises(BagError, match=r'is not a rosbag2 directory \(no metadata.yaml\)'):
        read_bag(tmp_path)
    with pytest.raises(BagError, match=r'notes.txt.* is not a bag: give its directory'):
        read_bag(tmp_path / 'notes.txt')
    with pytest.raises(BagError, match=r'does not exist'):
        read_bag(tmp_path / 'nothing')
    assert issubclass(BagError, ScenarioError)   # the CLI answers exit code 2


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_truncated_bag(written, tmp_path: Path, storage):
    """What a killed recording leaves: a storage file cut short."""
    paths, _ = written
    bag = tmp_path / 'cut'
    shutil.copytree(paths[storage], bag)
    data = next(p for p in bag.iterdir() if p.suffix in ('.mcap', '.db3'))
    data.write_bytes(data.read_bytes()[:data.stat().st_size // 2])
    with pytest.raises(BagError, match=r'is truncated or corrupt \(.+\); a recording that '
                                       'was killed'):
        read_bag(bag)
    (bag / 'metadata.yaml').unlink()    # rosbags writes it on close: a killed run has none
    # read as a killed run's bag (test_salvage.py): here nothing complete is left to read
    with pytest.raises(BagError, match=rf"^bag '{bag}': the recording did not finish \(a "
                                       r'killed run\?\), and .*' + data.name):
        read_bag(bag)


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_recovery_is_pointed_to_for_a_cut_file(written, tmp_path: Path, storage):
    paths, _ = written
    bag = tmp_path / 'cut'
    shutil.copytree(paths[storage], bag)
    data = next(p for p in bag.iterdir() if p.suffix in ('.mcap', '.db3'))
    data.write_bytes(data.read_bytes()[:data.stat().st_size // 2])
    with pytest.raises(BagError) as info:
        read_bag(bag)
    message = str(info.value)
    assert '\n' not in message and f'({str(data)!r}: ' in message
    assert message.endswith(': `ttb-sim recover` may rescue it')


@pytest.mark.parametrize('text, message', [
    ('rosbag2_bagfile_information: [\n', r'is not valid YAML: .*\(line 2, column 1\)$'),
    ('rosbag2_bagfile_information:\n  version: 9\n\tfiles: []\n',
     r'is not valid YAML: .*\(line 3, column 1\)$'),
    ('', r"is not rosbag2 metadata: it needs a mapping 'rosbag2_bagfile_information' at the "
     r'top, found nothing \(an empty file\)$'),
    ('foo: 1\nbar: 2\n', r'is not rosbag2 metadata: .* found the keys foo, bar$'),
    ('- 1\n', r'is not rosbag2 metadata: .* found a list$'),
    ('rosbag2_bagfile_information: {}\n', r"is invalid: the key 'version' is missing$"),
    ('rosbag2_bagfile_information: {version: 9, relative_file_paths: [gone.mcap]}\n',
     r"lists storage files that are not in '.*meta': gone.mcap$"),
])
def test_a_broken_metadata_file_is_named_in_one_line(written, tmp_path: Path, text, message):
    paths, _ = written
    bag = tmp_path / 'meta'
    shutil.copytree(paths['mcap'], bag)
    (bag / 'metadata.yaml').write_text(text)
    with pytest.raises(BagError, match=rf"^bag metadata '{bag}/metadata.yaml' {message}") as info:
        read_bag(bag)
    assert '\n' not in str(info.value) and 'recover' not in str(info.value)
    (bag / 'metadata.yaml').write_bytes(b'\xff\xfe')
    with pytest.raises(BagError, match=r'metadata.yaml. cannot be read: not UTF-8 text'):
        bag_topics(bag)


def test_damaged_messages_are_refused_not_raised(written, tmp_path: Path):
    """Bytes changed inside an MCAP: a length field or a message gone wrong is a BagError."""
    paths, _ = written
    source = next(p for p in paths['mcap'].iterdir() if p.suffix == '.mcap')
    data = source.read_bytes()
    rng = np.random.default_rng(1)
    outcomes = set()
    for trial in range(12):
        bag = tmp_path / f'damaged{trial}'
        shutil.copytree(paths['mcap'], bag)
        damaged = bytearray(data)
        for i in rng.integers(0, len(data), 20):
            damaged[i] = int(rng.integers(0, 256))
        (bag / source.name).write_bytes(bytes(damaged))
        try:
            read_bag(bag)
            outcomes.add('read')
        except BagError as exc:
            assert '\n' not in str(exc) and str(exc).startswith(f'bag {str(bag)!r} ')
            outcomes.add('refused')
    assert 'refused' in outcomes


# -- what `ros2 bag record` adds ------------------------------------------------------------

def _header(store, stamp_ns: int, frame_id: str):
    return store.types['std_msgs/msg/Header'](
        stamp=store.types['builtin_interfaces/msg/Time'](sec=stamp_ns // 10**9,
                                                         nanosec=stamp_ns % 10**9),
        frame_id=frame_id)


def _cloud(store, stamp_ns: int, points: np.ndarray):
    names = ('x', 'y', 'z', 'ux', 'uy', 'uz', 'ax', 'ay', 'az')
    field = store.types['sensor_msgs/msg/PointField']
    fields = [field(name=n, offset=4 * i, datatype=7, count=1) for i, n in enumerate(names)]
    data = np.ascontiguousarray(points, dtype='<f4').view(np.uint8).ravel()
    return store.types['sensor_msgs/msg/PointCloud2'](
        header=_header(store, stamp_ns, 'track'), height=1, width=len(points), fields=fields,
        is_bigendian=False, point_step=36, row_step=36 * len(points), data=data,
        is_dense=True)


def _diagnostic(store, stamp_ns: int, rtf: str):
    kv = store.types['diagnostic_msgs/msg/KeyValue']
    status = store.types['diagnostic_msgs/msg/DiagnosticStatus'](
        level=1, name='ttb_sim: simulation', message='ok', hardware_id='ttb_sim',
        values=[kv(key='state', value='running'), kv(key='real-time factor', value=rtf)])
    return store.types['diagnostic_msgs/msg/DiagnosticArray'](
        header=_header(store, stamp_ns, ''), status=[status])


@pytest.fixture(scope='module')
def recorded(tmp_path_factory) -> tuple[Path, dict[str, list]]:
    """Write a bag like `ros2 bag record` makes: log times are wall clock, stamps sim time."""
    path = tmp_path_factory.mktemp('record') / 'bag'
    store = typestore()
    rng = np.random.default_rng(3)
    written: dict[str, list] = {'clouds': [], 'vectors': [], 'stamps': []}
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = {
            'points': writer.add_connection(f'{NS}/soil/points', 'sensor_msgs/msg/PointCloud2',
                                            typestore=store),
            'diag': writer.add_connection('/diagnostics',
                                          'diagnostic_msgs/msg/DiagnosticArray',
                                          typestore=store),
            'marker': writer.add_connection(f'{NS}/model/markers',
                                            'visualization_msgs/msg/MarkerArray',
                                            typestore=store),
            'obs': writer.add_connection(f'{NS}/observers/rail',
                                         'geometry_msgs/msg/Vector3Stamped', typestore=store),
        }
        wall = 1_700_000_000_000_000_000
        for k in range(6):
            stamp = k * 10_000_000
            log_time = wall + k * 25_000_000
            points = rng.standard_normal((4 if k != 3 else 2, 9)).astype(np.float32)
            written['clouds'].append(points)
            written['stamps'].append((stamp, log_time))
            msg = _cloud(store, stamp, points)
            writer.write(conn['points'], log_time,
                         store.serialize_cdr(msg, 'sensor_msgs/msg/PointCloud2'))
            vector = rng.standard_normal(3)
            written['vectors'].append(vector)
            frame_id = 'track' if k % 2 else 'a_longer_frame_id'   # two CDR layouts
            obs = store.types['geometry_msgs/msg/Vector3Stamped'](
                header=_header(store, stamp, frame_id),
                vector=store.types['geometry_msgs/msg/Vector3'](*vector))
            writer.write(conn['obs'], log_time,
                         store.serialize_cdr(obs, 'geometry_msgs/msg/Vector3Stamped'))
            if k % 3 == 0:
                rtf = 'n/a' if k == 0 else f'{0.5 + k:.3g}'
                writer.write(conn['diag'], log_time, store.serialize_cdr(
                    _diagnostic(store, stamp, rtf), 'diagnostic_msgs/msg/DiagnosticArray'))
        markers = store.types['visualization_msgs/msg/MarkerArray'](markers=[])
        writer.write(conn['marker'], wall, store.serialize_cdr(
            markers, 'visualization_msgs/msg/MarkerArray'))
    return path, written


def test_recorded_bag_stamps_receive_times_and_layouts(recorded):
    path, written = recorded
    bag = read_bag(path)
    assert f'{NS}/model/markers' not in bag   # not flattened: skipped
    obs = bag[f'{NS}/observers/rail']
    stamps, log_times = np.array(written['stamps']).T
    np.testing.assert_array_equal(obs.stamp_ns, stamps)
    np.testing.assert_array_equal(obs.receive_ns, log_times)
    np.testing.assert_array_equal(obs['vector'], np.array(written['vectors']))


def test_point_clouds_become_messages_by_points_by_fields(recorded):
    path, written = recorded
    cloud = read_bag(path, ['soil/points'])[f'{NS}/soil/points']
    assert cloud.components['points'] == ('x', 'y', 'z', 'ux', 'uy', 'uz', 'ax', 'ay', 'az')
    assert cloud['points'].shape == (6, 4, 9) and cloud['points'].dtype == np.float32
    for k, points in enumerate(written['clouds']):
        np.testing.assert_array_equal(cloud['points'][k, :len(points)], points)
    assert np.isnan(cloud['points'][3, 2:]).all()   # a smaller cloud is padded with NaN
    np.testing.assert_array_equal(cloud.component('points', 'uz')[0], written['clouds'][0][:, 5])


def test_diagnostics_give_levels_and_numeric_values(recorded):
    path, _ = recorded
    diag = read_bag(path, ['/diagnostics'])['/diagnostics']
    assert len(diag) == 2
    np.testing.assert_array_equal(diag['ttb_sim: simulation/level'], [1, 1])
    rtf = diag['ttb_sim: simulation/real-time factor']
    assert np.isnan(rtf[0]) and rtf[1] == 3.5
    assert 'ttb_sim: simulation/state' not in diag.fields


def test_unsupported_types_are_refused_by_name(recorded):
    path, _ = recorded
    with pytest.raises(BagError, match=r'visualization_msgs/msg/MarkerArray, which read_bag '
                                       r'does not flatten; supported: .*Vector3Stamped'):
        read_bag(path, ['model/markers'])
    assert 'sensor_msgs/msg/PointCloud2' in SUPPORTED_TYPES
    assert read_bag(path, []) == {}


def test_an_empty_topic_has_empty_arrays():
    arrays = TopicArrays('/t', 'geometry_msgs/msg/Vector3Stamped', *reader_module._decode(
        typestore(), 'geometry_msgs/msg/Vector3Stamped', [])[:1], np.zeros(0, np.int64),
        *reader_module._decode(typestore(), 'geometry_msgs/msg/Vector3Stamped', [])[1:])
    assert len(arrays) == 0 and arrays['vector'].shape == (0, 3)


def test_one_layout_per_topic_and_cdr_shape(written, recorded, monkeypatch):
    """Messages of one shape are decoded together: one layout each, not one per message."""
    built: list[str] = []
    original = cdr_module.CdrLayout

    def spy(store, msgtype, data):
        built.append(msgtype)
        return original(store, msgtype, data)
    monkeypatch.setattr(cdr_module, 'CdrLayout', spy)
    paths, frames = written
    assert len(read_bag(paths['mcap'])) == len(built) == 11
    built.clear()
    read_bag(recorded[0], ['observers/rail'])
    assert built == ['geometry_msgs/msg/Vector3Stamped'] * 2   # two frame_id lengths
