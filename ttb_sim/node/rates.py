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
Per-family publishing rates: which topics of a frame go out live, decided without ROS.

A topic's family is the first part of its node-relative name (``piles/pier07/pile01/imu``
is of family ``piles``): one of :data:`FAMILIES`. ``publish_rate_hz`` is the rate of every
family; ``publish_rates.<family>_hz`` (:data:`RATE_PARAMETERS`) overrides it for one family
(0: use ``publish_rate_hz``), so that a 1 kHz pile IMU does not force the soil cloud to
1 kHz. An override's period is a whole number of output frames (the rate is rounded to
the nearest such period) and a rate above the output rate (one message per frame) is
refused (:func:`check_rate`), since there is nothing to publish in between. The bag
records every frame at the output rate whatever the live rates.

:func:`family_periods` gives each family's period in simulation seconds,
:class:`Schedule` says which families are due at a frame, and :func:`frame_stride`
how many output frames the model may skip computing when no bag needs every frame.
"""

from __future__ import annotations

import math
from typing import Any, Iterable, Mapping

__all__ = ['check_rate', 'family_of', 'family_periods', 'FAMILIES', 'frame_stride',
           'RATE_PARAMETERS', 'Schedule']

FAMILIES = ('train', 'wheel_rail', 'bridge', 'bearings', 'piers', 'piles', 'soil', 'observers')
"""The topic families, by the first part of the topic name."""

RATE_PARAMETERS = {f'publish_rates.{family}_hz': family for family in FAMILIES}
"""Node parameter -> the family whose rate it overrides."""

_TOLERANCE = 1e-9


def family_of(topic_name: str) -> str:
    """
    Return the family of a topic: the first part of its node-relative name.

    Absolute names (``/clock``) have the family ''.
    """
    if topic_name.startswith('/'):
        return ''
    return topic_name.split('/', 1)[0]


def _rate_period(rate: float) -> float:
    return 1.0 / rate if rate > 0 else 0.0


def family_periods(values: Mapping[str, Any], frame_period: float,
                   families: Iterable[str] = FAMILIES) -> dict[str, float]:
    """
    Return each family's publishing period in simulation seconds (0: every frame).

    Parameters
    ----------
    values : mapping
        The node's parameter values (``publish_rate_hz`` and ``publish_rates.*``).
    frame_period : float
        Simulation seconds between two output frames (the bag's rate).
    families : iterable of str
        The families to plan (those the model has topics of).

    Returns
    -------
    dict
        Family -> period (s). A family without an override publishes at
        ``publish_rate_hz`` (period ``1 / publish_rate_hz``, as before the
        overrides); an override's period is the nearest whole number of frames
        (at least one).

    """
    base = _rate_period(float(values.get('publish_rate_hz', 0.0)))
    out = {}
    for family in families:
        rate = float(values.get(f'publish_rates.{family}_hz', 0.0))
        if rate > 0 and frame_period > 0:
            frames = max(1, round(1.0 / (rate * frame_period)))
            out[family] = frames * frame_period
        else:
            out[family] = base
    return out


def check_rate(name: str, rate: float, frame_period: float) -> tuple[bool, str]:
    """
    Check a family's rate against the output rate of the model.

    Parameters
    ----------
    name : str
        The parameter (``publish_rates.piles_hz``).
    rate : float
        The proposed rate (Hz); 0 means ``publish_rate_hz``.
    frame_period : float
        Simulation seconds between two output frames.

    Returns
    -------
    tuple of (bool, str)
        ``(False, reason)`` for a rate above the output rate, else ``(True, '')``.

    """
    if rate <= 0 or frame_period <= 0:
        return True, ''
    output_rate = 1.0 / frame_period
    if rate <= output_rate * (1 + _TOLERANCE):
        return True, ''
    return False, (f'{name} = {rate:g} Hz is above the output rate of this model, '
                   f'{output_rate:g} Hz (one frame every {frame_period:g} s of simulation '
                   f'time): allowed [0, {output_rate:g}] Hz (0 = publish_rate_hz); a '
                   "family's period is a whole number of frames")


def frame_stride(periods: Mapping[str, float], frame_period: float) -> int:
    """
    Return how many output frames apart the frames that some family publishes are.

    The greatest common divisor of the families' periods in frames; 1 when a
    period is 0 (every frame) or not a whole number of frames.
    """
    if frame_period <= 0 or not periods:
        return 1
    stride = 0
    for period in periods.values():
        ratio = period / frame_period
        whole = round(ratio)
        if period <= 0 or whole < 1 or abs(ratio - whole) > 1e-6:
            return 1
        stride = math.gcd(stride, whole)
    return max(1, stride)


class Schedule:
    """
    Which families are due at each frame, each at its own period.

    Parameters
    ----------
    families : iterable of str
        The families to schedule.
    start : float
        Simulation time (s) of the first frame that is due for every family.

    """

    def __init__(self, families: Iterable[str], start: float = 0.0) -> None:
        self.families = tuple(families)
        self._next = {f: start for f in self.families}

    def restart(self, start: float, family: str | None = None) -> None:
        """Make one family (all when None) due again from ``start``."""
        for f in self.families if family is None else (family,):
            if f in self._next:
                self._next[f] = start

    def due(self, time: float, periods: Mapping[str, float]) -> frozenset[str]:
        """
        Return the families due at a frame of simulation time ``time`` and advance them.

        A family is due when its next time has come (0 period: at every frame); its next
        time then moves on by one period, or to one period after ``time`` when the
        rate was raised so far that it fell behind.
        """
        out = []
        for family in self.families:
            period = periods.get(family, 0.0)
            if period <= 0:
                out.append(family)
                continue
            if time >= self._next[family] - _TOLERANCE:
                out.append(family)
                self._next[family] += period
                if self._next[family] <= time - _TOLERANCE:
                    self._next[family] = time + period
        return frozenset(out)
