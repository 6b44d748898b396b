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
V24: the virtual sensors — noise, anti-alias filter, decimation, dropouts, strain.

Each row goes through the code users run: a scenario's ``sensors`` through the model
and the :class:`~ttb_sim.sensors.SensorBank` that ``ttb-sim run`` feeds (noise), the
acquisition chain of :mod:`ttb_sim.sensors.acquisition` (filter, decimation, dropouts,
bias walk), and the probe rows of the model's own girder (strain). The references
are independent of the chain: the noise density the sensor is given, a tone's
attenuation required by the issue (60 dB), the filter's frequency response evaluated
in the frequency domain, the dropout fraction asked for, and M c / EI of a simply
supported span.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import signal
import scipy.sparse.linalg as spla

from ttb_sim.config import load_scenario
from ttb_sim.config.sensor_places import probe_requests
from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.sensors.acquisition import Acquisition
from ttb_sim.validation.rows import Case, relative_row, Row

__all__ = ['SENSOR_CASES']

FRAME_RATE = 1000.0
"""Frame rate of the chain's synthetic truth (Hz)."""
SENSOR_RATE = 200.0
"""Rate of the sensors of the rows (Hz)."""
NOISE_DENSITY = 2.2e-4
"""Accelerometer noise density of the noise row (m/s^2/sqrt(Hz), a MEMS sensor)."""
NOISE_TOLERANCE = 0.10
"""The issue's bound on the measured noise density."""
ALIAS_RATIO = 1e-3
"""The issue's bound on an aliased tone: 60 dB down."""
CHAIN_TOLERANCE = 1e-6
"""Decimated samples against the filtered truth, relative to the tone's amplitude."""
STRAIN_TOLERANCE = 1e-6
"""Fibre strain against M c / EI (cubic beam elements are exact under a nodal load)."""
DROPOUT_TOLERANCE = 0.10
"""Measured dropout fraction against the one asked (relative; about 4000 dropouts)."""
WALK_TOLERANCE = 0.02
"""Bias random walk: std of its increments against bias_walk / sqrt(rate) (relative)."""

QUIET_SCENARIO = {
    'name': 'v24_quiet', 'description': 'one span; the force is still 300 m away',
    'train': {'vehicle': 'moving_force', 'speed_kmh': 200.0, 'axle_offsets': [0.0],
              'axle_load': 156960.0, 'start_position': -300.0},
    'bridge': {'n_spans': 1, 'span_length': 32.0},
    'bearings': {'model': 'rigid'}, 'foundation': {'model': 'rigid'},
    'solver': {'duration': 5.0}, 'output': {'rate_hz': FRAME_RATE},
    'sensors': [{'name': 'deck_z', 'type': 'accelerometer', 'at': 'girder@16.0',
                 'axes': ['z'], 'rate_hz': SENSOR_RATE, 'noise_density': NOISE_DENSITY}]}


def noise_density_row() -> Row:
    """Compare the Welch ASD of a girder accelerometer on a quiet span with its density."""
    from ttb_sim.config.schema import from_mapping
    from ttb_sim.config.records import Scenario
    from ttb_sim.sensors import SensorBank
    from ttb_sim.sim import Simulation

    scenario = from_mapping(QUIET_SCENARIO, Scenario)
    sim = Simulation(scenario)
    bank = SensorBank.of_run(scenario.all_sensors, sim.layout, sim.dt, sim.output_every)
    batches = [b for frame in sim.frames() for b in bank.push(frame)] + bank.flush()
    z = np.concatenate([samples.values[:, 0] for _, samples in batches])
    f, psd = signal.welch(z, fs=SENSOR_RATE, nperseg=128)
    band = (f > 2.0) & (f < 0.9 * SENSOR_RATE / 2)
    asd = math.sqrt(float(np.mean(psd[band])))
    return relative_row('V24', 'noise: ASD of a girder accelerometer on a quiet span (Welch)',
                        asd, NOISE_DENSITY, NOISE_TOLERANCE, 'm/s^2/sqrt(Hz)')


def _sensor(**keys: float | str) -> SensorConfig:
    return SensorConfig(**{'name': 'probe', 'type': 'accelerometer', 'at': 'girder@0',
                           'rate_hz': SENSOR_RATE, **keys})  # type: ignore[arg-type]


def _through_chain(config: SensorConfig, truth: np.ndarray, block: int = 97) -> np.ndarray:
    """Return the samples of a (n,) truth at FRAME_RATE through the chain, in blocks."""
    chain = Acquisition(config, FRAME_RATE, 1)
    times = np.arange(truth.size) / FRAME_RATE
    out = [chain.push(times[i:i + block], truth[i:i + block, None]).values[:, 0]
           for i in range(0, truth.size, block)]
    return np.concatenate(out)


def alias_row() -> Row:
    """Return the recorded over the true amplitude of a tone at 1.25 x the sensor's Nyquist."""
    f = 1.25 * SENSOR_RATE / 2
    t = np.arange(int(20 * FRAME_RATE)) / FRAME_RATE
    out = _through_chain(_sensor(), np.sin(2 * math.pi * f * t))
    tail = out[out.size // 2:]            # the filter's start-up left out
    ratio = float(np.sqrt(2.0) * np.std(tail))
    return Row('V24', f'anti-alias: tone at {f:g} Hz (1.25 x Nyquist), recorded / true '
               f'amplitude ({20 * math.log10(max(ratio, 1e-300)):.1f} dB)', ratio, ALIAS_RATIO,
               ratio, ALIAS_RATIO, ratio <= ALIAS_RATIO, '-', 'amplitude ratio')


def decimation_row() -> Row:
    """Compare an in-band tone's samples with the truth filtered in the frequency domain."""
    config = _sensor()
    f = 0.3 * SENSOR_RATE
    t = np.arange(int(10 * FRAME_RATE)) / FRAME_RATE
    out = _through_chain(config, np.sin(2 * math.pi * f * t))
    h = Acquisition(config, FRAME_RATE, 1).filter.response(np.array([f]), FRAME_RATE)[0]
    ts = t[::round(FRAME_RATE / SENSOR_RATE)]
    expected = abs(h) * np.sin(2 * math.pi * f * ts + np.angle(h))
    settled = ts > 2.0
    error = float(np.max(np.abs(out[settled] - expected[settled])))
    return Row('V24', f'decimation: {f:g} Hz tone at {SENSOR_RATE:g} Hz vs the truth times '
               'H(f) (max difference / amplitude)', error, 0.0, error, CHAIN_TOLERANCE,
               error <= CHAIN_TOLERANCE, '-', 'absolute')


def dropout_rows() -> list[Row]:
    """Measure the fraction of samples lost and the bias walk's increments on a zero truth."""
    p, walk = 0.1, 1e-3
    config = _sensor(dropout_probability=p, dropout_mean_length=0.05, bias_walk=walk)
    n = int(2000 * FRAME_RATE)
    chain = Acquisition(config, FRAME_RATE, 1)
    samples = chain.push(np.arange(n) / FRAME_RATE, np.zeros((n, 1)))
    total = len(samples.stamps_ns) + samples.dropped
    lost = samples.dropped / total
    free = Acquisition(_sensor(bias_walk=walk), FRAME_RATE, 1)
    steps = np.diff(free.push(np.arange(n) / FRAME_RATE, np.zeros((n, 1))).values[:, 0])
    return [relative_row('V24', f'dropouts: fraction of samples lost (asked {p:g})', lost, p,
                         DROPOUT_TOLERANCE),
            relative_row('V24', 'bias walk: std of the increments vs bias_walk / sqrt(rate)',
                         float(np.std(steps)), walk / math.sqrt(SENSOR_RATE), WALK_TOLERANCE,
                         'm/s^2')]


def strain_rows() -> list[Row]:
    """Compare soffit strain gauges of a span under a static mid-span load with M c / EI."""
    from ttb_sim.sim import build_structure, probe_rows

    fibre, load = -1.5, 1.0e6
    scenario = load_scenario('moving_force_beam', [], [('sensors', [
        {'name': f'sg_{k}', 'type': 'strain', 'at': f'girder@{x}', 'fibre': [0.0, fibre]}
        for k, x in (('q', 8.0), ('m', 16.0), ('e', 3.0))])])
    st = build_structure(scenario)
    force = np.zeros(st.n_free)
    force[st.midspan_dofs[0, 2]] = -load
    u = spla.spsolve(st.stiffness.tocsc(), force)
    state = np.zeros((3, st.n_free + 1))
    state[0, :-1] = u
    requests = probe_requests(scenario.sensors)
    strain = probe_rows(requests, st).values(state)[:, 0]
    b = scenario.bridge
    rows = []
    for req, eps in zip(requests, strain):
        moment = load * min(req.x, b.span_length - req.x) / 2.0
        reference = -moment * fibre / b.bending_stiffness
        rows.append(relative_row('V24', f'strain gauge on the soffit (z = {fibre:g} m) at x = '
                                 f'{req.x:g} m: vs M c / EI', float(eps) * 1e6,
                                 reference * 1e6, STRAIN_TOLERANCE, 'micro-strain'))
    return rows


def v24() -> list[Row]:
    """Return the rows of V24."""
    return [noise_density_row(), alias_row(), decimation_row(), *dropout_rows(),
            *strain_rows()]


SENSOR_CASES = (Case('V24', 'virtual sensors: noise, anti-alias, decimation, dropouts, '
                     'strain', v24),)
