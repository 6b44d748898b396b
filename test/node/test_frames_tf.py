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

"""Tests of the static TF frames (ttb_sim.node.frames_tf): names, positions, the message."""

from __future__ import annotations

import re

import pytest
from ttb_sim.config import load_scenario
from ttb_sim.io.cdr import typestore
from ttb_sim.io.topics import topic_table
from ttb_sim.node.frames_tf import static_frames, tf_message
from ttb_sim.node.markers import model_markers, pile_group_markers
from ttb_sim.sim import Layout

FRAME_ID = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')   # a TF frame id: no '/', no leading digit


@pytest.fixture(scope='module')
def coupled():
    return load_scenario('paper_ttbcpsi')


@pytest.fixture(scope='module')
def coupled_layout(coupled):
    return Layout(n_spans=10, n_supports=11, n_bodies=4, n_axles=4,
                  piles=((7, 15), (8, 15)), soil_points=50, piers=(7, 8))


def test_frames_are_rooted_at_track_with_valid_unique_names(coupled, coupled_layout):
    frames = static_frames(coupled, coupled_layout)
    names = [f.child for f in frames]
    assert len(names) == len(set(names)) == 10 + 11 + 30
    assert all(FRAME_ID.match(n) for n in names), names
    assert {f.parent for f in frames} == {'track'}
    assert names[:2] == ['span01', 'span02'] and 'pier11' in names
    assert names[-1] == 'pier08_pile15' and 'pier07_pile01' in names
    assert 'track' not in names


def test_every_sensor_topic_has_its_frame(coupled, coupled_layout):
    names = {f.child for f in static_frames(coupled, coupled_layout)}
    for topic in topic_table(coupled_layout):
        parts = topic.name.split('/')
        if parts[0] == 'bridge':
            assert parts[1] in names
        elif parts[0] in ('bearings', 'piers'):
            assert parts[1] in names
        elif parts[0] == 'piles':
            assert f'{parts[1]}_{parts[2]}' in names


def test_positions_are_the_markers(coupled, coupled_layout):
    frames = {f.child: f.translation for f in static_frames(coupled, coupled_layout)}
    length = coupled.bridge.span_length
    assert frames['span01'] == pytest.approx((0.5 * length, 0.0, 0.0))
    assert frames['span10'] == pytest.approx((9.5 * length, 0.0, 0.0))
    boxes = model_markers(coupled)
    girder = next(b for b in boxes if b.ns == 'girders')
    for s in (0, 3, 10):
        assert frames[f'pier{s + 1:02d}'] == pytest.approx((s * length, 0.0, -girder.size[2]))
    piles = [b for b in boxes if b.ns == 'piles' and 600 <= b.marker_id < 700]  # pier07
    assert len(piles) == 15
    for m, box in enumerate(piles):   # the head is the top of the pile's box
        x, y, z = frames[f'pier07_pile{m + 1:02d}']
        assert (x, y) == pytest.approx(box.position[:2])
        assert z == pytest.approx(box.position[2] + box.size[2] / 2)


def test_a_substructure_alone_has_its_pile_heads_on_the_ground():
    single = load_scenario('single_pile')
    layout = Layout(n_spans=0, n_supports=0, n_bodies=0, piles=((1, len(
        single.piles.centres())),), train=False)
    frames = static_frames(single, layout)
    assert [f.child for f in frames][0] == 'pier01_pile01'
    box = next(b for b in pile_group_markers(single) if b.ns == 'piles')
    assert frames[0].translation == pytest.approx(
        (box.position[0], box.position[1], box.position[2] + box.size[2] / 2))


def test_tf_message_serialises(coupled, coupled_layout):
    store = typestore()
    frames = static_frames(coupled, coupled_layout)
    msg = tf_message(store.types.__getitem__, frames)
    assert len(msg.transforms) == len(frames)
    first = msg.transforms[0]
    assert first.header.frame_id == 'track' and first.child_frame_id == 'span01'
    assert first.transform.rotation.w == 1.0
    data = bytes(store.serialize_cdr(msg, 'tf2_msgs/msg/TFMessage'))
    back = store.deserialize_cdr(data, 'tf2_msgs/msg/TFMessage')
    assert back.transforms[-1].child_frame_id == 'pier08_pile15'
