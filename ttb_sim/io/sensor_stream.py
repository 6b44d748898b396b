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
run computes and returns the samples due (:class:`SensorSample`: extra-topic index,
stamp, values), which :meth:`SensorStream.message` turns into messages of either
back-end (rosbags' classes for a bag, rclpy's for the node); the labels are extra
topic 0, the sensors 1, 2, ... in order (:func:`~ttb_sim.io.sensor_topics.extra_topics`).
:meth:`SensorStream.write_labels` also stores the labels in the metadata of a sink that
has metadata (a bag's ``custom_data``, :data:`~ttb_sim.config.labels.LABELS_KEY`), for
``ttb-sim run`` and the node alike: at each change, so a bag closes with its last labels.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterator, Protocol, runtime_checkable, Sequence

import numpy as np

from ttb_sim.config.labels import labels_json, LABELS_KEY, run_labels
from ttb_sim.config.records import Scenario
from ttb_sim.io.sensor_topics import extra_topics, labels_message, sensor_topics, SensorTopic
from ttb_sim.io.topics import MessageTypes
from ttb_sim.sensors import Samples, SensorBank
from ttb_sim.sim import Frame, Layout

__all__ = ['MessageSink', 'MetadataSink', 'SensorSample', 'SensorStream']


@runtime_checkable
class MessageSink(Protocol):
    """What takes the messages of the extra topics one by one (a BagRecorder)."""

    @property
    def types(self) -> MessageTypes:
        """The map from a type name to the sink's message class."""

    @property
    def extra(self) -> list[tuple[str, str]]:
        """(name, message type) of its extra topics."""

    def write_message(self, index: int, stamp_ns: int, message: Any) -> None:
        """Write one message of the ``index``-th extra topic."""


@runtime_checkable
class MetadataSink(Protocol):
    """A sink with metadata of its own (a BagRecorder: rosbag2's ``custom_data``)."""

    def set_custom_data(self, key: str, value: str) -> None:
        """Store ``key: value`` in the metadata (the last value of a key wins)."""


@dataclass(frozen=True)
class SensorSample:
    """One recorded sample of one sensor."""

    index: int
    """Extra-topic index (1 + the sensor's place in the run's sensors)."""
    stamp_ns: int
    """Its stamp: true sample time plus the sensor's clock offset (ns)."""
    xyz: np.ndarray
    """(3,) its values on x, y, z (zeros on the axes it does not measure)."""


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

    def takes(self, sink: object) -> bool:
        """Tell whether a sink records this stream's topics (labels, then the sensors)."""
        return isinstance(sink, MessageSink) and sink.extra == self.extra

    @property
    def samples_every_frame(self) -> bool:
        """True when the sensors need every frame of the run (there are sensors)."""
        return self.bank is not None

    def relabel(self, scenario: Scenario) -> None:
        """Take the labels of a new passage (its speed, irregularity, state)."""
        self.labels = run_labels(scenario)

    def labels_message(self, types: MessageTypes) -> Any:
        """Return the labels' message (extra topic 0) in the classes of ``types``."""
        return labels_message(types, self.labels)

    def message(self, types: MessageTypes, sample: SensorSample) -> Any:
        """Return a sample's message in the classes of ``types``."""
        return self.topics[sample.index - 1].message(types, sample.stamp_ns, sample.xyz)

    def write_labels(self, sink: MessageSink, stamp_ns: int) -> None:
        """
        Write the labels' message to a sink, and the labels to its metadata if it has any.

        The metadata (:data:`~ttb_sim.config.labels.LABELS_KEY`) is overwritten at each
        call: it holds the labels last written when the sink closes; the history of the
        labels is the labels' topic.
        """
        if isinstance(sink, MetadataSink):
            sink.set_custom_data(LABELS_KEY, labels_json(self.labels))
        sink.write_message(0, stamp_ns, self.labels_message(sink.types))

    def write(self, sink: MessageSink, samples: Sequence[SensorSample]) -> None:
        """Write samples' messages to a sink."""
        for sample in samples:
            sink.write_message(sample.index, sample.stamp_ns, self.message(sink.types, sample))

    def push(self, frame: Frame) -> list[SensorSample]:
        """Give one frame to the sensors; return the samples they record from the block."""
        if self.bank is None:
            return []
        return list(self._samples(self.bank.push(frame)))

    def flush(self) -> list[SensorSample]:
        """Return the samples of the frames the sensors still keep."""
        if self.bank is None:
            return []
        return list(self._samples(self.bank.flush()))

    def _samples(self, batches: Sequence[tuple[int, Samples]]) -> Iterator[SensorSample]:
        for index, samples in batches:
            topic = self.topics[index]
            for stamp, xyz in zip(samples.stamps_ns, topic.spread(samples.values)):
                yield SensorSample(index + 1, int(stamp), xyz)

    def describe(self) -> list[dict[str, Any]]:
        """Return the sensors for ``summary.json`` (none without sensors)."""
        return [] if self.bank is None else self.bank.describe()
