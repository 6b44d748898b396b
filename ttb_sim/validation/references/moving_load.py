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
Closed-form load a train of constant axle forces puts on a pier (V20's reference).

A pier between two simply supported spans of length L carries, of a vertical
force P standing a distance x from its axis, the reaction P (1 - |x| / L) for
|x| < L and nothing farther: its influence line is a triangle of half-base L.
An axle of load P_k passing the pier axis at time t_k at speed V therefore
loads it with ``r_k(t) = P_k tri(V (t - t_k) / L)``, whose Fourier transform
``R_k(f) = int r_k(t) exp(-i 2 pi f t) dt`` is

    R_k(f) = P_k (L / V) sinc^2(f L / V) exp(-i 2 pi f t_k),

``sinc(u) = sin(pi u) / (pi u)``: zero at every f = n V / L. A train sums its
axles: ``R(f) = (L / V) sinc^2(f L / V) sum_k P_k exp(-i 2 pi f t_k)``, the
influence line's spectrum times the axle train's. The quasi-static reaction
(no girder dynamics) is what this describes; it shares no code with the model.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ['axle_train_factor', 'passage_times', 'pier_load_history', 'pier_load_spectrum',
           'triangle_spectrum']


def passage_times(offsets: ArrayLike, head_start: float, pier_position: float,
                  speed: float) -> NDArray[np.float64]:
    """
    Return the times (s) at which the axles pass the pier.

    ``offsets`` are the axles' distances behind the head (m), which starts at
    ``head_start`` (m) and runs at ``speed`` (m/s); the pier stands at
    ``pier_position`` (m).
    """
    return np.asarray((pier_position - head_start + np.asarray(offsets, dtype=float)) / speed,
                      dtype=float)


def triangle_spectrum(f: ArrayLike, half_base: float, speed: float) -> NDArray[np.float64]:
    """Return the Fourier transform (s) of tri(V t / L) at f (Hz): (L / V) sinc^2(f L / V)."""
    tau = half_base / speed
    return np.asarray(tau * np.sinc(np.asarray(f, dtype=float) * tau) ** 2, dtype=float)


def axle_train_factor(f: ArrayLike, loads: ArrayLike, times: ArrayLike
                      ) -> NDArray[np.complex128]:
    """Return sum_k P_k exp(-i 2 pi f t_k) at f (Hz): loads P_k (N), passage times t_k (s)."""
    phase = np.exp(-2j * np.pi * np.outer(np.asarray(f, dtype=float), np.asarray(times)))
    return np.asarray(phase @ np.asarray(loads, dtype=float), dtype=complex)


def pier_load_spectrum(f: ArrayLike, loads: ArrayLike, times: ArrayLike, half_base: float,
                       speed: float) -> NDArray[np.complex128]:
    """Return R(f) (N s) of the quasi-static pier reaction of the axle train (module text)."""
    return triangle_spectrum(f, half_base, speed) * axle_train_factor(f, loads, times)


def pier_load_history(t: ArrayLike, loads: ArrayLike, times: ArrayLike, half_base: float,
                      speed: float) -> NDArray[np.float64]:
    """Return the quasi-static pier reaction r(t) (N) at times t (s): sum of the triangles."""
    u = speed * (np.asarray(t, dtype=float)[:, None] - np.asarray(times)[None, :]) / half_base
    return np.asarray(np.clip(1.0 - np.abs(u), 0.0, None) @ np.asarray(loads, dtype=float),
                      dtype=float)
