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
The RViz / Foxglove markers of ``~/model/markers``, described as plain data.

:func:`model_markers` gives one :class:`Box` per girder, pier and abutment (or,
for a pile-soil substructure run, per pile plus the soil block and the cap),
:func:`train_markers` the car bodies and axles at a head position, and
:func:`markers` the complete :class:`MarkerSet` that the node sends latched;
:func:`marker_array` copies a set into a ``visualization_msgs/msg/MarkerArray`` of
the message classes it is given (rclpy's in the node).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ttb_sim.config import Scenario
from ttb_sim.io.topics import FRAME_ID, MessageTypes


@dataclass(frozen=True)
class Box:
    """
    An axis-aligned box marker in the track frame.

    Attributes
    ----------
    ns : str
        Marker namespace ('girders', 'piers', 'abutments', 'train', 'axles', 'piles',
        'cap', 'soil').
    marker_id : int
        Id, unique within the namespace.
    position : tuple of float
        Centre (x, y, z) in metres.
    size : tuple of float
        Edge lengths (x, y, z) in metres.
    color : tuple of float
        (r, g, b, a), each in [0, 1].

    """

    ns: str
    marker_id: int
    position: tuple[float, float, float]
    size: tuple[float, float, float]
    color: tuple[float, float, float, float]


@dataclass(frozen=True)
class MarkerSet:
    """All markers of one ``~/model/markers`` message, in the frame ``frame_id``."""

    boxes: tuple[Box, ...]
    frame_id: str = FRAME_ID


GIRDER_COLOR = (0.62, 0.62, 0.66, 1.0)
PIER_COLOR = (0.45, 0.45, 0.50, 1.0)
ABUTMENT_COLOR = (0.35, 0.35, 0.38, 1.0)
CAR_COLOR = (0.85, 0.85, 0.95, 0.9)
AXLE_COLOR = (0.9, 0.2, 0.15, 1.0)
PILE_COLOR = (0.55, 0.55, 0.60, 1.0)
CAP_COLOR = (0.50, 0.50, 0.55, 1.0)
SOIL_COLOR = (0.55, 0.42, 0.28, 0.25)


def girder_depth(scenario: Scenario) -> float:
    """Return a drawing depth of the girder (m): span/12, at least 0.5 m (display only)."""
    return max(scenario.bridge.span_length / 12.0, 0.5)


def _group_origin(scenario: Scenario,
                  origin: tuple[float, float, float] | None) -> tuple[float, float, float]:
    """Return the offset of a pile group's own axes: the ground under the pier base."""
    piles, cap = scenario.piles, scenario.cap
    if origin is None:
        return 0.0, 0.0, 0.0
    # the pier stands on the group centre, the cap on the ground
    return origin[0] - piles.centre[0], origin[1] - piles.centre[1], origin[2] - cap.thickness


def pier_base(scenario: Scenario, pier: int) -> tuple[float, float, float]:
    """Return the base of a piled pier (the cap top) in the track frame; ``pier`` 1-based."""
    return ((pier - 1) * scenario.bridge.span_length, 0.0, -scenario.piers.height)


def pile_heads(scenario: Scenario, pier: int | None) -> list[tuple[float, float, float]]:
    """
    Return the pile-head positions of a pile group, in pile-number order.

    Parameters
    ----------
    scenario : Scenario
        The scenario.
    pier : int or None
        The piled pier (1-based support number; the group under its base), or None
        for a pile-soil substructure alone (its own axes, ground surface z = 0).

    """
    ox, oy, oz = _group_origin(scenario, None if pier is None else pier_base(scenario, pier))
    return [(ox + x, oy + y, oz) for x, y in scenario.piles.centres()]


def model_markers(scenario: Scenario) -> list[Box]:
    """
    Describe the static structure: one box per girder, pier and abutment.

    The deck top is at z = 0; widths and depths are display values (the beam
    model has no cross-section geometry beyond its stiffness and mass).

    Parameters
    ----------
    scenario : Scenario
        The scenario.

    Returns
    -------
    list of Box

    """
    if scenario.substructure_only:
        return pile_group_markers(scenario)
    b = scenario.bridge
    depth = girder_depth(scenario)
    width = scenario.bearings.spacing + 2.0
    gap = min(0.1, 0.01 * b.span_length)
    boxes = [Box('girders', k, ((k + 0.5) * b.span_length, 0.0, -depth / 2),
                 (b.span_length - gap, width, depth), GIRDER_COLOR)
             for k in range(b.n_spans)]
    height = scenario.piers.height
    for s in range(b.n_spans + 1):
        x = s * b.span_length
        if s in (0, b.n_spans):
            boxes.append(Box('abutments', s, (x, 0.0, -depth - 1.5), (2.0, width + 1.0, 3.0),
                             ABUTMENT_COLOR))
        elif s + 1 in scenario.foundation.piled_piers:
            # as modelled: the column from the bearings (z = 0) down to the cap
            column = max(height - depth, 0.1)
            boxes.append(Box('piers', s, (x, 0.0, -depth - column / 2),
                             (2.0, 0.6 * width, column), PIER_COLOR))
            boxes.extend(pile_group_markers(scenario, origin=pier_base(scenario, s + 1),
                                            first_id=100 * s))
        else:
            boxes.append(Box('piers', s, (x, 0.0, -depth - height / 2),
                             (2.0, 0.6 * width, height), PIER_COLOR))
    return boxes


def pile_group_markers(scenario: Scenario, origin: tuple[float, float, float] | None = None,
                       first_id: int = 0) -> list[Box]:
    """
    Describe a pile-soil substructure: one box per pile, the cap if modelled, the soil block.

    Alone (``origin`` None) the positions are in the substructure's own axes
    (ground surface z = 0, block centred on the origin). Under a piled pier,
    ``origin`` is the pier base (the cap top): the group is centred under it
    and the ground is a cap thickness lower. Circular piles are drawn as their
    equal-area squares; ids start at ``first_id``.
    """
    piles, soil, cap = scenario.piles, scenario.soil, scenario.cap
    ox, oy, oz = _group_origin(scenario, origin)
    w = piles.width
    boxes = [Box('piles', first_id + i, (ox + x, oy + y, oz - piles.length / 2),
                 (w, w, piles.length), PILE_COLOR)
             for i, (x, y) in enumerate(piles.centres())]
    if cap.enabled:
        cx, cy = piles.centre
        boxes.append(Box('cap', first_id, (ox + cx, oy + cy, oz + cap.thickness / 2),
                         (cap.lx, cap.ly, cap.thickness), CAP_COLOR))
    boxes.append(Box('soil', first_id, (ox, oy, oz - soil.depth / 2),
                     (soil.block.lx, soil.block.ly, soil.depth), SOIL_COLOR))
    return boxes


def train_markers(scenario: Scenario, head_position: float) -> list[Box]:
    """
    Describe the train at a head position: car bodies and one small box per axle.

    Parameters
    ----------
    scenario : Scenario
        The scenario (train layout).
    head_position : float
        Position of the train head along the track (m).

    Returns
    -------
    list of Box

    """
    if scenario.substructure_only:
        return []
    t = scenario.train
    offsets = scenario.axle_positions()
    boxes = [Box('axles', i, (head_position - a, 0.0, 0.5), (1.0, 1.5, 1.0), AXLE_COLOR)
             for i, a in enumerate(offsets)]
    if not t.axle_offsets:
        for c in range(t.n_cars):
            x = head_position - (c + 0.5) * t.car_length
            boxes.append(Box('train', c, (x, 0.0, 2.4), (t.car_length - 0.6, 3.2, 3.6),
                             CAR_COLOR))
    return boxes


def markers(scenario: Scenario, head_position: float) -> MarkerSet:
    """Return the complete marker set: structure and train (sent latched as a whole)."""
    return MarkerSet(tuple(model_markers(scenario) + train_markers(scenario, head_position)))


def marker_array(types: MessageTypes, marker_set: MarkerSet) -> Any:
    """
    Copy a plain marker description into a ``visualization_msgs/msg/MarkerArray``.

    Parameters
    ----------
    types : callable
        Maps a ROS type name to its message class (rclpy's, whose fields have defaults).
    marker_set : MarkerSet
        Boxes in the track frame.

    Returns
    -------
    MarkerArray
        One CUBE marker per box, stamp zero (latest transform), never expiring.

    """
    marker = types('visualization_msgs/msg/Marker')
    point, pose = types('geometry_msgs/msg/Point'), types('geometry_msgs/msg/Pose')
    quaternion, vector3 = types('geometry_msgs/msg/Quaternion'), types('geometry_msgs/msg/Vector3')
    color_rgba = types('std_msgs/msg/ColorRGBA')
    stamp = types('builtin_interfaces/msg/Time')(sec=0, nanosec=0)
    header = types('std_msgs/msg/Header')(stamp=stamp, frame_id=marker_set.frame_id or FRAME_ID)
    out = []
    for box in marker_set.boxes:
        x, y, z = (float(v) for v in box.position)
        sx, sy, sz = (float(v) for v in box.size)
        r, g, b, a = (float(v) for v in box.color)
        out.append(marker(header=header, ns=box.ns, id=box.marker_id, type=marker.CUBE,
                          action=marker.ADD,
                          pose=pose(position=point(x=x, y=y, z=z),
                                    orientation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
                          scale=vector3(x=sx, y=sy, z=sz),
                          color=color_rgba(r=r, g=g, b=b, a=a), frame_locked=False))
    return types('visualization_msgs/msg/MarkerArray')(markers=out)
