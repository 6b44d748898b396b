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
The static TF frames of the model (``/tf_static``), described as plain data.

REP 105 / REP 103: the root is the track frame ``track`` (x along the track from the
start of the modelled line, y to the left, z up; the frame of every topic), and each
sensor place of the structure is a child of it, translated, not rotated:

- ``spanNN`` at each girder's mid-span on the deck (z = 0), where
  ``~/bridge/spanNN/midspan`` is measured;
- ``pierNN`` at each support's top, under the bearings of ``~/bearings/pierNN/...``
  (support 1 and the last are the abutments, as in the topic names);
- ``pierNN_pileMM`` at each pile head of a piled pier (``~/piles/pierNN/pileMM/...``;
  ``/`` is not used in a frame id, so the pier and the pile are joined by ``_``).

Positions are those of the RViz markers (:mod:`ttb_sim.node.markers`), so frames and
boxes agree: the girder depth and pier tops are the markers' display values (the beam
model has no cross-section geometry). The soil cloud (``~/soil/points``) is given in
``track`` itself, so it needs no frame of its own; the cars move, so their frames
would be dynamic (``/tf``) and are left out. :func:`tf_message` copies the frames
into a ``tf2_msgs/msg/TFMessage`` of the message classes it is given.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ttb_sim.config import Scenario
from ttb_sim.io.topics import FRAME_ID, MessageTypes
from ttb_sim.node.markers import girder_depth, pile_heads
from ttb_sim.sim import Layout

__all__ = ['static_frames', 'StaticFrame', 'tf_message']


@dataclass(frozen=True)
class StaticFrame:
    """
    One static transform: a child frame translated from its parent (no rotation).

    Attributes
    ----------
    child : str
        Child frame id (``span01``, ``pier07``, ``pier07_pile01``).
    parent : str
        Parent frame id (``track``).
    translation : tuple of float
        The child's origin in the parent frame (x, y, z), metres.

    """

    child: str
    parent: str
    translation: tuple[float, float, float]


def static_frames(scenario: Scenario, layout: Layout) -> list[StaticFrame]:
    """
    Return the static frames of a model: spans, pier tops and pile heads under ``track``.

    Parameters
    ----------
    scenario : Scenario
        The scenario (geometry).
    layout : Layout
        The model's output sizes (which piers have piles, and how many).

    Returns
    -------
    list of StaticFrame
        In topic order: spans, piers, pile heads.

    """
    out: list[StaticFrame] = []
    length = scenario.bridge.span_length
    for k in range(layout.n_spans):
        out.append(StaticFrame(f'span{k + 1:02d}', FRAME_ID, ((k + 0.5) * length, 0.0, 0.0)))
    depth = girder_depth(scenario)
    for s in range(layout.n_supports):
        out.append(StaticFrame(f'pier{s + 1:02d}', FRAME_ID, (s * length, 0.0, -depth)))
    for pier, n_piles in layout.piles:
        heads = pile_heads(scenario, None if scenario.substructure_only else pier)
        for m, head in enumerate(heads[:n_piles]):
            out.append(StaticFrame(f'pier{pier:02d}_pile{m + 1:02d}', FRAME_ID, head))
    return out


def tf_message(types: MessageTypes, frames: list[StaticFrame]) -> Any:
    """
    Copy static frames into a ``tf2_msgs/msg/TFMessage`` (stamp 0: valid at all times).

    Parameters
    ----------
    types : callable
        Maps a ROS type name to its message class (rclpy's in the node).
    frames : list of StaticFrame
        The frames.

    """
    transform_stamped = types('geometry_msgs/msg/TransformStamped')
    transform, vector3 = types('geometry_msgs/msg/Transform'), types('geometry_msgs/msg/Vector3')
    quaternion, header = types('geometry_msgs/msg/Quaternion'), types('std_msgs/msg/Header')
    stamp = types('builtin_interfaces/msg/Time')(sec=0, nanosec=0)
    out = []
    for frame in frames:
        x, y, z = (float(v) for v in frame.translation)
        out.append(transform_stamped(
            header=header(stamp=stamp, frame_id=frame.parent), child_frame_id=frame.child,
            transform=transform(translation=vector3(x=x, y=y, z=z),
                                rotation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0))))
    return types('tf2_msgs/msg/TFMessage')(transforms=out)
