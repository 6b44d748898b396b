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

"""Tests of the structure and train markers (plain boxes for ~/model/markers)."""

from types import SimpleNamespace

import pytest
from ttb_sim.config import load_scenario
from ttb_sim.node.markers import marker_array, markers, model_markers, train_markers


def test_markers_describe_girders_supports_and_train():
    scenario = load_scenario('moving_force_beam', ['bridge.n_spans=3', 'train.axle_offsets=[]',
                                                   'train.n_cars=2'])
    boxes = model_markers(scenario)
    ns = [b.ns for b in boxes]
    assert ns.count('girders') == 3 and ns.count('piers') == 2 and ns.count('abutments') == 2
    girder = next(b for b in boxes if b.ns == 'girders' and b.marker_id == 1)
    assert girder.position[0] == pytest.approx(1.5 * 32.0)
    train = train_markers(scenario, 100.0)
    cars = [b for b in train if b.ns == 'train']
    axles = [b for b in train if b.ns == 'axles']
    assert len(cars) == 2 and len(axles) == 8
    assert cars[0].position[0] == pytest.approx(100.0 - 12.5)
    assert all(0 <= v <= 1 for b in boxes + train for v in b.color)
    full = markers(scenario, 100.0)
    assert full.frame_id == 'track' and len(full.boxes) == len(boxes) + len(train)
    ids = [(b.ns, b.marker_id) for b in full.boxes]
    assert len(ids) == len(set(ids))


def test_a_pile_group_is_drawn_instead_of_the_bridge():
    scenario = load_scenario('pile_harmonic', ['cap.enabled=true'])
    full = markers(scenario, 0.0)
    piles = [b for b in full.boxes if b.ns == 'piles']
    assert len(piles) == 15 and not [b for b in full.boxes if b.ns in ('girders', 'train')]
    first, fifth = piles[0], piles[4]
    assert first.position[:2] == pytest.approx((-6.0, -3.0))  # smallest x and y first
    assert fifth.position[:2] == pytest.approx((6.0, -3.0))   # x runs fastest
    assert first.size == pytest.approx((0.886227, 0.886227, 12.0), rel=1e-5)
    (soil,) = [b for b in full.boxes if b.ns == 'soil']
    assert soil.size == pytest.approx((36.0, 30.0, 22.0)) and soil.position[2] == -11.0
    assert [b.ns for b in full.boxes].count('cap') == 1


def test_piled_piers_stand_on_their_pile_groups():
    scenario = load_scenario('paper_ttbcpsi')
    boxes = model_markers(scenario)
    piles = [b for b in boxes if b.ns == 'piles']
    caps = [b for b in boxes if b.ns == 'cap']
    soils = [b for b in boxes if b.ns == 'soil']
    assert len(piles) == 30 and len(caps) == 2 and len(soils) == 2
    ids = [(b.ns, b.marker_id) for b in boxes]
    assert len(ids) == len(set(ids))
    height, cap = scenario.piers.height, scenario.cap.thickness
    for support, cap_box in zip((7, 8), caps):
        x = (support - 1) * scenario.bridge.span_length
        # the cap top carries the pier base (z = -height), centred under the pier
        assert cap_box.position == pytest.approx((x, 0.0, -height - cap / 2))
        group = [b for b in piles if abs(b.position[0] - x) < 10.0]
        assert len(group) == 15
        assert max(b.position[2] + b.size[2] / 2 for b in group) == pytest.approx(-height - cap)
    assert [b.ns for b in boxes].count('piers') == 9


def _message_types(name):
    """Message classes with default fields, as rclpy's (plain namespaces here)."""
    cls = type(name.rsplit('/', 1)[1], (SimpleNamespace,), {'CUBE': 1, 'ADD': 0})
    cls.type_name = name
    return cls


def test_marker_array_has_one_cube_per_box():
    scenario = load_scenario('moving_force_beam', ['bridge.n_spans=3'])
    full = markers(scenario, 100.0)
    array = marker_array(_message_types, full)
    assert array.type_name == 'visualization_msgs/msg/MarkerArray'
    assert len(array.markers) == len(full.boxes)
    for box, marker in zip(full.boxes, array.markers):
        assert (marker.ns, marker.id, marker.type, marker.action) == (box.ns, box.marker_id, 1, 0)
        assert marker.header.frame_id == 'track' and marker.header.stamp.sec == 0
        position, scale, color = marker.pose.position, marker.scale, marker.color
        assert (position.x, position.y, position.z) == box.position
        assert (scale.x, scale.y, scale.z) == box.size
        assert (color.r, color.g, color.b, color.a) == box.color
        assert marker.pose.orientation.w == 1.0 and marker.frame_locked is False
