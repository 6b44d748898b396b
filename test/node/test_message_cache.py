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


def _cache(n_frames: int):
    """Return live_train's first frames, the typestore, its types, the topics and a cache."""
    sim = make_runner(load_scenario('live_train'))
    frames = list(itertools.islice(sim.frames(), n_frames))
    store = typestore()
    types = store.types.__getitem__
    topics = [t for t in topic_table(sim.layout) if t.qos != 'clock']
    return frames, store, types, topics, MessageCache(topics, types)


def test_cached_messages_serialise_like_fresh_ones():
    """Every message of every frame has the bytes of one built from scratch."""
    frames, store, types, topics, cache = _cache(40)
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


def test_due_messages_are_those_of_the_due_families_and_fresh():
    """Only the due families' topics come back, each with the bytes of a fresh message."""
    frames, store, types, topics, cache = _cache(6)
    for k, frame in enumerate(frames):
        due = frozenset({'wheel_rail'} if k % 2 else {'wheel_rail', 'bridge'})
        got = cache.due_messages(frame, due)
        names = [topics[i].name for i, _ in got]
        assert names and all(n.split('/')[0] in due for n in names)
        assert {n.split('/')[0] for n in names} == due
        for i, msg in got:
            want = topics[i].message(types, frame)
            assert (bytes(store.serialize_cdr(msg, topics[i].msgtype))
                    == bytes(store.serialize_cdr(want, topics[i].msgtype)))
