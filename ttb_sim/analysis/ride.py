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
Ride comfort: the Sperling index (GB 5599-85 form) and car-body acceleration limits.

Sperling (PHYSICS.md section 8): a component of peak acceleration A (in g) at
frequency f scores ``W = 7.08 (A^3 F(f) / f)^(1/10)`` and components combine as
``W = (sum W_i^10)^(1/10)``.  Here the components are 1/3-octave bands from
0.5 to 40 Hz with ``A_i = sqrt(2) * band r.m.s.`` and f_i the band's power-weighted mean
frequency, so a pure tone scores exactly
its single-component value.  F is the vertical or lateral correction:

- vertical: 0.325 f^2 (0.5-5.9 Hz), 400 / f^2 (5.9-20 Hz), 1 above 20 Hz;
- lateral: 0.8 f^2 (0.5-5.4 Hz), 650 / f^2 (5.4-26 Hz), 1 above 26 Hz.

Grades for passenger cars: < 2.5 excellent, 2.5-2.75 good, 2.75-3.0 acceptable.
Car-body acceleration limits (TB 10621-2014, [unverified] in PHYSICS.md):
1.3 m/s^2 vertical, 1.0 m/s^2 lateral.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.analysis.levels import band_sums, line_power, third_octave_bands
from ttb_sim.errors import ScenarioError

__all__ = ['CAR_BODY_LIMITS', 'GRAVITY', 'SPERLING_GRADES', 'sperling_correction',
           'sperling_index', 'sperling_grade']

GRAVITY: float = 9.81
"""g of the Sperling formula (m/s^2)."""
CAR_BODY_LIMITS: dict[str, float] = {'vertical': 1.3, 'lateral': 1.0}
"""Peak car-body acceleration limits (m/s^2)."""
SPERLING_GRADES: tuple[tuple[float, str], ...] = ((2.5, 'excellent'), (2.75, 'good'),
                                                  (3.0, 'acceptable'))
"""Upper bounds of the Sperling grades of passenger cars."""


def sperling_correction(f: ArrayLike, direction: str = 'vertical') -> NDArray[np.float64]:
    """Return the frequency correction F(f) of the Sperling index (0 below 0.5 Hz)."""
    freq = np.asarray(f, dtype=float)
    if direction == 'vertical':
        knee, top, a, b = 5.9, 20.0, 0.325, 400.0
    elif direction == 'lateral':
        knee, top, a, b = 5.4, 26.0, 0.8, 650.0
    else:
        raise ScenarioError(f"direction must be 'vertical' or 'lateral', got {direction!r}")
    with np.errstate(divide='ignore'):
        out = np.where(freq < knee, a * freq**2, np.where(freq < top, b / freq**2, 1.0))
    return np.asarray(np.where(freq < 0.5, 0.0, out), dtype=float)


def sperling_index(acceleration: ArrayLike, sample_rate: float,
                   direction: str = 'vertical') -> float:
    """
    Return the Sperling index of a car-body acceleration record (m/s^2).

    Parameters
    ----------
    acceleration : array_like
        Uniformly sampled 1-D record (m/s^2), gravity excluded.
    sample_rate : float
        Sampling rate (Hz).
    direction : {'vertical', 'lateral'}
        Which correction F(f) applies.

    """
    _, lo, hi = third_octave_bands(0.5, min(40.0, 0.5 * sample_rate / 10 ** 0.05))
    power, centroid = band_sums(*line_power(acceleration, sample_rate), lo, hi)
    amplitude = np.sqrt(2.0 * power) / GRAVITY
    terms = 7.08**10 * amplitude**3 * sperling_correction(centroid, direction) / centroid
    return float(np.sum(terms) ** 0.1)


def sperling_grade(index: float) -> str:
    """Return the passenger-car grade of a Sperling index."""
    for bound, grade in SPERLING_GRADES:
        if index < bound:
            return grade
    return 'not acceptable'
