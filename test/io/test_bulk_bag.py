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
Bags written a block at a time equal bags written message by message, for both storages.

The reference is the per-message path (``BagRecorder(bulk=False)``: every
message built and serialised by rosbags, written by rosbags' own storages).
One layout has every message type of the table (Clock, Odometry, Imu,
WrenchStamped, Vector3Stamped, PointCloud2), enough frames for several blocks
and several MCAP chunks, stamps across whole seconds, and values that are
negative, zero of both signs, tiny, huge, infinite and NaN. Compared: the
connections, every message's stamp and bytes in order (rosbags' AnyReader and
the independent ``mcap`` / ``mcap_ros2`` readers), metadata.yaml, the MCAP
summary (schemas, channels and their metadata, statistics, the rosbag2
metadata record) and the SQLite tables.
"""

from __future__ import annotations

from importlib.metadata import version
from pathlib import Path
import sqlite3

from mcap.reader import make_reader
from mcap_ros2.reader import read_ros2_messages
import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.io import bag as bag_module
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.block_storage import McapBlockStorage
from ttb_sim.io.topics import topic_table
from ttb_sim.sim import Frame

from block_frames import frames, LAYOUT   # noqa: I100 - the helper next to this file

FRAMES = 420
pytestmark = pytest.mark.filterwarnings('ignore:overflow encountered in cast:RuntimeWarning')


def _write(path: Path, storage: str, bulk: bool, items: list[Frame] | None = None) -> Path:
    with BagRecorder(path, topic_table(LAYOUT), storage, bulk=bulk) as bag:
        for frame in frames(FRAMES) if items is None else items:
            bag.write(frame)
    return path


@pytest.fixture(scope='module')
def bags(tmp_path_factory) -> dict[tuple[str, bool], Path]:
    """Per storage: the bag written in blocks (13 frames each) and the per-message one."""
    root = tmp_path_factory.mktemp('bulk')
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(bag_module, 'MAX_BLOCK_FRAMES', 13)
        # the same bag name in two folders: the file names in the metadata agree too
        return {(storage, bulk): _write(root / f'{storage}-{bulk}' / 'bag', storage, bulk)
                for storage in ('mcap', 'sqlite3') for bulk in (True, False)}


def _anyreader(path: Path) -> tuple[list[tuple], list[tuple[str, int, bytes]]]:
    with AnyReader([path]) as reader:
        connections = [(c.topic, c.msgtype, c.msgdef, c.digest, c.ext) for c in
                       reader.connections]
        messages = [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]
    return connections, messages


def test_the_layout_has_every_message_type():
    assert {t.msgtype for t in topic_table(LAYOUT)} == {
        'rosgraph_msgs/msg/Clock', 'nav_msgs/msg/Odometry', 'sensor_msgs/msg/Imu',
        'geometry_msgs/msg/WrenchStamped', 'geometry_msgs/msg/Vector3Stamped',
        'sensor_msgs/msg/PointCloud2'}


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_every_message_equals_the_per_message_path(bags, storage: str):
    bulk_connections, bulk = _anyreader(bags[storage, True])
    ref_connections, ref = _anyreader(bags[storage, False])
    assert bulk_connections == ref_connections
    assert len(ref) == FRAMES * len(topic_table(LAYOUT))
    assert bulk == ref   # topic, stamp and bytes of every message, in the reader's order
    stamps = sorted({t for _, t, _ in ref})
    assert stamps[0] == 950_000_000 and stamps[-1] > 1_000_000_000  # over a whole second


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_metadata_yaml_is_the_same(bags, storage: str):
    assert ((bags[storage, True] / 'metadata.yaml').read_text()
            == (bags[storage, False] / 'metadata.yaml').read_text())


def _mcap(path: Path) -> tuple[object, list[tuple], list[tuple]]:
    with open(path / 'bag.mcap', 'rb') as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        messages = [(channel.topic, m.log_time, m.publish_time, m.sequence, m.data)
                    for _, channel, m in reader.iter_messages(log_time_order=False)]
        metadata = [(m.name, m.metadata) for m in reader.iter_metadata()]
    return summary, messages, metadata


def test_mcap_summary_and_messages_with_the_mcap_reader(bags):
    summary, messages, metadata = _mcap(bags['mcap', True])
    ref_summary, ref_messages, ref_metadata = _mcap(bags['mcap', False])
    assert summary is not None and ref_summary is not None
    assert summary.schemas == ref_summary.schemas
    assert summary.channels == ref_summary.channels
    assert {s.encoding for s in summary.schemas.values()} == {'ros2msg'}
    assert {c.message_encoding for c in summary.channels.values()} == {'cdr'}
    assert all('offered_qos_profiles' in c.metadata for c in summary.channels.values())
    assert summary.statistics == ref_summary.statistics
    assert len(summary.chunk_indexes) == len(ref_summary.chunk_indexes) > 2
    assert [(c.message_start_time, c.message_end_time, c.uncompressed_size)
            for c in summary.chunk_indexes] == [
        (c.message_start_time, c.message_end_time, c.uncompressed_size)
        for c in ref_summary.chunk_indexes]
    assert metadata == ref_metadata and metadata[0][0] == 'rosbag2'
    assert messages == ref_messages


@pytest.mark.parametrize('count', [0, 1, FRAMES])
def test_mcap_file_is_rosbags_own_but_for_the_library_field(tmp_path: Path, monkeypatch,
                                                            count: int):
    """Written with rosbags' library name, the file is the very bytes rosbags writes."""
    items = frames(count)
    ref = _write(tmp_path / 'ref' / 'bag', 'mcap', False, items)
    monkeypatch.setattr(McapBlockStorage, 'LIBRARY', f'rosbags-{version("rosbags")}')
    monkeypatch.setattr(bag_module, 'MAX_BLOCK_FRAMES', 13)
    ours = _write(tmp_path / 'ours' / 'bag', 'mcap', True, items)
    assert (ours / 'bag.mcap').read_bytes() == (ref / 'bag.mcap').read_bytes()
    assert (ours / 'metadata.yaml').read_text() == (ref / 'metadata.yaml').read_text()


def test_mcap_ros2_decodes_every_message_to_the_frames_values(bags):
    items = frames(FRAMES)
    topics = {t.full_name(): t for t in topic_table(LAYOUT)}
    seen = dict.fromkeys(topics, 0)
    for m in read_ros2_messages(str(bags['mcap', True] / 'bag.mcap')):
        topic = topics[m.channel.topic]
        frame = items[seen[m.channel.topic]]
        seen[m.channel.topic] += 1
        assert m.log_time_ns == frame.stamp_ns
        if topic.msgtype == 'geometry_msgs/msg/WrenchStamped':
            force = m.ros_msg.wrench.force
            np.testing.assert_array_equal([force.x, force.y, force.z], topic.extract(frame)[:3])
        elif topic.msgtype == 'sensor_msgs/msg/PointCloud2':
            points = np.frombuffer(bytes(m.ros_msg.data), '<f4')
            np.testing.assert_array_equal(points, topic.extract(frame).astype('<f4'))
    assert set(seen.values()) == {FRAMES}


def _tables(path: Path) -> dict[str, list[tuple]]:
    db = sqlite3.connect(path / 'bag.db3')
    try:
        names = [r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")]
        return {name: db.execute(f'SELECT * FROM {name} ORDER BY 1').fetchall()
                for name in names}
    finally:
        db.close()


def test_sqlite_tables_are_the_same(bags):
    ours, ref = _tables(bags['sqlite3', True]), _tables(bags['sqlite3', False])
    assert ours.keys() == ref.keys() and 'messages' in ours
    assert ours == ref
