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
A bag of ours as named streams for analysis: car bodies, wheel-rail forces, girders, piles, soil.

:func:`load_streams` reads a bag with :func:`ttb_sim.io.read_bag` (MCAP or
SQLite 3, from ``ttb-sim run`` or ``ros2 bag record`` of the node, under any node
namespace) and sorts its topics by what they measure.  ``summary.json`` next to
the bag (written by ``ttb-sim run``) supplies the scenario echo: the car and
track geometry for excitation frequencies and the observer positions and layer
properties for power flow.  Without it those figures are skipped with a reason.
The virtual sensors' topics (``~/sensors/<name>``) are streams by sensor name,
described by ``summary.json``'s ``sensors`` where it has them; the odometry's
head position places the train (the free vibration after it has left).

Every stream is a :class:`Series`: times (s) from ``header.stamp`` and values
(n, 3) in SI units.  Records sampled unevenly (a recorder that dropped
messages) are put on an even grid by linear interpolation, with a log line.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import json
import logging
from pathlib import Path
import re
from typing import Any

import numpy as np

from ttb_sim.errors import BagError
from ttb_sim.io.reader import read_bag, TopicArrays

log = logging.getLogger(__name__)

_PATTERNS = {
    'car_body': re.compile(r'/train/car(\d+)/body/imu$'),
    'wheel_rail': re.compile(r'/wheel_rail/car(\d+)/axle(\d+)/(left|right)$'),
    'midspan': re.compile(r'/bridge/span(\d+)/midspan$'),
    'bearing': re.compile(r'/bearings/pier(\d+)/(left|right)$'),
    'pile_displacement': re.compile(r'/piles/pier(\d+)/pile(\d+)/displacement$'),
    'pile_imu': re.compile(r'/piles/pier(\d+)/pile(\d+)/imu$'),
    'soil': re.compile(r'/soil/points$'),
    'pier_top': re.compile(r'/piers/pier(\d+)/top$'),
    'observer': re.compile(r'/observers/([^/]+)$'),
    'odometry': re.compile(r'/train/odometry$'),
    'sensor': re.compile(r'/sensors/([A-Za-z0-9_]+)$'),
}
_SENSOR_FIELDS = {'sensor_msgs/msg/Imu': 'linear_acceleration',
                  'geometry_msgs/msg/WrenchStamped': 'force',
                  'geometry_msgs/msg/Vector3Stamped': 'vector'}
"""The field of a sensor topic's message that holds its measured axes (x, y, z)."""


@dataclass(frozen=True)
class Series:
    """An evenly sampled record: times (s), values (n, ...) and the sampling rate (Hz)."""

    t: np.ndarray
    values: np.ndarray

    @property
    def rate(self) -> float:
        """Return the sampling rate in Hz."""
        return float((self.t.size - 1) / (self.t[-1] - self.t[0])) if self.t.size > 1 else 0.0


@dataclass
class Streams:
    """What one bag holds, by kind (keys are 1-based indices as in the topic names)."""

    path: Path
    label: str
    scenario: dict[str, Any] | None = None
    speed: float | None = None
    car_body: dict[int, Series] = field(default_factory=dict)
    car_body_rate: dict[int, Series] = field(default_factory=dict)
    wheel_rail: dict[tuple[int, int, str], Series] = field(default_factory=dict)
    midspan: dict[int, Series] = field(default_factory=dict)
    bearing: dict[tuple[int, str], Series] = field(default_factory=dict)
    pile_displacement: dict[tuple[int, int], Series] = field(default_factory=dict)
    pile_acceleration: dict[tuple[int, int], Series] = field(default_factory=dict)
    pile_rotation_rate: dict[tuple[int, int], Series] = field(default_factory=dict)
    soil: Series | None = None
    soil_fields: tuple[str, ...] = ()
    soil_names: tuple[str, ...] = ()
    """Names of the cloud's points (``pierNN/line_01`` ...) from summary.json; () without."""
    observers: dict[str, Series] = field(default_factory=dict)
    pier_top: dict[int, Series] = field(default_factory=dict)
    sensors: dict[str, Series] = field(default_factory=dict)
    """Virtual sensors by name: (n, 3) values on x, y, z (0 on the axes not measured)."""
    sensor_types: dict[str, str] = field(default_factory=dict)
    """Message type of each sensor's topic (``sensor_msgs/msg/Imu`` for accelerometers)."""
    sensor_info: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Each sensor's entry of ``summary.json``'s ``sensors`` (type, at, axes, ...); {} without."""
    head_position: Series | None = None
    """The train head's track position x (m) from the odometry, (n, 1); None without."""

    @property
    def duration(self) -> float:
        """Return the longest record in seconds."""
        spans = [s.t[-1] - s.t[0] for s in self._all() if s.t.size > 1]
        return float(max(spans)) if spans else 0.0

    @property
    def rate(self) -> float:
        """Return the highest sampling rate of the records in Hz."""
        rates = [s.rate for s in self._all()]
        return max(rates) if rates else 0.0

    def _all(self) -> list[Series]:
        out: list[Series] = []
        for d in (self.car_body, self.wheel_rail, self.midspan, self.bearing,
                  self.pile_displacement, self.pile_acceleration, self.observers,
                  self.sensors):
            out.extend(d.values())
        if self.soil is not None:
            out.append(self.soil)
        return out

    def is_empty(self) -> bool:
        """Return True when the bag has none of the streams analysis reads."""
        return not self._all()

    def section(self, name: str) -> dict[str, Any]:
        """Return a section of the scenario echo ({} without summary.json)."""
        if not self.scenario:
            return {}
        value = self.scenario.get(name, {})
        return value if isinstance(value, dict) else {}


def _series(arrays: TopicArrays, values: np.ndarray) -> Series | None:
    """Return the topic's values on an even time grid (None for fewer than 8 messages)."""
    t = arrays.stamp
    if t.size < 8:
        log.info('%s: %d messages, too few to analyse', arrays.topic, t.size)
        return None
    order = np.argsort(t, kind='stable')
    t, values = t[order], values[order]
    keep = np.concatenate([[True], np.diff(t) > 0])
    t, values = t[keep], values[keep]
    step = np.diff(t)
    if t.size > 2 and (step.max() - step.min()) > 1e-6 * np.median(step) + 1e-9:
        n = int(round((t[-1] - t[0]) / np.median(step))) + 1
        grid = np.linspace(t[0], t[-1], n)
        flat = values.reshape(values.shape[0], -1)
        cols = [np.interp(grid, t, flat[:, j]) for j in range(flat.shape[1])]
        log.info('%s: uneven stamps (%.3g..%.3g s), interpolated to %d even samples',
                 arrays.topic, step.min(), step.max(), n)
        return Series(grid, np.stack(cols, axis=-1).reshape((n,) + values.shape[1:]))
    return Series(t, values)


def read_summary(bag: Path) -> dict[str, Any] | None:
    """Return the ``summary.json`` written next to a bag by ``ttb-sim run``, or None."""
    folder = bag if bag.is_dir() else bag.parent
    path = folder / 'summary.json'
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as exc:
        log.warning('%s cannot be read (%s): analysing without the scenario echo', path, exc)
        return None
    return data if isinstance(data, dict) else None


def load_streams(path: str | Path, label: str | None = None) -> Streams:
    """
    Read a bag into :class:`Streams`.

    Raises
    ------
    BagError
        When ``path`` is not a readable bag, or holds none of the streams analysis reads.

    """
    bag = Path(path)
    arrays = read_bag(bag)
    summary = read_summary(bag)
    scenario = summary.get('scenario') if summary else None
    out = Streams(bag, label or (bag.name if bag.is_dir() else bag.stem),
                  scenario if isinstance(scenario, dict) else None)
    speeds: list[float] = []
    for topic, a in arrays.items():
        kind, match = _kind(topic)
        if kind is None or match is None:
            continue
        groups = match.groups()
        if kind == 'odometry' and len(a):
            speeds.append(float(np.median(a['linear_velocity'][:, 0])))
            out.head_position = _series(a, np.asarray(a['position'][:, :1], dtype=float))
        elif kind == 'sensor' and a.msgtype in _SENSOR_FIELDS:
            _put(out.sensors, groups[0], a, a[_SENSOR_FIELDS[a.msgtype]])
            if groups[0] in out.sensors:   # a topic with no messages has no series
                out.sensor_types[groups[0]] = a.msgtype
        elif kind == 'car_body':
            _put(out.car_body, int(groups[0]), a, a['linear_acceleration'])
            _put(out.car_body_rate, int(groups[0]), a, a['angular_velocity'])
        elif kind == 'wheel_rail':
            _put(out.wheel_rail, (int(groups[0]), int(groups[1]), groups[2]), a, a['force'])
        elif kind == 'midspan':
            _put(out.midspan, int(groups[0]), a, a['vector'])
        elif kind == 'bearing':
            _put(out.bearing, (int(groups[0]), groups[1]), a, a['force'])
        elif kind == 'pile_displacement':
            _put(out.pile_displacement, (int(groups[0]), int(groups[1])), a, a['vector'])
        elif kind == 'pile_imu':
            key = (int(groups[0]), int(groups[1]))
            _put(out.pile_acceleration, key, a, a['linear_acceleration'])
            _put(out.pile_rotation_rate, key, a, a['angular_velocity'])
        elif kind == 'soil' and a['points'].size:
            out.soil = _series(a, a['points'].astype(float))
            out.soil_fields = a.components['points']
        elif kind == 'observer':
            _put(out.observers, groups[0], a, a['vector'])
        elif kind == 'pier_top':
            _put(out.pier_top, int(groups[0]), a, a['vector'])
    described = summary.get('sensors') if summary else None
    if isinstance(described, list):
        out.sensor_info = {str(d['name']): d for d in described
                           if isinstance(d, dict) and d.get('name') in out.sensors}
    names = summary.get('soil_points') if summary else None
    if (out.soil is not None and isinstance(names, list)
            and len(names) == out.soil.values.shape[1]):
        out.soil_names = tuple(str(n) for n in names)
    if speeds:
        out.speed = speeds[0]
    elif scenario and isinstance(scenario.get('train'), dict):
        out.speed = float(scenario['train'].get('speed_kmh', 0.0)) / 3.6 or None
    if out.is_empty():
        raise BagError(f'bag {str(bag)!r} has none of the topics analysis reads (car bodies, '
                       'wheel-rail forces, mid-spans, bearings, piles, soil points, '
                       f'observers, sensors); it has: {", ".join(arrays) or "no readable topic"}')
    return out


def _kind(topic: str) -> tuple[str | None, re.Match[str] | None]:
    for kind, pattern in _PATTERNS.items():
        match = pattern.search(topic)
        if match:
            return kind, match
    return None, None


def _put(into: dict[Any, Series], key: Any, arrays: TopicArrays, values: np.ndarray) -> None:
    series = _series(arrays, np.asarray(values, dtype=float))
    if series is not None:
        into[key] = series
