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
Tests of the publishing thread: order, bounded backlog, counted drops, clean stop.

A publish function that blocks on an event stands for a slow middleware, so the
counts are exact whatever the machine's load: the offering side never waits, the
backlog keeps the newest ``max_backlog`` frames and every other frame is counted
as dropped. Waits are bounded (hang guards), never timing assertions.
"""

from __future__ import annotations

import functools
import threading
from typing import Any, Sequence

import pytest
from ttb_sim.node.publishing import PublishLoop
from polling import poll_until  # noqa: I100 - the helper in test/

TIMEOUT = 30.0


wait_for = functools.partial(poll_until, timeout=TIMEOUT, interval=0.005)


class SlowSink:
    """Records published batches; the first call blocks until released."""

    def __init__(self) -> None:
        self.batches: list[list[Any]] = []
        self.markers = 0
        self.entered = threading.Event()
        self.release = threading.Event()

    def __call__(self, frames: Sequence[Any], markers: bool) -> None:
        self.entered.set()
        assert self.release.wait(TIMEOUT)
        self.batches.append(list(frames))
        self.markers += int(markers)


def test_a_slow_publisher_drops_the_oldest_and_never_blocks_the_offer() -> None:
    sink = SlowSink()
    loop = PublishLoop(sink, duty=1.0, max_backlog=10)
    loop.start()
    try:
        loop.offer([0])
        assert sink.entered.wait(TIMEOUT)          # frame 0 is being published
        loop.offer(list(range(1, 101)), markers=True)   # returns at once: nothing blocks
        stats = loop.stats()
        assert stats.offered == 101 and stats.dropped == 90
        sink.release.set()
        wait_for(lambda: loop.stats().published == 11)
    finally:
        loop.stop()
    published = [f for batch in sink.batches for f in batch]
    assert published == [0] + list(range(91, 101))   # in order, the newest kept
    assert sink.markers == 1
    assert loop.stats().ms_per_frame > 0


def test_publishing_errors_end_the_loop_with_a_message() -> None:
    def broken(frames: Sequence[Any], markers: bool) -> None:
        raise RuntimeError('publisher context is invalid')

    loop = PublishLoop(broken, duty=0.5)
    loop.start()
    loop.offer([1])
    wait_for(lambda: loop.error)
    assert 'publisher context is invalid' in loop.error
    loop.stop()


def test_stop_ends_an_idle_loop_and_offers_after_it_are_harmless() -> None:
    sink = SlowSink()
    sink.release.set()
    loop = PublishLoop(sink, duty=0.4)
    loop.start()
    loop.stop()
    loop.offer([1, 2])
    assert not sink.batches


def test_duty_outside_its_range_is_refused() -> None:
    with pytest.raises(ValueError, match='duty'):
        PublishLoop(lambda frames, markers: None, duty=0.0)


class FakeClocks:
    """A CPU clock that each publish call advances by ``cost``, and a wall clock set by hand."""

    def __init__(self, cost: float) -> None:
        self.cost = cost
        self.cpu = 0.0
        self.wall = 0.0
        self.batches: list[list[Any]] = []

    def publish(self, frames: Sequence[Any], markers: bool) -> None:
        self.batches.append(list(frames))
        self.cpu += self.cost


def test_inline_publishing_runs_on_the_caller_in_order() -> None:
    """Without a thread, each offer publishes its frames at once, as one batch."""
    caller = threading.get_ident()
    seen: list[int] = []

    def publish(frames: Sequence[Any], markers: bool) -> None:
        seen.append(threading.get_ident())
        batches.append(list(frames))

    batches: list[list[Any]] = []
    loop = PublishLoop(publish, duty=1.0, threaded=False)
    loop.start()
    for k in range(5):
        loop.offer([2 * k, 2 * k + 1])
    assert batches == [[0, 1], [2, 3], [4, 5], [6, 7], [8, 9]]
    assert set(seen) == {caller}
    assert loop.stats().published == 10 and loop.stats().dropped == 0


def test_inline_publishing_rests_within_its_duty_and_counts_drops() -> None:
    """
    A batch costing s of CPU makes the loop rest s (1 - duty) / duty of wall time.

    Duty 0.25 and 10 ms per batch: 30 ms of rest. Frames offered meanwhile wait
    (the newest ``max_backlog``) and go out with the first offer after the rest.
    """
    clocks = FakeClocks(cost=0.010)
    loop = PublishLoop(clocks.publish, duty=0.25, max_backlog=3, threaded=False,
                       clock=lambda: clocks.cpu, wall=lambda: clocks.wall)
    loop.offer([0])                       # published at t = 0: rest until 30 ms
    for k in range(1, 6):                 # t = 5 ... 25 ms: resting, frames wait
        clocks.wall = 0.005 * k
        loop.offer([k])
    assert clocks.batches == [[0]]
    clocks.wall = 0.030
    loop.offer([])                        # the rest is over: the waiting frames go out
    assert clocks.batches == [[0], [3, 4, 5]]
    stats = loop.stats()
    assert (stats.offered, stats.published, stats.dropped) == (6, 4, 2)
    assert stats.busy == pytest.approx(0.020)


def test_inline_publishing_errors_stop_publishing_without_raising() -> None:
    calls: list[int] = []

    def broken(frames: Sequence[Any], markers: bool) -> None:
        calls.append(len(frames))
        raise RuntimeError('publisher context is invalid')

    loop = PublishLoop(broken, duty=0.5, threaded=False)
    loop.offer([1, 2])                    # the stepping thread is never hit by the error
    loop.offer([3])
    assert calls == [2]
    assert 'publisher context is invalid' in loop.error
    loop.stop()
    loop.offer([4])
    assert calls == [2]
