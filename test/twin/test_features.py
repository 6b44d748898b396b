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


"""Features of a channel: the PSD level, the tone, the RMS and peak, gaps bridged."""

import numpy as np
import pytest
from ttb_sim.errors import ScenarioError
from ttb_sim.twin import channel_features, FeatureSpec

RATE = 200.0


def test_white_noise_psd_equals_its_density():
    density = 3.0e-4   # unit/sqrt(Hz), one-sided
    n = int(400 * RATE)
    t = np.arange(n) / RATE
    x = np.random.default_rng(4).normal(0.0, density * np.sqrt(RATE / 2.0), n)
    grid = FeatureSpec(psd_fmin_hz=1.0, psd_fmax_hz=90.0, psd_points=40).frequencies()
    scalars, psd = channel_features(t, x, RATE, grid, segment_s=2.0)
    level = density ** 2
    assert abs(np.mean(psd) / level - 1.0) < 0.03
    assert np.all(np.abs(psd / level - 1.0) < 0.35)   # 400 segments: each bin within 35 %
    assert scalars['rms'] == pytest.approx(density * np.sqrt(RATE / 2.0), rel=0.01)


def test_a_tone_peaks_at_its_frequency_with_its_power():
    t = np.arange(int(60 * RATE)) / RATE
    x = 0.5 + 2.0 * np.sin(2 * np.pi * 12.5 * t)
    grid = np.linspace(1.0, 99.0, 197)
    scalars, psd = channel_features(t, x, RATE, grid, segment_s=4.0)
    assert grid[np.argmax(psd)] == pytest.approx(12.5, abs=0.5)
    assert scalars['mean'] == pytest.approx(0.5, abs=1e-3)
    assert scalars['rms'] == pytest.approx(2.0 / np.sqrt(2.0), rel=1e-3)
    assert scalars['peak'] == pytest.approx(2.5, rel=1e-3)
    # the tone's power, summed over the bins of Welch's own resolution, is A^2 / 2
    from scipy.signal import welch
    f, pxx = welch(x, fs=RATE, nperseg=int(4 * RATE))
    assert np.sum(pxx[np.abs(f - 12.5) < 1.0]) * (f[1] - f[0]) == pytest.approx(2.0, rel=0.02)


def test_lost_samples_are_bridged_and_the_level_kept():
    t = np.arange(int(100 * RATE)) / RATE
    x = np.sin(2 * np.pi * 5.0 * t)
    keep = np.ones(len(t), bool)
    for start in np.random.default_rng(2).integers(0, len(t) - 20, 30):
        keep[start:start + 10] = False   # 30 gaps of 50 ms
    grid = np.array([5.0])
    full, psd_full = channel_features(t, x, RATE, grid, 2.0)
    gappy, psd_gappy = channel_features(t[keep], x[keep], RATE, grid, 2.0)
    assert gappy['rms'] == pytest.approx(full['rms'], rel=0.02)
    assert psd_gappy[0] == pytest.approx(psd_full[0], rel=0.05)


def test_grid_points_above_nyquist_are_nan_and_short_records_give_nan():
    t = np.arange(1000) / 50.0
    _, psd = channel_features(t, np.sin(t), 50.0, np.array([10.0, 24.0, 26.0, 40.0]), 2.0)
    assert np.isfinite(psd[:2]).all() and np.isnan(psd[2:]).all()
    scalars, psd = channel_features(t[:3], np.ones(3), 50.0, np.array([1.0]), 2.0)
    assert np.isnan(scalars['rms']) and np.isnan(psd).all()


def test_an_empty_grid_is_refused():
    with pytest.raises(ScenarioError, match='psd_fmin_hz = 60 must be below'):
        FeatureSpec(psd_fmin_hz=60.0, psd_fmax_hz=50.0)
