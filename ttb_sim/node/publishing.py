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
Live publishing within a share of the processor, so that publishing never throttles stepping.

The stepping thread :meth:`PublishLoop.offer` s the frames due for publishing
and goes on at once; :class:`PublishLoop` turns them into messages on a thread
of its own. Python runs one thread at a time, so the loop also bounds its own
share of the processor (``duty``): after a batch that took ``s`` seconds of
this thread's CPU time it rests ``s (1 - duty) / duty``. CPU time, not wall
time: the time a batch waits for the interpreter lock while the stepping
thread runs is not publishing, and counting it throttled publishing for
nothing (measured: 6.9 ms of wall clock per frame of 81 messages that cost
2 ms of CPU, on a loaded machine). Frames that arrive faster than that are dropped,
oldest first, beyond ``max_backlog`` waiting frames, and counted: the
stepping keeps its pace, the subscribers get fewer frames, and
:meth:`PublishLoop.stats` says how many (``/diagnostics``).

With ``threaded=False`` the same budget applies without a thread: :meth:`offer`
publishes the waiting frames on the caller's thread (the stepping thread), in
one batch per call, unless the loop is resting. The node uses this mode: two
threads that both run Python hand the interpreter lock back and forth at every
call into C code (each solve, each publish), and on the two-core machine that
churn cost more CPU than the publishing itself (measured on ``live_train`` at
50 Hz: 0.53-0.64 s of CPU per simulated second with a publishing thread,
0.24 s with publishing on the stepping thread; the subscribers got 20-35 Hz
instead of the full 50 Hz).
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
import logging
import math
import threading
import time
from typing import Callable, Generic, Sequence, TypeVar

log = logging.getLogger(__name__)

Item = TypeVar('Item')
"""What is published: a frame, or a frame with the topic families due in it."""


@dataclass(frozen=True)
class PublishStats:
    """
    Counters of a :class:`PublishLoop`.

    Attributes
    ----------
    offered : int
        Frames handed to the loop.
    published : int
        Frames published.
    dropped : int
        Frames dropped because the loop could not keep up.
    busy : float
        Seconds spent publishing (by the loop's clock: CPU time by default).

    """

    offered: int
    published: int
    dropped: int
    busy: float

    @property
    def ms_per_frame(self) -> float:
        """Mean milliseconds (by the loop's clock) to publish one frame (0 before the first)."""
        return 1e3 * self.busy / self.published if self.published else 0.0


class PublishLoop(Generic[Item]):
    """
    Publish frames on a thread of its own, within a share of the processor.

    Parameters
    ----------
    publish : callable
        ``publish(frames, markers)`` sends the messages of some frames in order;
        ``markers`` asks for a refresh of the train markers. Exceptions end
        the loop (logged), never the process.
    duty : float
        Largest share of the processor the loop spends publishing (0 < duty <= 1).
    max_backlog : int
        Frames kept waiting at most; older ones are dropped.
    clock : callable
        Clock of a batch's cost in seconds, read on the publishing thread (default:
        that thread's CPU time).
    threaded : bool
        True: publish on a thread of the loop's own; False: publish on the
        thread that calls :meth:`offer`.
    wall : callable
        Wall clock in seconds (the rest between two batches).

    """

    def __init__(self, publish: Callable[[Sequence[Item], bool], None], *,
                 duty: float = 0.4, max_backlog: int = 50,
                 clock: Callable[[], float] = time.thread_time, threaded: bool = True,
                 wall: Callable[[], float] = time.monotonic) -> None:
        if not 0 < duty <= 1:
            raise ValueError(f'duty = {duty!r}: allowed (0, 1]')
        self._publish = publish
        self._duty = duty
        self._clock = clock
        self._frames: deque[Item] = deque()
        self._max_backlog = max_backlog
        self._markers = False
        self._cond = threading.Condition()
        self._stop = False
        self._offered = 0
        self._published = 0
        self._dropped = 0
        self._busy = 0.0
        self.error = ''
        self._threaded = threaded
        self._wall = wall
        self._resume_at = -math.inf
        self._thread = threading.Thread(target=self._run, name='ttb_sim-publisher', daemon=True)

    def start(self) -> None:
        """Start the publishing thread (nothing to start when not threaded)."""
        if self._threaded:
            self._thread.start()

    def offer(self, frames: Sequence[Item], markers: bool = False) -> None:
        """
        Queue frames for publishing (drops the oldest beyond the backlog).

        Threaded, it returns at once. Otherwise it publishes the waiting frames
        now, unless the loop rests after its previous batch (they wait for a
        later call) or has stopped.
        """
        if not self._threaded:
            self._offer_inline(frames, markers)
            return
        if not frames and not markers:
            return
        self._queue(frames, markers)

    def _queue(self, frames: Sequence[Item], markers: bool) -> None:
        with self._cond:
            self._frames.extend(frames)
            self._offered += len(frames)
            excess = len(self._frames) - self._max_backlog
            for _ in range(max(0, excess)):
                self._frames.popleft()
            self._dropped += max(0, excess)
            self._markers = self._markers or markers
            self._cond.notify()

    def _offer_inline(self, frames: Sequence[Item], markers: bool) -> None:
        if self._stop or self.error:
            return
        if frames or markers:
            self._queue(frames, markers)
        if self._wall() < self._resume_at:
            return
        batch = self._take(wait=False)
        if batch is None or not (batch[0] or batch[1]):
            return
        self._publish_batch(*batch)

    def stop(self, timeout: float = 2.0) -> None:
        """Stop the thread (frames still waiting are dropped) and wait for it."""
        with self._cond:
            self._stop = True
            self._cond.notify()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout)

    def stats(self) -> PublishStats:
        """Return the counters."""
        with self._cond:
            return PublishStats(self._offered, self._published, self._dropped, self._busy)

    def _take(self, wait: bool = True) -> tuple[list[Item], bool] | None:
        with self._cond:
            while wait and not self._stop and not self._frames and not self._markers:
                self._cond.wait(0.5)
            if self._stop:
                return None
            frames, markers = list(self._frames), self._markers
            self._frames.clear()
            self._markers = False
            return frames, markers

    def _rest(self, seconds: float) -> None:
        with self._cond:
            if not self._stop:
                self._cond.wait_for(lambda: self._stop, timeout=seconds)

    def _publish_batch(self, frames: list[Item], markers: bool) -> float | None:
        """Publish one batch; return its cost (None: it failed, publishing has ended)."""
        start = self._clock()
        try:
            self._publish(frames, markers)
        except Exception as exc:  # noqa: B902 - publishing ends, the node goes on
            self.error = f'publishing stopped: {type(exc).__name__}: {exc}'
            log.error(self.error)
            return None
        spent = self._clock() - start
        with self._cond:
            self._published += len(frames)
            self._busy += spent
        if self._duty < 1 and spent > 0:
            self._resume_at = self._wall() + spent * (1 - self._duty) / self._duty
        return spent

    def _run(self) -> None:
        while True:
            batch = self._take()
            if batch is None:
                return
            spent = self._publish_batch(*batch)
            if spent is None:
                return
            if self._duty < 1 and spent > 0:
                self._rest(spent * (1 - self._duty) / self._duty)
