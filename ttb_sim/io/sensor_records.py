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
A bag's accelerometers as channels on one time grid, and when the train has left the bridge.

:func:`accelerometer_records` gathers the channels (one per measured axis of each
``sensor_msgs/msg/Imu`` sensor topic) of a :class:`~ttb_sim.io.streams.Streams` on the
times of the first; :func:`train_exit_time` says when the last axle leaves the bridge,
from the odometry's head position (or the scenario's speed without it), so that the free
vibration after the passage can be cut (:data:`FREE_MARGIN_S` later). Operational modal
analysis (``ttb-sim analyze``'s modes section, V27) reads these.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
import logging
from typing import TYPE_CHECKING

import numpy as np

from ttb_sim.io.streams import Streams

if TYPE_CHECKING:
    from ttb_sim.config import Scenario

__all__ = ['accelerometer_records', 'Channel', 'FREE_MARGIN_S', 'Records', 'StillOnBridge',
           'train_exit_time']

log = logging.getLogger(__name__)

IMU = 'sensor_msgs/msg/Imu'
AXES = ('x', 'y', 'z')
FREE_MARGIN_S = 0.1
"""The free vibration is taken from this long after the last axle has left the bridge:
about ten group delays of a 200 Hz sensor's anti-alias filter (11 ms, docs/sensors.md), so
that the filter's response to the forced part has died out."""


class StillOnBridge(ValueError):
    """The train has not left the bridge by the end of the record (the text says where)."""


@dataclass(frozen=True)
class Channel:
    """One measured axis of one accelerometer."""

    sensor: str
    axis: str
    place: str
    """The sensor's ``at`` (``girder@16``); '' when the bag does not describe it."""

    @property
    def name(self) -> str:
        """Return ``sensor.axis``."""
        return f'{self.sensor}.{self.axis}'


@dataclass(frozen=True)
class Records:
    """Channels on one even time grid: times (s), values (channels, samples), rate (Hz)."""

    t: np.ndarray
    values: np.ndarray
    channels: tuple[Channel, ...]
    rate: float
    passband_hz: float | None = None
    """The lowest anti-alias pass-band edge of the channels' sensors (None: not described)."""

    def between(self, start: float, end: float) -> Records:
        """Return the samples with start <= t <= end."""
        keep = (self.t >= start) & (self.t <= end)
        return Records(self.t[keep], self.values[:, keep], self.channels, self.rate,
                       self.passband_hz)


def _axes_of(name: str, s: Streams, values: np.ndarray) -> list[str]:
    info = s.sensor_info.get(name)
    if info is not None:
        axes = info.get('axes') or 'z'
        return [a for a in AXES if a in list(axes)]
    return [a for k, a in enumerate(AXES) if np.any(values[:, k])]   # unmeasured axes read 0


def accelerometer_records(s: Streams) -> Records:
    """
    Return the bag's accelerometer channels on the grid of the most common sensor rate.

    Sensors whose topic is an IMU and, where ``summary.json`` describes them, whose type is
    ``accelerometer``; the measured axes from the description, else the axes that are not
    all zero. Channels of another rate are left out (logged); all are interpolated onto
    the times of the first one over the span they share (clock offsets differ by sensor).
    No channel gives empty records.
    """
    found: list[tuple[Channel, np.ndarray, np.ndarray, float]] = []
    for name, series in sorted(s.sensors.items()):
        info = s.sensor_info.get(name, {})
        if s.sensor_types.get(name) != IMU or info.get('type', 'accelerometer') != 'accelerometer':
            continue
        for axis in _axes_of(name, s, series.values):
            found.append((Channel(name, axis, str(info.get('at', ''))), series.t,
                          series.values[:, AXES.index(axis)], series.rate))
    if not found:
        return Records(np.zeros(0), np.zeros((0, 0)), (), 0.0)
    rates = Counter(round(r, 6) for *_, r in found)
    common = max(rates, key=lambda r: (rates[r], r))
    left = [c.name for c, *_, r in found if round(r, 6) != common]
    if left:
        log.info('channels %s sampled at another rate than %g Hz left out', ', '.join(left),
                 common)
    found = [f for f in found if round(f[3], 6) == common]
    start = max(t[0] for _, t, _, _ in found)
    end = min(t[-1] for _, t, _, _ in found)
    grid = found[0][1][(found[0][1] >= start) & (found[0][1] <= end)]
    values = np.vstack([np.interp(grid, t, v) for _, t, v, _ in found])
    passbands = [float(s.sensor_info[c.sensor]['anti_alias']['passband_hz']) for c, *_ in found
                 if isinstance(s.sensor_info.get(c.sensor, {}).get('anti_alias'), dict)]
    return Records(grid, values, tuple(c for c, *_ in found), float(found[0][3]),
                   min(passbands) if passbands else None)


def train_exit_time(s: Streams, scenario: Scenario) -> float:
    """
    Return when the last axle leaves the bridge (s): from the odometry, else from the speed.

    Raises
    ------
    StillOnBridge
        When the last axle is still on the bridge at the end of the odometry.

    """
    length = scenario.bridge.n_spans * scenario.bridge.span_length
    rear = max(scenario.axle_positions())
    if s.head_position is not None and s.head_position.t.size:
        t, x = s.head_position.t, s.head_position.values[:, 0] - rear
        off = np.flatnonzero(x >= length)
        if off.size == 0:
            raise StillOnBridge(f'the last axle is still on the bridge at the end of the record '
                                f'(t = {t[-1]:.3f} s, {length - x[-1]:.3g} m to go)')
        k = int(off[0])
        if k == 0:
            return float(t[0])
        return float(np.interp(length, x[k - 1:k + 1], t[k - 1:k + 1]))
    return (length + rear - scenario.train.start_position) / scenario.train.speed
