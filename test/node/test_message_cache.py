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
Messages updated in place (:class:`~ttb_sim.node.message_cache.MessageCache`) equal fresh ones.

Checked byte for byte through an independent serialiser (rosbags' CDR): for
every topic of the node's default scenario (odometry, car-body IMU, wheel-rail
wrenches, mid-span vectors, bearings), over frames whose values change.
"""

from __future__ import annotations

import itertools

from ttb_sim.config import load_scenario
from ttb_sim.io.cdr import typestore
from ttb_sim.io.topics import topic_table
from ttb_sim.node.message_cache import MessageCache
from ttb_sim.sim import make_runner


def test_cached_messages_serialise_like_fresh_ones():
    """Every message of every frame has the bytes of one built from scratch."""
    sim = make_runner(load_scenario('live_train'))
    frames = list(itertools.islice(sim.frames(), 40))
    store = typestore()
    types = store.types.__getitem__
    topics = [t for t in topic_table(sim.layout) if t.qos != 'clock']
    cache = MessageCache(topics, types)
    changed = set()
    previous: dict[str, bytes] = {}
    for frame in frames:
        for topic, msg in zip(topics, cache.messages(frame)):
            got = bytes(store.serialize_cdr(msg, topic.msgtype))
            want = bytes(store.serialize_cdr(topic.message(types, frame), topic.msgtype))
            assert got == want, (topic.name, frame.step)
            if previous.get(topic.name, got) != got:
                changed.add(topic.msgtype)
            previous[topic.name] = got
    # The values and stamps do change from frame to frame for every message type.
    assert changed == {t.msgtype for t in topics}
    assert len(changed) == 4
