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
The sensors of a run: the truth of every sensor gathered from the frames, then acquired.

:class:`SensorBank` keeps the frames' flat rows for a block (:data:`BLOCK_FRAMES`),
takes each sensor's truth columns from them (the difference of two places for a
``relative_to`` displacement) and passes them through the sensor's
:class:`~ttb_sim.sensors.acquisition.Acquisition`. Blocks of any size give the same
samples; the node and ``ttb-sim run`` use the same bank.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, Sequence

import numpy as np

from ttb_sim.config.sensor_places import gauge_requests, probe_requests
from ttb_sim.config.sensor_records import SensorConfig, SensorError
from ttb_sim.errors import ScenarioError
from ttb_sim.sensors.acquisition import Acquisition, Samples
from ttb_sim.sensors.locations import truth_columns
from ttb_sim.sim import Frame, Layout

__all__ = ['BLOCK_FRAMES', 'SensorBank', 'SensorChannel']

BLOCK_FRAMES = 256
"""Frames kept before the sensors process them (the samples' latency, in frames)."""


@dataclass
class SensorChannel:
    """One sensor of a bank: its record, truth columns and acquisition chain, and its counts."""

    config: SensorConfig
    columns: np.ndarray
    relative: np.ndarray | None
    acquisition: Acquisition
    published: int = 0
    dropped: int = 0
    clipped: int = 0

    def record(self, times: np.ndarray, rows: np.ndarray) -> Samples:
        """Return the samples of a block of frame rows (and count them)."""
        truth = rows[:, self.columns]
        if self.relative is not None:
            truth = truth - rows[:, self.relative]
        samples = self.acquisition.push(times, truth)
        self.published += len(samples.stamps_ns)
        self.dropped += samples.dropped
        self.clipped += samples.clipped
        return samples

    def describe(self) -> dict[str, Any]:
        """Return the sensor for ``summary.json``: what, where, chain, counts."""
        c, acq = self.config, self.acquisition
        aa = acq.filter
        delay = aa.group_delay(0.1 * c.rate_hz / 2.0, acq.frame_rate)
        return {'name': c.name, 'type': c.type, 'at': c.at, 'relative_to': c.relative_to,
                'axes': c.measured_axes, 'unit': c.unit, 'rate_hz': c.rate_hz,
                'decimation': acq.q, 'seed': c.rng_seed,
                'anti_alias': {'type': 'chebyshev2', 'order': aa.order,
                               'passband_hz': aa.passband_hz, 'stopband_hz': aa.stopband_hz,
                               'attenuation_db': aa.attenuation_db,
                               'group_delay_s': delay},
                'noise_std': acq.sigma, 'noise_density': c.noise_density, 'bias': c.bias,
                'bias_walk': c.bias_walk, 'resolution': c.resolution,
                'full_scale': c.full_scale, 'dropout_probability': c.dropout_probability,
                'clock_offset': c.clock_offset,
                'clock_drift_ppm': c.clock_drift, 'samples_published': self.published,
                'samples_dropped': self.dropped, 'samples_clipped': self.clipped}


class SensorBank:
    """
    All sensors of a run over its frames.

    Parameters
    ----------
    sensors : sequence of SensorConfig
        The scenario's ``sensors``.
    layout : Layout
        The run's frame layout (its ``probes`` from the same sensors).
    frame_rate : float
        Frames per second of simulation time.
    block : int
        Frames kept before they are processed.

    Raises
    ------
    ScenarioError
        Naming ``sensors[i]`` when a sensor's place is not in the model or its rate
        does not divide the frame rate.

    """

    def __init__(self, sensors: Sequence[SensorConfig], layout: Layout, frame_rate: float,
                 block: int = BLOCK_FRAMES) -> None:
        requests = probe_requests(sensors)
        if len(requests) != layout.probes:
            raise ScenarioError(f'the model evaluates {layout.probes} beam-line probes; the '
                                f'sensors read {len(requests)} (a substructure alone has '
                                'no beam lines: sensors at girder@x, rail_left@x ... need a '
                                'train run)')
        gauges = gauge_requests(sensors)
        if len(gauges) != layout.pile_gauges:
            raise ScenarioError(f'the model evaluates {layout.pile_gauges} pile strain gauges; '
                                f'the sensors read {len(gauges)}')
        self.channels: list[SensorChannel] = []
        for i, config in enumerate(sensors):
            try:
                at, relative = truth_columns(config, layout, requests, gauges)
                acquisition = Acquisition(config, frame_rate, len(at))
            except (SensorError, ScenarioError) as exc:
                raise ScenarioError(f'sensors[{i}]: {exc}') from None
            self.channels.append(SensorChannel(config, at, relative, acquisition))
        self.block = max(1, int(block))
        self._rows: list[np.ndarray] = []
        self._times: list[float] = []

    @classmethod
    def of_run(cls, sensors: Sequence[SensorConfig], layout: Layout, dt: float,
               output_every: int, block: int = BLOCK_FRAMES) -> SensorBank:
        """Return the bank of a runner's frames (frame rate 1 / (output_every dt))."""
        rate = 1.0 / (output_every * dt)
        nice = round(rate)   # a frame rate of 1 kHz computed as 999.9999999 is 1 kHz
        return cls(sensors, layout, float(nice) if math.isclose(rate, nice) else rate, block)

    def push(self, frame: Frame) -> list[tuple[int, Samples]]:
        """Keep one frame; when a block is full, return each sensor's samples of it."""
        self._rows.append(frame.row)
        self._times.append(frame.time)
        if len(self._rows) < self.block:
            return []
        return self.flush()

    def flush(self) -> list[tuple[int, Samples]]:
        """Process the frames kept; return (sensor index, samples) of sensors with samples."""
        if not self._rows:
            return []
        rows, times = np.stack(self._rows), np.asarray(self._times)
        self._rows, self._times = [], []
        out = []
        for i, channel in enumerate(self.channels):
            samples = channel.record(times, rows)
            if len(samples.stamps_ns):
                out.append((i, samples))
        return out

    def describe(self) -> list[dict[str, Any]]:
        """Return every sensor's description and counts (``summary.json``'s ``sensors``)."""
        return [c.describe() for c in self.channels]
