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
The sensors and labels of a run as messages: what ``ttb-sim run`` and the node write and send.

:class:`SensorStream` owns the run's :class:`~ttb_sim.sensors.SensorBank` (none
without sensors), the sensors' topics and the labels. It takes every frame the
run computes and returns the messages due: the samples of each sensor, as
``(extra-topic index, stamp, message)``; the labels are extra topic 0, the sensors
1, 2, ... in order (:func:`~ttb_sim.io.sensor_topics.extra_topics`).
"""

from __future__ import annotations

from typing import Any, Iterator, Sequence

from ttb_sim.config.labels import run_labels
from ttb_sim.config.records import Scenario
from ttb_sim.io.sensor_topics import extra_topics, labels_message, sensor_topics, SensorTopic
from ttb_sim.io.topics import MessageTypes
from ttb_sim.sensors import Samples, SensorBank
from ttb_sim.sim import Frame, Layout

__all__ = ['SensorStream']

Message = tuple[int, int, Any]
"""(extra-topic index, stamp in ns, message)."""


class SensorStream:
    """
    The sensors and labels of a run.

    Parameters
    ----------
    scenario : Scenario
        The run's scenario (its ``all_sensors``).
    layout : Layout
        The run's frame layout.
    dt, output_every : float, int
        The run's time step and steps per frame (the frame rate the sensors sample).

    Raises
    ------
    ScenarioError
        Naming the sensor whose place the model does not have, before any message.

    """

    def __init__(self, scenario: Scenario, layout: Layout, dt: float,
                 output_every: int) -> None:
        sensors = scenario.all_sensors
        self.bank = SensorBank.of_run(sensors, layout, dt, output_every) if sensors else None
        self.topics: list[SensorTopic] = [] if self.bank is None else sensor_topics(
            [c.config for c in self.bank.channels],
            [c.acquisition.sigma for c in self.bank.channels])
        self.extra = extra_topics(sensors)
        """(name, message type) of the labels' topic, then of each sensor's."""
        self.labels = run_labels(scenario)

    @property
    def samples_every_frame(self) -> bool:
        """True when the sensors need every frame of the run (there are sensors)."""
        return self.bank is not None

    def relabel(self, scenario: Scenario, types: MessageTypes, stamp_ns: int) -> Message:
        """Take the labels of a new passage (or state); return their message."""
        self.labels = run_labels(scenario)
        return self.labels_message(types, stamp_ns)

    def labels_message(self, types: MessageTypes, stamp_ns: int = 0) -> Message:
        """Return the labels' message (extra topic 0)."""
        return 0, int(stamp_ns), labels_message(types, self.labels)

    def push(self, frame: Frame, types: MessageTypes) -> list[Message]:
        """Give one frame to the sensors; return the messages of the samples they return."""
        if self.bank is None:
            return []
        return list(self._messages(self.bank.push(frame), types))

    def flush(self, types: MessageTypes) -> list[Message]:
        """Return the messages of the frames the sensors still keep."""
        if self.bank is None:
            return []
        return list(self._messages(self.bank.flush(), types))

    def _messages(self, batches: Sequence[tuple[int, Samples]],
                  types: MessageTypes) -> Iterator[Message]:
        for index, samples in batches:
            topic = self.topics[index]
            for stamp, xyz in zip(samples.stamps_ns, topic.spread(samples.values)):
                yield index + 1, int(stamp), topic.message(types, int(stamp), xyz)

    def describe(self) -> list[dict[str, Any]]:
        """Return the sensors for ``summary.json`` (none without sensors)."""
        return [] if self.bank is None else self.bank.describe()
