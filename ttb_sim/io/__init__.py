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
bags), ``bag`` records frames to rosbag2 (MCAP or SQLite 3), ``reader`` reads any
bag of ours back into numpy arrays per topic (``bag_checks`` says in one line what
is wrong with a bag it cannot read), ``streams`` sorts those arrays into named,
evenly sampled streams (car bodies, wheel-rail forces, girders, piles, soil) for
the reports.
"""

from ttb_sim.io.bag import BagRecorder, default_bag_path, STORAGES
from ttb_sim.io.reader import bag_topics, read_bag, TopicArrays
from ttb_sim.io.streams import load_streams, Series, Streams
from ttb_sim.io.topics import FRAME_ID, NAMESPACE, PeakTracker, Topic, topic_table

__all__ = ['bag_topics', 'BagRecorder', 'default_bag_path', 'FRAME_ID', 'load_streams',
           'NAMESPACE', 'PeakTracker', 'read_bag', 'Series', 'STORAGES', 'Streams', 'Topic',
           'topic_table', 'TopicArrays']
