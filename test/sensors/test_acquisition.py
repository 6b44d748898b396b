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

"""The acquisition chain of a sensor: filter, decimation, noise, bias, quantisation, dropouts."""

import math

import numpy as np
import pytest
from scipy import signal

from ttb_sim.config.sensor_records import decimation_factor, SensorConfig, SensorError
from ttb_sim.sensors.acquisition import Acquisition, design_anti_alias

FRAME_RATE = 1000.0


def sensor(**keys):
    return SensorConfig(**{'name': 'probe', 'type': 'accelerometer', 'at': 'girder@0',
                           'rate_hz': 200.0, **keys})


def through(config, truth, block):
    """Return (stamps, values, dropped) of a truth (n, axes) pushed in blocks of ``block``."""
    chain = Acquisition(config, FRAME_RATE, truth.shape[1])
    times = np.arange(len(truth)) / FRAME_RATE
    parts = [chain.push(times[i:i + block], truth[i:i + block])
             for i in range(0, len(truth), block)]
    return (np.concatenate([p.stamps_ns for p in parts]),
            np.concatenate([p.values for p in parts]), sum(p.dropped for p in parts))


def test_rate_must_divide_the_frame_rate_by_an_integer_of_two_or_more():
    assert decimation_factor(1000.0, sensor(rate_hz=200.0)) == 5
    assert decimation_factor(1000.0, sensor(rate_hz=500.0)) == 2
    for rate in (1000.0, 300.0, 2000.0):
        with pytest.raises(SensorError, match=rf'rate_hz = {rate:g} does not divide'):
            decimation_factor(1000.0, sensor(rate_hz=rate))


def test_filter_meets_its_pass_band_and_stop_band():
    config = sensor(passband=0.8, stopband_attenuation=70.0)
    aa = design_anti_alias(config, FRAME_RATE)
    f = np.linspace(0.0, aa.passband_hz, 50)
    gain = np.abs(aa.response(f, FRAME_RATE))
    assert np.all(gain <= 1.0 + 1e-9) and np.all(20 * np.log10(gain) >= -0.1 - 1e-6)
    stop = np.abs(aa.response(np.linspace(aa.stopband_hz, FRAME_RATE / 2, 200), FRAME_RATE))
    assert np.all(20 * np.log10(stop) <= -70.0 + 1e-6)


def test_blocks_of_any_size_give_the_same_bits():
    rng = np.random.default_rng(3)
    truth = rng.normal(size=(5003, 3))
    config = sensor(axes='xyz', noise_density=1e-3, bias=0.01, bias_walk=1e-3,
                    resolution=1e-4, full_scale=2.0, dropout_probability=0.2,
                    dropout_mean_length=0.02, clock_offset=0.003)
    reference = through(config, truth, len(truth))
    for block in (1, 7, 256):
        got = through(config, truth, block)
        assert np.array_equal(got[0], reference[0])
        assert np.array_equal(got[1], reference[1])
        assert got[2] == reference[2]


def test_seed_sets_the_noise_and_the_name_seeds_it_by_default():
    truth = np.zeros((4000, 1))
    a = through(sensor(noise_density=1e-3, seed=5), truth, 100)[1]
    b = through(sensor(noise_density=1e-3, seed=5, name='other'), truth, 100)[1]
    c = through(sensor(noise_density=1e-3, seed=6), truth, 100)[1]
    d = through(sensor(noise_density=1e-3, name='other'), truth, 100)[1]
    e = through(sensor(noise_density=1e-3), truth, 100)[1]
    assert np.array_equal(a, b) and not np.array_equal(a, c) and not np.array_equal(d, e)


def test_white_noise_has_the_density_asked_for():
    density = 2e-4
    values = through(sensor(noise_density=density), np.zeros((400_000, 1)), 4096)[1][:, 0]
    f, psd = signal.welch(values, fs=200.0, nperseg=256)
    band = (f > 1.0) & (f < 95.0)
    assert math.sqrt(np.mean(psd[band])) == pytest.approx(density, rel=0.03)
    assert np.std(values) == pytest.approx(density * math.sqrt(100.0), rel=0.02)


def test_a_constant_passes_unchanged_from_the_first_sample():
    values = through(sensor(axes='xz'), np.full((3000, 2), [0.5, -2.0]), 64)[1]
    assert np.allclose(values, [0.5, -2.0], rtol=0, atol=1e-12)


def test_quantisation_and_clipping():
    truth = np.linspace(-3.0, 3.0, 20_000)[:, None]
    chain = Acquisition(sensor(resolution=0.25, full_scale=2.0, passband=0.5), FRAME_RATE, 1)
    out = chain.push(np.arange(len(truth)) / FRAME_RATE, truth)
    assert np.all(np.abs(out.values) <= 2.0)
    assert np.allclose(out.values / 0.25, np.round(out.values / 0.25))
    assert 0 < out.clipped < len(out.values)


def test_clock_offset_shifts_the_stamps_and_drops_the_negative_ones():
    truth = np.zeros((1000, 1))
    stamps = through(sensor(clock_offset=0.0123), truth, 100)[0]
    assert stamps[0] == 12_300_000 and np.all(np.diff(stamps) == 5_000_000)
    late, _, dropped = through(sensor(clock_offset=-0.0123), truth, 100)
    assert late[0] == 2_700_000 and dropped == 3


def test_clock_drift_stretches_the_stamps_by_its_ppm():
    """100 ppm: 5 ms samples stamped 5.0005 ms apart; the samples themselves are unchanged."""
    rng = np.random.default_rng(5)
    truth = rng.normal(size=(4000, 1))
    stamps, values, _ = through(sensor(clock_drift=100.0, clock_offset=0.001), truth, 333)
    plain_stamps, plain_values, _ = through(sensor(), truth, 333)
    assert np.array_equal(values, plain_values)
    assert np.all(np.abs(np.diff(stamps) - 5_000_500) <= 1)
    expected = np.round(plain_stamps * (1 + 1e-4) + 1_000_000).astype(np.int64)
    assert np.all(np.abs(stamps - expected) <= 1)


def test_dropouts_lose_the_fraction_asked_in_runs_of_the_mean_length():
    p, mean = 0.25, 0.05
    stamps, _, dropped = through(sensor(dropout_probability=p, dropout_mean_length=mean),
                                 np.zeros((2_000_000, 1)), 50_000)
    assert dropped / (dropped + len(stamps)) == pytest.approx(p, rel=0.05)
    gaps = np.diff(stamps) // 5_000_000 - 1
    gaps = gaps[gaps > 0]
    assert np.mean(gaps) / 200.0 == pytest.approx(mean, rel=0.05)


def test_bias_and_its_walk():
    n = 400_000
    out = through(sensor(bias=0.3), np.zeros((n, 1)), 10_000)[1]
    assert np.all(out == pytest.approx(0.3, abs=1e-12))
    walk = through(sensor(bias_walk=2e-3), np.zeros((n, 1)), 10_000)[1][:, 0]
    assert np.std(np.diff(walk)) == pytest.approx(2e-3 / math.sqrt(200.0), rel=0.01)
