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
Live messages built once per topic and updated in place, frame after frame.

Building the messages of a frame from scratch (:meth:`ttb_sim.io.topics.Topic.message`:
a header, a time, vectors, covariance arrays per message) was most of the
node's publishing cost. :class:`MessageCache` builds each topic's message once
from the first frame and afterwards writes only what changes: the stamp, once
per frame in one :class:`std_msgs/msg/Header` that all stamped messages share,
and the numbers of each topic, all gathered from the frame's flat row
(:attr:`~ttb_sim.sim.Frame.row`) with one index. A publisher serialises the
message when it is published, so handing the same object out again for the
next frame is safe.

It works with any message classes of the standard field names (rclpy's or
rosbags'), so it is tested without ROS: every message it hands out serialises
to the bytes of a freshly built one (``test/test_node_message_cache.py``).
Topics of other types (``sensor_msgs/msg/PointCloud2``, ``/clock``) are
built from scratch every frame.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.io.topics import MessageTypes, Topic
from ttb_sim.node.rates import family_of
from ttb_sim.sim import Frame

Updater = Callable[[list[float]], None]
"""Writes a topic's values (as Python floats) into its message."""


def _vector_updater(vector: Any) -> Updater:
    def update(values: list[float]) -> None:
        vector.x, vector.y, vector.z = values[0], values[1], values[2]
    return update


def _pair_updater(first: Any, second: Any) -> Updater:
    def update(values: list[float]) -> None:
        first.x, first.y, first.z = values[0], values[1], values[2]
        second.x, second.y, second.z = values[3], values[4], values[5]
    return update


def _odometry_updater(position: Any, linear: Any) -> Updater:
    def update(values: list[float]) -> None:
        position.x = values[0]
        linear.x = values[1]
    return update


def _updater(msgtype: str, msg: Any) -> Updater | None:
    """Return the in-place updater of a message type (None: rebuild every frame)."""
    if msgtype == 'geometry_msgs/msg/Vector3Stamped':
        return _vector_updater(msg.vector)
    if msgtype == 'geometry_msgs/msg/WrenchStamped':
        return _pair_updater(msg.wrench.force, msg.wrench.torque)
    if msgtype == 'sensor_msgs/msg/Imu':
        return _pair_updater(msg.linear_acceleration, msg.angular_velocity)
    if msgtype == 'nav_msgs/msg/Odometry':
        return _odometry_updater(msg.pose.pose.position, msg.twist.twist.linear)
    return None


class MessageCache:
    """
    Each topic's message for a frame, updated in place instead of rebuilt.

    Parameters
    ----------
    topics : sequence of Topic
        The topics, in publishing order.
    types : callable
        Maps a ROS type name to its message class.

    """

    def __init__(self, topics: Sequence[Topic], types: MessageTypes) -> None:
        self.topics = list(topics)
        self._types = types
        self._header: Any = None
        self._entries: list[tuple[Topic, Any, Updater | None]] = []
        self._index = np.concatenate([t.index for t in self.topics] or [np.zeros(0, np.intp)])
        ends = np.cumsum([len(t.columns) for t in self.topics], dtype=int).tolist()
        self._spans = list(zip([0, *ends[:-1]], ends))
        self._families = [family_of(t.name) for t in self.topics]
        self._selections: dict[frozenset[str], list[int]] = {}

    def _build(self, frame: Frame) -> None:
        self._header = self._types('std_msgs/msg/Header')(
            stamp=self._types('builtin_interfaces/msg/Time')(sec=0, nanosec=0),
            frame_id='')
        for topic in self.topics:
            msg = topic.message(self._types, frame)
            update = _updater(topic.msgtype, msg)
            if update is not None:
                self._header.frame_id = msg.header.frame_id
                msg.header = self._header   # one stamp for the whole frame
            self._entries.append((topic, msg, update))

    def messages(self, frame: Frame) -> list[Any]:
        """
        Return every topic's message for ``frame``, in topic order.

        The objects are the same from one call to the next: publish (or
        serialise) them before the next call.
        """
        if not self._entries:
            self._build(frame)
        sec, nanosec = divmod(int(frame.stamp_ns), 1_000_000_000)
        stamp = self._header.stamp
        stamp.sec, stamp.nanosec = sec, nanosec
        values = frame.row[self._index].tolist()   # every topic's values, as Python floats
        out = []
        for (topic, msg, update), (start, end) in zip(self._entries, self._spans):
            if update is None:
                msg = topic.message(self._types, frame)
            else:
                update(values[start:end])
            out.append(msg)
        return out

    def due_messages(self, frame: Frame, due: frozenset[str]) -> list[tuple[int, Any]]:
        """
        Return ``(topic index, message)`` of the topics whose family is due in ``frame``.

        Only those messages are updated (the others keep their previous frame's
        values); the same objects come back on the next call, as with :meth:`messages`.
        """
        if not self._entries:
            self._build(frame)
        selection = self._selections.get(due)
        if selection is None:
            selection = [i for i, f in enumerate(self._families) if f in due]
            self._selections[due] = selection
        sec, nanosec = divmod(int(frame.stamp_ns), 1_000_000_000)
        stamp = self._header.stamp
        stamp.sec, stamp.nanosec = sec, nanosec
        values = frame.row[self._index].tolist()
        out = []
        for i in selection:
            topic, msg, update = self._entries[i]
            if update is None:
                msg = topic.message(self._types, frame)
            else:
                start, end = self._spans[i]
                update(values[start:end])
            out.append((i, msg))
        return out
