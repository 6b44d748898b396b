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
The pieces of the block output path: frame rows, learnt CDR layouts, kept frames, peaks.

Frames read as flat rows mapped by their layout; every topic's layout is learnt
from its builder (and a builder whose bytes change size with the values is
left to the per-message path, with the same bag); frames kept for a block are
written when the recorder closes, also on an error; the peaks over rows are
those of the values per topic.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.cdr import typestore
from ttb_sim.io.codec import learn
from ttb_sim.io.topics import build_vector3_stamped, PeakTracker, topic_table
from ttb_sim.sim import Layout

from block_frames import frames, LAYOUT   # noqa: I100 - the helper next to this file

pytestmark = pytest.mark.filterwarnings('ignore:overflow encountered in cast:RuntimeWarning')


def _messages(path: Path) -> list[tuple[str, int, bytes]]:
    with AnyReader([path]) as reader:
        return [(c.topic, t, bytes(raw)) for c, t, raw in reader.messages()]


def test_frame_rows_follow_the_layout_columns():
    frame = frames(1)[0]
    columns = LAYOUT.columns()
    assert frame.row.size == LAYOUT.row_width and frame.row[columns['zero']] == 0.0
    for name, cols in columns.items():
        if name != 'zero':
            np.testing.assert_array_equal(frame.row[cols], getattr(frame, name))
    LAYOUT.check(frame)
    with pytest.raises(ValueError, match='frame field midspan has shape'):
        replace(LAYOUT, n_spans=3).check(frame)


def test_topic_values_are_the_frame_fields_they_name():
    frame = frames(1)[0]
    values = {t.name: t.extract(frame) for t in topic_table(LAYOUT)}
    np.testing.assert_array_equal(values['wheel_rail/car02/axle3/right'],
                                  [*frame.wheel_rail[1, 2, 1], 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(values['bearings/pier03/left'],
                                  [*frame.bearings[2, 0], 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(values['train/car02/body/imu'],
                                  [*frame.body_acceleration[1], *frame.body_angular_velocity[1]])
    np.testing.assert_array_equal(values['piles/pier03/pile01/imu'],
                                  [*frame.pile_acceleration[3], *frame.pile_rotation_rate[3]])
    np.testing.assert_array_equal(values['train/odometry'],
                                  [frame.head_position, frame.speed])
    np.testing.assert_array_equal(values['soil/points'], frame.soil_points.ravel())
    np.testing.assert_array_equal(values['observers/mid'], frame.observers[1])
    assert values['/clock'].size == 0


def test_every_topic_has_a_learnt_layout_with_its_stamp():
    store = typestore()
    for topic in topic_table(LAYOUT):
        codec = learn(store, topic)
        assert codec is not None, topic.name
        assert codec.stamp is not None and len(codec.offsets) == len(topic.columns)
        assert codec.float32.any() == (topic.msgtype == 'sensor_msgs/msg/PointCloud2')


def _named_by_value(types, stamp_ns: int, values: np.ndarray):
    msg = build_vector3_stamped(types, stamp_ns, values)
    msg.header.frame_id = f'{values[0]:.3g}'   # its size changes with the value
    return msg


def test_a_topic_without_a_fixed_layout_takes_the_per_message_path(tmp_path: Path, caplog):
    midspan = next(t for t in topic_table(LAYOUT) if t.name == 'bridge/span01/midspan')
    odd = replace(midspan, name='odd', build=_named_by_value)
    assert learn(typestore(), odd) is None
    bags = []
    for bulk in (True, False):
        with BagRecorder(tmp_path / f'{bulk}' / 'bag', [midspan, odd], bulk=bulk) as bag:
            for frame in frames(30):
                bag.write(frame)
        bags.append(_messages(tmp_path / f'{bulk}' / 'bag'))
    assert 'no fixed CDR layout for odd' in caplog.text
    assert bags[0] == bags[1] and len(bags[0]) == 60


def test_kept_frames_are_written_when_the_recording_fails(tmp_path: Path):
    with pytest.raises(RuntimeError, match='stepping failed'):
        with BagRecorder(tmp_path / 'bag', topic_table(LAYOUT)) as bag:
            for frame in frames(5):
                bag.write(frame)
            raise RuntimeError('stepping failed')
    messages = _messages(tmp_path / 'bag')
    assert len(messages) == 5 * len(topic_table(LAYOUT)) == bag.messages


def test_a_frame_of_another_width_is_refused(tmp_path: Path):
    other = Layout(n_spans=2, n_supports=3, n_bodies=2, n_axles=4, observers=('left',),
                   piles=((2, 3), (3, 1)), soil_points=40)
    with BagRecorder(tmp_path / 'bag', topic_table(other)) as bag:
        bag.write(frames(1, other)[0])
        with pytest.raises(ValueError, match=r'has \d+ values; the frames before it had'):
            bag.write(frames(1)[0])
    assert len(_messages(tmp_path / 'bag')) == len(topic_table(other))


def test_peaks_over_rows_are_the_peaks_of_each_topics_values():
    items = frames(60)
    topics = topic_table(LAYOUT)
    by_frame, by_block = PeakTracker(topics), PeakTracker(topics)
    for frame in items:
        by_frame.update(frame)
    by_block.update_rows(np.stack([f.row for f in items[:17]]))
    by_block.update_rows(np.stack([f.row for f in items[17:]]))
    want = {}
    for topic in topics:
        if not topic.fields:
            continue
        values = np.stack([topic.extract(f) for f in items])
        lo, hi = values.min(axis=0), values.max(axis=0)
        if np.all(np.isfinite(lo)):
            want[topic.full_name()] = {f: {'min': a, 'max': b, 'abs_max': max(abs(a), abs(b))}
                                       for f, a, b in zip(topic.fields, lo, hi)}
    assert by_frame.summary() == by_block.summary() == want
    assert 0 < len(want) < len([t for t in topics if t.fields])  # NaN and inf leave some out
    assert PeakTracker(topics).summary() == {}
