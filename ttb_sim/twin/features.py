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
Features of a passage: what a twin pipeline learns from, read off the sensors' records.

Per measured axis of each virtual sensor (topic ``sensors/<name>`` in any namespace,
so a bag recorded elsewhere with the same topics serves too): the mean, the RMS about
the mean, the peak (largest magnitude) and the power spectral density on a grid common
to every sensor and case.  The PSD is Welch's estimate (:func:`ttb_sim.analysis.psd.welch_psd`:
Hann segments of ``psd_segment_s``, half overlapping, one-sided, unit^2/Hz) interpolated
onto the grid; grid points above a sensor's Nyquist frequency are NaN.  Lost samples
(dropouts) are bridged by linear interpolation on the sensor's own sample grid before
the estimate, so a channel with gaps still gives a spectrum of the right level.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ttb_sim.analysis.psd import MIN_SEGMENT_SAMPLES, welch_psd
from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.declarations import param
from ttb_sim.errors import BagError, ScenarioError
from ttb_sim.io.reader import bag_topics, read_bag
from ttb_sim.io.sensor_topics import SensorTopic

__all__ = ['channel_features', 'FeatureSpec', 'Features', 'record_length', 'sensor_features']

FIELDS = {'sensor_msgs/msg/Imu': 'linear_acceleration',
          'geometry_msgs/msg/WrenchStamped': 'force',
          'geometry_msgs/msg/Vector3Stamped': 'vector'}
"""The field of each sensor message type that holds the measurement."""
SCALARS = ('mean', 'rms', 'peak')
"""The scalar features of a channel."""
MIN_SAMPLES = MIN_SEGMENT_SAMPLES
"""Fewest samples a channel needs for its features (one Welch segment)."""


@dataclass(frozen=True)
class FeatureSpec:
    """The features to keep of each case (the ``features`` mapping of a dataset spec)."""

    psd_fmin_hz: float = param(0.5, 'Hz', 'Lowest frequency of the common PSD grid.',
                               low=0.0, low_inclusive=False, high=1e5)
    psd_fmax_hz: float = param(50.0, 'Hz', 'Highest frequency of the common PSD grid (points '
                               "above a sensor's Nyquist frequency are NaN).",
                               low=0.0, low_inclusive=False, high=1e5)
    psd_points: int = param(64, '-', 'Points of the PSD grid, log-spaced (0: no PSDs).',
                            low=0, high=4096)
    psd_segment_s: float = param(2.0, 's', "Length of Welch's segments (the frequency "
                                 'resolution is its inverse); shortened to the record.',
                                 low=0.0, low_inclusive=False, high=1e4)
    truth: bool = param(True, '-', "Also keep the exact topics' peaks (girder, wheel-rail, "
                        'car body, piles, soil: the columns of sweep.csv).')

    def __post_init__(self) -> None:
        """Refuse an empty grid."""
        if self.psd_points and not self.psd_fmin_hz < self.psd_fmax_hz:
            raise ScenarioError(f'features.psd_fmin_hz = {self.psd_fmin_hz:g} must be below '
                                f'features.psd_fmax_hz = {self.psd_fmax_hz:g}')

    def frequencies(self) -> np.ndarray:
        """Return the PSD grid (Hz), log-spaced from ``psd_fmin_hz`` to ``psd_fmax_hz``."""
        if self.psd_points == 0:
            return np.zeros(0)
        return np.geomspace(self.psd_fmin_hz, self.psd_fmax_hz, self.psd_points)


@dataclass(frozen=True)
class Features:
    """A case's features: scalars by name, PSDs by channel on the common grid."""

    scalars: dict[str, float]
    """``<sensor>.<axis>.<mean|rms|peak>`` -> value (the sensor's unit)."""
    psd: dict[str, np.ndarray]
    """``<sensor>.<axis>`` -> PSD on :attr:`frequencies_hz` (unit^2/Hz, NaN above Nyquist)."""
    frequencies_hz: np.ndarray


def channel_features(stamp_s: np.ndarray, values: np.ndarray, rate_hz: float,
                     frequencies_hz: np.ndarray, segment_s: float
                     ) -> tuple[dict[str, float], np.ndarray]:
    """
    Return the scalar features and the PSD on ``frequencies_hz`` of one channel.

    Parameters
    ----------
    stamp_s, values
        (n,) sample times (s) and values; gaps (lost samples) are allowed.
    rate_hz
        The channel's sampling rate.
    frequencies_hz
        The common grid.
    segment_s
        Welch's segment length (shortened to the record).

    """
    if len(values) < MIN_SAMPLES:
        nan = float('nan')
        return {k: nan for k in SCALARS}, np.full(len(frequencies_hz), np.nan)
    index = np.rint((stamp_s - stamp_s[0]) * rate_hz)
    regular = np.interp(np.arange(index[-1] + 1), index, values)
    mean = float(np.mean(regular))
    scalars = {'mean': mean, 'rms': float(np.sqrt(np.mean((regular - mean) ** 2))),
               'peak': float(np.max(np.abs(values)))}
    if len(frequencies_hz) == 0:
        return scalars, np.zeros(0)
    nperseg = int(min(len(regular), max(MIN_SAMPLES, round(segment_s * rate_hz))))
    f, pxx = welch_psd(regular, rate_hz, nperseg / rate_hz)
    psd = np.interp(frequencies_hz, f, pxx)
    psd[frequencies_hz > rate_hz / 2.0] = np.nan
    return scalars, psd


def sensor_features(bag: str | Path, sensors: Sequence[SensorConfig],
                    spec: FeatureSpec) -> Features:
    """
    Return the features of every sensor's record in a bag.

    Raises
    ------
    BagError
        If the bag cannot be read, or lacks the topic of one of ``sensors``.

    """
    grid = spec.frequencies()
    topics = [SensorTopic(c, 0.0).name for c in sensors]
    available = bag_topics(bag)
    missing = [t for t in topics if not any(_is(a, t) for a in available)]
    if missing:
        raise BagError(f'bag {str(bag)!r} has no topic {", ".join(missing)} of the sensors '
                       'asked for')
    arrays = read_bag(bag, topics) if topics else {}
    scalars: dict[str, float] = {}
    psd: dict[str, np.ndarray] = {}
    for config, topic in zip(sensors, topics):
        record = next(a for name, a in arrays.items() if _is(name, topic))
        measurement = record[FIELDS.get(record.msgtype, 'vector')]
        for axis in config.measured_axes:
            channel = f'{config.name}.{axis}'
            values, channel_psd = channel_features(
                record.stamp, measurement[:, 'xyz'.index(axis)], config.rate_hz, grid,
                spec.psd_segment_s)
            scalars.update({f'{channel}.{k}': v for k, v in values.items()})
            if len(grid):
                psd[channel] = channel_psd
    return Features(scalars, psd, grid)


def record_length(bag: str | Path, sensors: Sequence[SensorConfig]) -> float:
    """
    Return the shortest span of the sensors' records in a bag (s).

    Raises
    ------
    BagError
        If a sensor's topic is missing, or no sensor recorded two samples.

    """
    arrays = read_bag(bag, [SensorTopic(c, 0.0).name for c in sensors])
    spans = [float(a.stamp[-1] - a.stamp[0]) for a in arrays.values() if len(a) > 1]
    if not spans:
        raise BagError(f'bag {str(bag)!r}: the sensors recorded fewer than two samples each')
    return min(spans)


def _is(absolute: str, relative: str) -> bool:
    """Return True when ``absolute`` is the topic ``relative`` in some namespace."""
    return absolute == relative or absolute.endswith('/' + relative)
