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
Running safety and bridge deck indices against their limits (PHYSICS.md section 8).

- derailment coefficient Q/P = |lateral| / vertical wheel-rail force, per wheel;
- wheel-load reduction: GB 5599 form ``(P_mean - P_min) / P_mean`` with P_mean
  the mean of the two wheels of a wheelset at the same instant
  (``|P_l - P_r| / (P_l + P_r)``), and the dynamic form ``(P0 - P) / P0`` with
  P0 the wheel's mean load over the record (its static load on a long record);
- lateral wheelset force ``H = Q_l + Q_r`` against ``10 kN + P0 / 3`` (P0 the
  static axle load);
- deck acceleration: the second derivative of a mid-span displacement record,
  low-passed at 30 Hz (EN 1990 A2 counts frequencies up to 30 Hz at least).

Limits (TB 10621-2014 for high-speed lines, GB 5599-85; all [unverified] in
PHYSICS.md): Q/P 0.8, wheel-load reduction 0.6, deck 5.0 m/s^2 (ballastless).
Indices are evaluated on the records as sampled, without the standards'
minimum durations, so a short spike counts: they are upper estimates.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import signal as ssig

from ttb_sim.errors import ScenarioError

__all__ = ['LIMITS', 'deck_acceleration', 'derailment_coefficient', 'lateral_force_limit',
           'wheel_load_reduction']

LIMITS: dict[str, float] = {
    'derailment_coefficient': 0.8,
    'wheel_load_reduction': 0.6,
    'deck_acceleration_ballastless': 5.0,
    'deck_acceleration_ballasted': 3.5,
}
"""Limits of the dimensionless indices and of the deck acceleration (m/s^2)."""

DECK_CUTOFF_HZ: float = 30.0
"""Low-pass corner of the deck acceleration (Hz)."""


def derailment_coefficient(lateral: ArrayLike, vertical: ArrayLike) -> NDArray[np.float64]:
    """
    Return Q/P = |lateral| / vertical per sample (NaN where the wheel is unloaded).

    A wheel with vertical force <= 1 % of its mean load has left the rail: its
    Q/P is undefined (NaN) and the lift-off shows in the wheel-load reduction.
    """
    q = np.abs(np.asarray(lateral, dtype=float))
    p = np.asarray(vertical, dtype=float)
    loaded = p > 0.01 * max(float(np.mean(p)), 0.0)
    out = np.full(p.shape, np.nan)
    np.divide(q, p, out=out, where=loaded & (p > 0))
    return out


def wheel_load_reduction(left: ArrayLike, right: ArrayLike
                         ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """
    Return (GB 5599 form, dynamic form) of the wheel-load reduction of a wheelset per sample.

    The GB 5599 form is ``|P_l - P_r| / (P_l + P_r)``; the dynamic form is the
    larger of the two wheels' ``(P0 - P) / P0``, P0 each wheel's record mean.
    """
    pl = np.asarray(left, dtype=float)
    pr = np.asarray(right, dtype=float)
    total = pl + pr
    gb = np.divide(np.abs(pl - pr), total, out=np.ones_like(total), where=total > 0)
    p0l, p0r = float(np.mean(pl)), float(np.mean(pr))
    dyn = np.maximum((p0l - pl) / p0l if p0l > 0 else np.zeros_like(pl),
                     (p0r - pr) / p0r if p0r > 0 else np.zeros_like(pr))
    return gb, dyn


def lateral_force_limit(static_axle_load: float) -> float:
    """Return the lateral wheelset force limit 10 kN + P0 / 3 (N) for a static axle load (N)."""
    return 10e3 + static_axle_load / 3.0


def deck_acceleration(displacement: ArrayLike, sample_rate: float,
                      cutoff: float = DECK_CUTOFF_HZ) -> NDArray[np.float64]:
    """
    Return the acceleration (m/s^2) of a sampled displacement (m), low-passed at ``cutoff``.

    Second-order central differences, then a zero-phase fourth-order
    Butterworth low-pass (skipped when the cutoff is at or above Nyquist).
    """
    u = np.asarray(displacement, dtype=float)
    if u.ndim != 1 or u.size < 4:
        raise ScenarioError(f'displacement must be a 1-D array of at least 4 samples, '
                            f'got shape {u.shape}')
    dt = 1.0 / sample_rate
    a = np.gradient(np.gradient(u, dt, edge_order=2), dt, edge_order=2)
    if cutoff < 0.5 * sample_rate and u.size > 27:
        sos = ssig.butter(4, cutoff, fs=sample_rate, output='sos')
        a = ssig.sosfiltfilt(sos, a)
    return np.asarray(a, dtype=float)
