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
ISO 2631 frequency weightings Wk, Wd (ISO 2631-1) and Wm (ISO 2631-2), PHYSICS.md section 8.

Each weighting is the product of four analogue filters in s = j*2*pi*f: a
band-limiting high-pass and low-pass (second-order Butterworth at f1, f2), an
acceleration-velocity transition (f3, f4, Q4) and, for Wk, an upward step (f5,
Q5, f6, Q6).  :func:`weighting_response` evaluates the complex response;
:func:`weighted_rms` applies it to a record in the frequency domain (one FFT,
the response multiplied bin by bin, Parseval), which is exact for the
stationary sines and narrow-band records the tests use and for any record as
long as it is long compared with 1 / f1.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.errors import ScenarioError

__all__ = ['WEIGHTINGS', 'Weighting', 'weighted_rms', 'weighting_db', 'weighting_response']


@dataclass(frozen=True)
class Weighting:
    """Corner frequencies (Hz) and quality factors of one ISO 2631 weighting."""

    name: str
    f1: float
    f2: float
    f3: float
    f4: float
    q4: float
    f5: float | None = None
    q5: float | None = None
    f6: float | None = None
    q6: float | None = None


WEIGHTINGS: dict[str, Weighting] = {
    'Wk': Weighting('Wk', 0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    'Wd': Weighting('Wd', 0.4, 100.0, 2.0, 2.0, 0.63),
    'Wm': Weighting('Wm', 0.7943, 100.0, 5.684, 5.684, 0.5),
}
"""Wk vertical and Wd horizontal whole-body (ISO 2631-1), Wm buildings (ISO 2631-2)."""


def _weighting(name: str | Weighting) -> Weighting:
    if isinstance(name, Weighting):
        return name
    if name not in WEIGHTINGS:
        raise ScenarioError(f'weighting must be one of {", ".join(WEIGHTINGS)}, got {name!r}')
    return WEIGHTINGS[name]


def weighting_response(f: ArrayLike, name: str | Weighting = 'Wk') -> NDArray[np.complex128]:
    """
    Return the complex response of an ISO 2631 weighting at frequencies f (Hz).

    ``abs()`` of it is the weighting factor: |Wk| is 0.482 at 1 Hz, 1.054 at
    6.3 Hz and 0.132 at 80 Hz (V22). The response is 0 at f = 0.
    """
    w = _weighting(name)
    s = 2j * math.pi * np.asarray(f, dtype=float)
    o1, o2, o3, o4 = (2 * math.pi * x for x in (w.f1, w.f2, w.f3, w.f4))
    rt2 = math.sqrt(2.0)
    h = s**2 / (s**2 + rt2 * o1 * s + o1**2)
    h = h * o2**2 / (s**2 + rt2 * o2 * s + o2**2)
    h = h * (1 + s / o3) / (1 + s / (w.q4 * o4) + s**2 / o4**2)
    if w.f5 is not None and w.f6 is not None and w.q5 is not None and w.q6 is not None:
        o5, o6 = 2 * math.pi * w.f5, 2 * math.pi * w.f6
        h = h * (o5 / o6)**2 * (1 + s / (w.q5 * o5) + s**2 / o5**2) \
            / (1 + s / (w.q6 * o6) + s**2 / o6**2)
    return np.asarray(h, dtype=np.complex128)


def weighting_db(f: ArrayLike, name: str | Weighting = 'Wk') -> NDArray[np.float64]:
    """Return 20 log10 |W(f)| (dB); -inf where the response is 0."""
    with np.errstate(divide='ignore'):
        return np.asarray(20.0 * np.log10(np.abs(weighting_response(f, name))), dtype=float)


def weighted_rms(signal: ArrayLike, sample_rate: float, name: str | Weighting = 'Wk') -> float:
    """
    Return the frequency-weighted r.m.s. of an acceleration record (same unit as the record).

    The mean is removed, the record's FFT is multiplied by the weighting's
    response and the r.m.s. is summed from the spectrum (Parseval), so a sine
    of amplitude A at frequency f (a whole number of periods) gives
    ``A / sqrt(2) * |W(f)|``.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1 or x.size < 2:
        raise ScenarioError(f'signal must be a 1-D array of at least 2 samples, got {x.shape}')
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise ScenarioError(f'sample_rate must be > 0, got {sample_rate!r}')
    spectrum = np.fft.rfft(x - x.mean())
    f = np.fft.rfftfreq(x.size, 1.0 / sample_rate)
    power = np.abs(spectrum * weighting_response(f, name))**2
    power[1:(x.size + 1) // 2] *= 2.0   # one-sided: every bin but DC and Nyquist twice
    return float(math.sqrt(power.sum()) / x.size)
