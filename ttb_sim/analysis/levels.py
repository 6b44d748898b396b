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
Vibration acceleration levels in 1/3-octave bands (PHYSICS.md section 8, [P] Fig. 26).

``VAL = 20 log10(a_rms / a0)`` dB with a0 = 1e-6 m/s^2, per 1/3-octave band:
centres ``10^(n/10)`` Hz (nominal 1, 1.25, 1.6, ... 80 Hz), edges ``f_c 10^(+-1/20)``
(the base-10 form of ``f_c 2^(+-1/6)``, 0.08 % apart, so that the bands tile the axis).
Band r.m.s. values are summed from the record's FFT lines (Parseval, mean
removed), so the band powers add up to the record's variance and a sine lying
inside one band gives ``20 log10(A / sqrt(2) / a0)`` there.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.analysis.weighting import Weighting, weighting_db
from ttb_sim.errors import ScenarioError

__all__ = ['A0', 'band_rms', 'band_sums', 'line_power', 'third_octave_bands', 'total_level',
           'vibration_levels']

A0: float = 1e-6
"""Reference acceleration of VAL (m/s^2)."""


def third_octave_bands(lowest: float = 1.0, highest: float = 80.0
                       ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """
    Return (centres, lower edges, upper edges) of the 1/3-octave bands from lowest to highest.

    Centres are ``10^(n/10)`` Hz for the integers n with centres inside
    [lowest, highest] (a 2 % tolerance admits the nominal 80 Hz = 10^1.9).
    """
    if not (0 < lowest <= highest):
        raise ScenarioError(f'need 0 < lowest <= highest, got {lowest!r}, {highest!r}')
    n = np.arange(math.floor(10 * math.log10(lowest * 0.98)),
                  math.ceil(10 * math.log10(highest * 1.02)) + 1)
    centres = 10.0 ** (n / 10.0)
    centres = centres[(centres >= lowest * 0.98) & (centres <= highest * 1.02)]
    return centres, centres * 10.0 ** -0.05, centres * 10.0 ** 0.05


def line_power(signal: ArrayLike, sample_rate: float
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return (f, mean square per FFT line) of a record, mean removed (sum: the variance)."""
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise ScenarioError(f'signal must be a 1-D array of at least 2 samples, got {x.shape}')
    if not np.all(np.isfinite(x)):
        raise ScenarioError('signal must be finite')
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise ScenarioError(f'sample_rate must be > 0, got {sample_rate!r}')
    power = np.abs(np.fft.rfft(x - x.mean()))**2 / x.size**2
    power[1:(x.size + 1) // 2] *= 2.0
    return np.asarray(np.fft.rfftfreq(x.size, 1.0 / sample_rate), dtype=float), power


def band_sums(f: ArrayLike, power: ArrayLike, lower: ArrayLike, upper: ArrayLike
              ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return (power sum, power-weighted mean frequency) of the lines in each [lower, upper)."""
    freq = np.asarray(f, dtype=float)
    pw = np.asarray(power, dtype=float)
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    inside = ((freq[None, :] >= lo[:, None]) & (freq[None, :] < hi[:, None])).astype(float)
    total = inside @ pw
    centroid = np.divide(inside @ (pw * freq), total, out=np.sqrt(lo * hi), where=total > 0)
    return np.asarray(total, dtype=float), np.asarray(centroid, dtype=float)


def band_rms(signal: ArrayLike, sample_rate: float, lower: ArrayLike, upper: ArrayLike
             ) -> NDArray[np.float64]:
    """Return the r.m.s. of a record in each band [lower, upper) (Hz), from its FFT lines."""
    f, power = line_power(signal, sample_rate)
    return np.asarray(np.sqrt(band_sums(f, power, lower, upper)[0]), dtype=float)


def vibration_levels(signal: ArrayLike, sample_rate: float, lowest: float = 1.0,
                     highest: float = 80.0) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """
    Return (band centres in Hz, VAL in dB re 1e-6 m/s^2) of an acceleration record (m/s^2).

    Bands above the Nyquist frequency are left out. A band without power is -inf dB.
    """
    centres, lo, hi = third_octave_bands(lowest, min(highest, 0.5 * sample_rate / 10 ** 0.05))
    rms = band_rms(signal, sample_rate, lo, hi)
    with np.errstate(divide='ignore'):
        return centres, np.asarray(20.0 * np.log10(rms / A0), dtype=float)


def total_level(centres: ArrayLike, levels: ArrayLike,
                weighting: str | Weighting | None = None) -> float:
    """
    Return the energy sum of band levels (dB), weighted at the band centres when asked.

    ``10 log10 sum 10^((VAL_i + W_i)/10)`` with ``W_i = 20 log10 |W(f_i)|`` (0 without
    a weighting): 'Wk' gives the vertical whole-body level, 'Wm' the building level.
    """
    lv = np.asarray(levels, dtype=float)
    w = np.zeros_like(lv) if weighting is None else weighting_db(centres, weighting)
    with np.errstate(divide='ignore'):
        return float(10.0 * np.log10(np.sum(10.0 ** ((lv + w) / 10.0))))
