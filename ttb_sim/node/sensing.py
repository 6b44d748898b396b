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
The virtual sensors and ground-truth labels of the live node's passages.

:class:`LiveSensing` keeps one :class:`~ttb_sim.io.sensor_stream.SensorStream` over the
passages of a node (built with the first, again only when the frame rate changes, so a
sensor's noise, filter state and clock run on across passages), takes each passage's
labels, and writes samples and labels to a recorder that takes messages; with the
labels, a recorder that has metadata (a bag) also gets the scenario of the passage
(:func:`~ttb_sim.io.passage.store_scenario`, as ``ttb-sim run`` stores it), so
``ttb-sim identify`` rebuilds the model from the node's bag. A writer
that fails hands its exception to the caller's ``on_error`` (recording stops; the
stepping does not).
"""

from __future__ import annotations

import logging
from typing import Callable

from ttb_sim.config import Scenario
from ttb_sim.io.passage import store_scenario
from ttb_sim.io.sensor_stream import MessageSink, MetadataSink, SensorSample, SensorStream
from ttb_sim.sim import Frame, Layout

__all__ = ['LiveSensing']

log = logging.getLogger(__name__)

OnError = Callable[[Exception], None]
"""Called with a writer's exception (the controller stops recording)."""


class LiveSensing:
    """The sensors and labels of a live node across its passages."""

    def __init__(self) -> None:
        self.stream: SensorStream | None = None
        """The sensors and labels (None until the first passage starts)."""
        self._rate = 0.0
        self.labels_due = False
        """True when the labels changed since they were last emitted."""
        self.scenario: Scenario | None = None
        """The scenario of the passage (as last relabelled)."""

    @property
    def samples_every_frame(self) -> bool:
        """Tell whether some sensor needs every frame (no frame stride then)."""
        return self.stream is not None and self.stream.samples_every_frame

    def start(self, scenario: Scenario, layout: Layout, dt: float, every: int) -> None:
        """Build the sensors for a passage (again if the frame rate changed); take its labels."""
        rate = 1.0 / (dt * every)
        if self.stream is None or abs(self._rate - rate) > 1e-9 * rate:
            if self.stream is not None:
                log.info('the frame rate changed to %g Hz: the sensors start afresh', rate)
            self.stream = SensorStream(scenario, layout, dt, every)
            self._rate = rate
        self.relabel(scenario)

    def relabel(self, scenario: Scenario) -> None:
        """Take the labels of ``scenario`` now; they are emitted with the next tick."""
        if self.stream is None:
            return
        self.stream.relabel(scenario)
        self.scenario = scenario
        self.labels_due = True

    def push(self, frame: Frame) -> list[SensorSample]:
        """Return the samples a frame completes (none without sensors)."""
        return self.stream.push(frame) if self.stream is not None else []

    def flush(self) -> list[SensorSample]:
        """Return the samples of the frames the sensors still keep."""
        return self.stream.flush() if self.stream is not None else []

    def record(self, sink: object, samples: list[SensorSample], on_error: OnError) -> None:
        """Write samples to ``sink`` if it takes messages."""
        stream = self.stream
        if not samples or stream is None or not stream.takes(sink):
            return
        assert isinstance(sink, MessageSink)
        try:
            stream.write(sink, samples)
        except Exception as exc:  # noqa: B902 - any writer failure stops recording only
            on_error(exc)

    def emit_labels(self, sink: object, stamp_ns: int, on_error: OnError) -> bool:
        """
        Write changed labels to ``sink`` (if it takes messages) at ``stamp_ns``.

        A sink with metadata also stores the passage's scenario (and the labels).

        Returns
        -------
        bool
            True when labels were due (the caller publishes them too).

        """
        stream = self.stream
        if not self.labels_due or stream is None:
            return False
        self.labels_due = False
        try:
            if isinstance(sink, MetadataSink) and self.scenario is not None:
                store_scenario(sink, self.scenario)
            if stream.takes(sink):
                assert isinstance(sink, MessageSink)
                stream.write_labels(sink, stamp_ns)
        except Exception as exc:  # noqa: B902 - any writer failure stops recording only
            on_error(exc)
        return True
