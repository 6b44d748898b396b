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
The acquisition chain of one sensor: what a data logger makes of the model's truth.

In order, on the truth sampled at the frame rate: an anti-alias filter (a
Chebyshev type II low-pass designed by :func:`scipy.signal.cheb2ord` for the
sensor's pass band and stop-band attenuation at its Nyquist frequency, run
causally as second-order sections with its state carried from block to block),
decimation to the sensor rate (every q-th frame, q = frame rate / sensor rate),
then bias, bias random walk and white noise, quantisation, clipping at full
scale, dropouts and the clock offset. The noise and dropout draws come from
generators of the sensor's own seed; blocks of any size give the same bits.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from scipy import signal

from ttb_sim.config.sensor_records import decimation_factor, SensorConfig

__all__ = ['Acquisition', 'AntiAlias', 'Samples', 'design_anti_alias']

PASSBAND_RIPPLE_DB = 0.1
"""Largest loss of the anti-alias filter inside its pass band (dB)."""


@dataclass(frozen=True)
class AntiAlias:
    """The anti-alias filter of a sensor: second-order sections at the frame rate."""

    sos: np.ndarray
    order: int
    passband_hz: float
    stopband_hz: float
    attenuation_db: float

    def response(self, frequency: np.ndarray, frame_rate: float) -> np.ndarray:
        """Return the complex frequency response at ``frequency`` (Hz)."""
        _, h = signal.sosfreqz(self.sos, worN=np.asarray(frequency, dtype=float), fs=frame_rate)
        return np.asarray(h)

    def group_delay(self, frequency: float, frame_rate: float) -> float:
        """Return the group delay at ``frequency`` (s), from the phase slope."""
        df = 1e-4 * max(frequency, 1e-3)
        f = np.array([max(frequency - df, 0.0), frequency + df])
        phase = np.unwrap(np.angle(self.response(f, frame_rate)))
        return float(-(phase[1] - phase[0]) / (2 * math.pi * (f[1] - f[0])))


def design_anti_alias(config: SensorConfig, frame_rate: float) -> AntiAlias:
    """Design the low-pass of a sensor: flat to passband x Nyquist, stopped from Nyquist on."""
    nyquist = config.rate_hz / 2.0
    wp, ws = config.passband * nyquist, nyquist
    order, wn = signal.cheb2ord(wp, ws, PASSBAND_RIPPLE_DB, config.stopband_attenuation,
                                fs=frame_rate)
    sos = signal.cheby2(order, config.stopband_attenuation, wn, output='sos', fs=frame_rate)
    return AntiAlias(sos=sos, order=int(order), passband_hz=wp, stopband_hz=ws,
                     attenuation_db=config.stopband_attenuation)


@dataclass(frozen=True)
class Samples:
    """What a sensor recorded from one block of frames."""

    stamps_ns: np.ndarray
    """(n,) int64 stamps of the published samples (true time + clock offset)."""
    values: np.ndarray
    """(n, axes) the recorded values of those samples."""
    dropped: int
    """Samples of the block lost to dropouts (or stamped before 0)."""
    clipped: int
    """Published samples with some axis clipped at full scale."""


class Acquisition:
    """
    The chain of one sensor over a stream of truth frames.

    Parameters
    ----------
    config : SensorConfig
        The sensor.
    frame_rate : float
        Rate of the truth frames (Hz).
    n_axes : int
        Channels of the truth (one per measured axis).

    Raises
    ------
    SensorError
        When the sensor's rate does not divide the frame rate (:func:`decimation_factor`).

    """

    def __init__(self, config: SensorConfig, frame_rate: float, n_axes: int) -> None:
        self.config = config
        self.frame_rate = frame_rate
        self.q = decimation_factor(frame_rate, config)
        self.filter = design_anti_alias(config, frame_rate)
        self.n_axes = n_axes
        self.sigma = config.noise_density * math.sqrt(config.rate_hz / 2.0)
        """Standard deviation of the white noise per sample (its one-sided PSD is density^2)."""
        noise, walk, drops = np.random.SeedSequence(config.rng_seed).spawn(3)
        self._noise = np.random.Generator(np.random.PCG64(noise))
        self._walk = np.random.Generator(np.random.PCG64(walk))
        self._drops = np.random.Generator(np.random.PCG64(drops))
        self._zi: np.ndarray | None = None
        self._frames = 0                 # frames seen so far
        self._walked = np.zeros(n_axes)  # the random-walk part of the bias now
        self._lost = False               # in a dropout now
        self._left = self._run_length()  # samples left in the present run (in or out)

    def _run_length(self) -> int:
        """Draw the length of the next run of kept (or lost) samples."""
        p = self.config.dropout_probability
        if p == 0.0:
            return np.iinfo(np.int64).max
        lost_mean = max(self.config.dropout_mean_length * self.config.rate_hz, 1.0)
        mean = lost_mean if self._lost else lost_mean * (1.0 - p) / p
        return int(self._drops.geometric(min(1.0, 1.0 / max(mean, 1.0))))

    def push(self, times: np.ndarray, truth: np.ndarray) -> Samples:
        """
        Take a block of truth frames; return the samples the sensor records in it.

        Parameters
        ----------
        times : numpy.ndarray
            (n,) the frames' times (s).
        truth : numpy.ndarray
            (n, axes) the true values at those frames.

        """
        truth = np.asarray(truth, dtype=float).reshape(len(times), self.n_axes)
        if self._zi is None:   # the logger has run long before: its filter rests on the truth
            if not len(times):
                return self._nothing()
            self._zi = signal.sosfilt_zi(self.filter.sos)[:, :, None] * truth[0][None, None, :]
        filtered, self._zi = signal.sosfilt(self.filter.sos, truth, axis=0, zi=self._zi)
        first = (-self._frames) % self.q
        self._frames += len(times)
        picked = np.arange(first, len(times), self.q)
        values = filtered[picked] + self._bias(len(picked))
        if self.sigma > 0.0:
            values = values + self.sigma * self._noise.standard_normal(values.shape)
        cfg = self.config
        if cfg.resolution > 0.0:
            values = cfg.resolution * np.round(values / cfg.resolution)
        clipped = np.zeros(len(picked), dtype=bool)
        if cfg.full_scale > 0.0:
            clipped = np.any(np.abs(values) > cfg.full_scale, axis=1)
            values = np.clip(values, -cfg.full_scale, cfg.full_scale)
        clock = np.asarray(times)[picked] * (1.0 + 1e-6 * cfg.clock_drift) + cfg.clock_offset
        stamps = np.round(clock * 1e9).astype(np.int64)
        kept = self._kept(len(picked)) & (stamps >= 0)
        return Samples(stamps_ns=stamps[kept], values=values[kept],
                       dropped=int(np.count_nonzero(~kept)),
                       clipped=int(np.count_nonzero(clipped[kept])))

    def _nothing(self) -> Samples:
        return Samples(np.zeros(0, dtype=np.int64), np.zeros((0, self.n_axes)), 0, 0)

    def _bias(self, n: int) -> np.ndarray:
        """Return the bias of the next n samples: constant plus its random walk."""
        if self.config.bias_walk == 0.0 or n == 0:
            return np.full((n, self.n_axes), self.config.bias)
        step = self.config.bias_walk / math.sqrt(self.config.rate_hz)
        path = self._walked + np.cumsum(step * self._walk.standard_normal((n, self.n_axes)),
                                        axis=0)
        self._walked = path[-1].copy()
        return self.config.bias + path

    def _kept(self, n: int) -> np.ndarray:
        """Return which of the next n samples survive the dropouts (runs drawn as needed)."""
        kept = np.ones(n, dtype=bool)
        at = 0
        while at < n:
            take = min(self._left, n - at)
            if self._lost:
                kept[at:at + take] = False
            at += take
            self._left -= take
            if self._left == 0:
                self._lost = not self._lost
                self._left = self._run_length()
        return kept
