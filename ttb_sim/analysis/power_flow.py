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
Vibration power flow, [P] Eqs. 17-18 (PHYSICS.md section 8).

The mean power an interaction force F delivers to a structure moving with
velocity v is the time mean of F(t) v(t) (Eq. 17).  In the frequency domain
(Eq. 18) each line contributes ``P_k = 1/2 Re[F_k conj(V_k)]`` with F_k and V_k
complex *peak* amplitudes; with numpy's FFT that is ``2 Re[F^_k conj(V^_k)] / N^2``
for 0 < k < N/2, and the DC and Nyquist lines count once.  The lines sum to
the time mean of F v exactly (Parseval), which V21 checks.

:func:`velocity_from_displacement` differentiates sampled displacements
(second-order central differences), for bags that record displacements only.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.errors import ScenarioError

__all__ = ['band_power', 'power_flow_spectrum', 'velocity_from_displacement']


def _pair(force: ArrayLike,
          velocity: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    f = np.asarray(force, dtype=float)
    v = np.asarray(velocity, dtype=float)
    if f.ndim != 1 or f.shape != v.shape or f.size < 2:
        raise ScenarioError(f'force and velocity must be 1-D arrays of the same length >= 2, '
                            f'got shapes {f.shape} and {v.shape}')
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(v))):
        raise ScenarioError('force and velocity must be finite')
    return f, v


def power_flow_spectrum(force: ArrayLike, velocity: ArrayLike, sample_rate: float
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """
    Return the frequency-domain power flow P(f) of a force against a velocity (Eq. 18).

    Parameters
    ----------
    force, velocity : array_like
        Simultaneous uniformly sampled records (N, W for forces in N and
        velocities in m/s; per metre when the force is per metre).
    sample_rate : float
        Sampling rate (Hz), > 0.

    Returns
    -------
    f : ndarray
        Frequencies (Hz), ``k * sample_rate / N``, k = 0 .. N // 2.
    p : ndarray
        Mean power of each line (W): ``p.sum()`` equals ``mean(force * velocity)``.

    """
    f_rec, v_rec = _pair(force, velocity)
    if not (np.isfinite(sample_rate) and sample_rate > 0):
        raise ScenarioError(f'sample_rate must be > 0, got {sample_rate!r}')
    n = f_rec.size
    cross = np.fft.rfft(f_rec) * np.conj(np.fft.rfft(v_rec))
    p = 2.0 * cross.real / n**2
    p[0] *= 0.5
    if n % 2 == 0:
        p[-1] *= 0.5
    return np.asarray(np.fft.rfftfreq(n, 1.0 / sample_rate), dtype=float), p


def band_power(f: ArrayLike, p: ArrayLike, edges: ArrayLike) -> NDArray[np.float64]:
    """Return the sum of the power lines p between consecutive edges (Hz), [lo, hi)."""
    freq = np.asarray(f, dtype=float)
    power = np.asarray(p, dtype=float)
    e = np.asarray(edges, dtype=float)
    which = np.digitize(freq, e) - 1
    inside = (which >= 0) & (which < e.size - 1)
    return np.asarray(np.bincount(which[inside], weights=power[inside], minlength=e.size - 1),
                      dtype=float)


def velocity_from_displacement(displacement: ArrayLike, sample_rate: float
                               ) -> NDArray[np.float64]:
    """
    Return the velocity of a sampled displacement (central differences, one-sided at the ends).

    The error of a sine of frequency f is a relative ``(2 pi f / sample_rate)^2 / 6``:
    0.7 % at 100 Hz sampled at 1 kHz.
    """
    u = np.asarray(displacement, dtype=float)
    if u.ndim != 1 or u.size < 3:
        raise ScenarioError(f'displacement must be a 1-D array of at least 3 samples, '
                            f'got shape {u.shape}')
    return np.asarray(np.gradient(u, 1.0 / sample_rate, edge_order=2), dtype=float)
