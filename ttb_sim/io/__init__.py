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
Input and output: the topic table, the rosbag2 recorder, the bag reader and the bag's streams.

``topics`` maps frames to standard ROS 2 messages (one table for the node and the
bags), ``bag`` records frames to rosbag2 (MCAP or SQLite 3) a block of frames at a
time, with the CDR layouts ``codec`` learns from the table's builders and the
block storages of ``block_storage`` under rosbags' writer; ``reader`` reads any
bag of ours back into numpy arrays per topic (``bag_checks`` says in one line what
is wrong with a bag it cannot read), ``streams`` sorts those arrays into named,
evenly sampled streams (car bodies, wheel-rail forces, girders, piles, soil) for
the reports.

The names below are imported when first used (PEP 562): ``topics`` and ``bag``
need the stepping core (``ttb_sim.sim``, over a second to import), which a
verb that only reads bags, or refuses its arguments, should not wait for.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ttb_sim.lazy_face import lazy_face

if TYPE_CHECKING:
    from ttb_sim.io.bag import BagRecorder, default_bag_path, STORAGES
    from ttb_sim.io.reader import bag_topics, read_bag, TopicArrays
    from ttb_sim.io.streams import load_streams, Series, Streams
    from ttb_sim.io.topics import FRAME_ID, NAMESPACE, PeakTracker, Topic, topic_table

_FACE = {
    'ttb_sim.io.bag': ('BagRecorder', 'default_bag_path', 'STORAGES'),
    'ttb_sim.io.reader': ('bag_topics', 'read_bag', 'TopicArrays'),
    'ttb_sim.io.streams': ('load_streams', 'Series', 'Streams'),
    'ttb_sim.io.topics': ('FRAME_ID', 'NAMESPACE', 'PeakTracker', 'Topic', 'topic_table'),
}

__all__ = ['bag_topics', 'BagRecorder', 'default_bag_path', 'FRAME_ID', 'load_streams',
           'NAMESPACE', 'PeakTracker', 'read_bag', 'Series', 'STORAGES', 'Streams', 'Topic',
           'topic_table', 'TopicArrays']

__getattr__, __dir__ = lazy_face(__name__, _FACE)
