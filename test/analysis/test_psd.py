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
Tests of the PSD tools for V19 on synthetic records with known answers.

Every expected value is written in closed form here (variance, sine
frequency, step frequency of a prescribed spectrum, transmissibility maximum
of a base-excited oscillator); none is taken from ``ttb_sim.analysis.psd``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from ttb_sim.analysis import psd

V19_STEP_HZ = 83.3              # V / lambda = (300 / 3.6 m/s) / 1 m
V19_CAR_BODY_HZ = 0.84          # car-body vertical natural frequency (paper section 4.1)


def band_limited_record(rng: np.random.Generator, sample_rate: float, seconds: float,
                        density) -> np.ndarray:
    """
    Return a Gaussian record whose one-sided PSD is ``density(f)``, built by inverse FFT.

    With N samples, bin k at f_k = k fs / N gets a complex Gaussian coefficient
    with E|X_k|^2 = S(f_k) fs N / 2, so that the variance (2 / N^2) sum |X_k|^2
    equals sum S(f_k) df, the integral of the PSD.
    """
    n = int(round(sample_rate * seconds))
    f = np.fft.rfftfreq(n, 1.0 / sample_rate)
    amplitude = np.sqrt(density(f) * sample_rate * n / 2.0)
    coefficients = amplitude * (rng.standard_normal(f.size)
                                + 1j * rng.standard_normal(f.size)) / math.sqrt(2.0)
    coefficients[0] = 0.0
    coefficients[-1] = coefficients[-1].real
    return np.fft.irfft(coefficients, n)


def stepped_density(step_hz: float, ratio: float, exponent: float = 0.0,
                    lo: float = 5.0, hi: float = 1000.0):
    """Return S(f) = (f / step_hz)^-exponent on [lo, hi], times ratio for f >= step_hz."""
    def density(f: np.ndarray) -> np.ndarray:
        inside = (f >= lo) & (f <= hi)
        s = np.zeros_like(f)
        s[inside] = (f[inside] / step_hz) ** -exponent
        return np.where(f >= step_hz, ratio * s, s)
    return density


# --- white noise: flat PSD, Parseval -----------------------------------------------------

@pytest.mark.parametrize('seed', [0, 1, 2])
def test_white_noise_is_flat_at_two_sigma2_over_fs_and_integrates_to_the_variance(seed):
    fs, sigma, n = 500.0, 2.5, 2 ** 17
    x = sigma * np.random.default_rng(seed).standard_normal(n)
    f, p = psd.welch_psd(x, fs, segment_seconds=2.048)
    df = f[1] - f[0]
    assert df == pytest.approx(fs / 1024)
    # Parseval: the integral of the PSD is the mean square of the detrended record
    # (within 1 %: Hann weighting of the segments), and the population variance within
    # 3 % (the sample variance of 2^17 samples scatters by sqrt(2 / n) = 0.4 %).
    assert np.sum(p) * df == pytest.approx(np.var(x), rel=0.01)
    assert np.sum(p) * df == pytest.approx(sigma ** 2, rel=0.03)
    # Flat one-sided level 2 sigma^2 / fs: the mean over each fifth of the band within
    # 5 % (each fifth averages ~100 bins of 255 overlapping segments, scatter ~0.5 %).
    level = 2.0 * sigma ** 2 / fs
    inner = p[1:-1]
    for part in np.array_split(inner, 5):
        assert np.mean(part) == pytest.approx(level, rel=0.05)


def test_default_welch_uses_seven_half_overlapping_hann_segments():
    # n = 4 L samples, segments of L starting every L / 2.  An impulse at sample L sits at
    # the centre (weight 1) of the segment starting at L / 2 and at the zero end of the
    # periodic Hann window of the segment starting at L; no other segment holds it.  So
    # p = 2 A^2 / (fs sum(w^2) K) with sum(w^2) = 3 L / 8 and K = 7 segments, flat.
    fs, seg, amplitude = 100.0, 64, 3.0
    x = np.zeros(4 * seg)
    x[seg] = amplitude
    f, p = psd.welch_psd(x, fs, detrend=False)
    assert f[1] - f[0] == pytest.approx(fs / seg)
    expected = 2.0 * amplitude ** 2 / (fs * (3.0 * seg / 8.0) * 7)
    np.testing.assert_allclose(p[1:-1], expected, rtol=1e-12)


def test_padded_periodogram_keeps_parseval_and_refines_the_bins():
    fs, n = 200.0, 2000
    x = np.random.default_rng(7).standard_normal(n)
    f, p = psd.padded_periodogram(x, fs, pad_factor=8)
    assert f[1] - f[0] <= fs / (8 * n) + 1e-12
    # Zero padding interpolates; the integral stays the Hann-weighted mean square of the
    # mean-removed record, sum((w x)^2) / sum(w^2) with the periodic Hann window w
    # (Parseval on the padded FFT, exact to rounding).
    hann = 0.5 - 0.5 * np.cos(2.0 * math.pi * np.arange(n) / n)
    weighted = np.sum((hann * (x - x.mean())) ** 2) / np.sum(hann ** 2)
    assert np.sum(p) * (f[1] - f[0]) == pytest.approx(weighted, rel=1e-9)


# --- sine: peak frequency to a fraction of a bin -----------------------------------------

@pytest.mark.parametrize('offset', np.linspace(0.0, 1.0, 9))
def test_sine_peak_frequency_within_five_hundredths_of_a_bin(offset):
    fs, seconds, segment = 1000.0, 8.0, 1.0
    df = 1.0 / segment
    f0 = 37.0 + offset * df
    t = np.arange(int(fs * seconds)) / fs
    x = 1.5 * np.sin(2.0 * math.pi * f0 * t + 0.3)
    f, p = psd.welch_psd(x, fs, segment_seconds=segment)
    assert f[1] - f[0] == pytest.approx(df)
    assert abs(psd.peak_frequency(f, p, band=(20.0, 60.0)) - f0) < 0.05 * df
    # The power of the line (amplitude^2 / 2) is the integral of its PSD lobe.
    lobe = (f > f0 - 4 * df) & (f < f0 + 4 * df)
    assert np.sum(p[lobe]) * df == pytest.approx(1.5 ** 2 / 2, rel=0.01)


def test_sine_in_a_short_record_located_by_the_padded_periodogram():
    fs, seconds = 200.0, 10.0
    f0 = 0.8437                  # between the 0.1 Hz bins of the unpadded record
    t = np.arange(int(fs * seconds)) / fs
    f, p = psd.padded_periodogram(np.sin(2.0 * math.pi * f0 * t), fs, pad_factor=8)
    bin_width = f[1] - f[0]
    assert bin_width <= 0.1 / 8 + 1e-12
    # The image at -f0 leaks into a 0.84 Hz line of a 10 s record, hence 0.1 bin.
    assert abs(psd.peak_frequency(f, p, band=(0.3, 3.0)) - f0) < 0.1 * bin_width


def test_peak_frequency_of_a_nonuniform_grid_is_the_vertex_of_the_log_parabola():
    f = np.array([1.0, 1.7, 2.0, 2.6, 4.0])
    vertex, width = 2.2, 0.8
    p = np.exp(-((f - vertex) / width) ** 2)
    assert psd.peak_frequency(f, p) == pytest.approx(vertex, rel=1e-12)
    assert psd.peak_frequency(f, p, fit_bins=5) == pytest.approx(vertex, rel=1e-12)


def test_peak_frequency_at_a_band_edge_that_rises_outside_is_not_refined():
    f = np.linspace(0.0, 10.0, 11)
    p = np.exp(-((f - 8.0) / 2.0) ** 2)
    assert psd.peak_frequency(f, p, band=(1.0, 5.0)) == 5.0


# --- level step of the V19 kind ---------------------------------------------------------

@pytest.mark.parametrize('seed', [0, 1, 2, 3])
def test_tenfold_drop_at_83_3_hz_found_within_5_percent(seed):
    fs, seconds = 10_000.0, 8.0
    x = band_limited_record(np.random.default_rng(seed), fs, seconds,
                            stepped_density(V19_STEP_HZ, 0.1))
    f, p = psd.welch_psd(x, fs)
    df = f[1] - f[0]
    assert df == pytest.approx(4.0 / seconds)            # default: quarter-record segments
    found = psd.level_change_frequency(f, p, band=(20.0, 300.0), direction='down')
    assert found == pytest.approx(V19_STEP_HZ, rel=0.05)   # the V19 criterion
    # Documented resolution ~1 bin, plus noise (200 seeds: -0.1 .. +1.9 bins).
    assert abs(found - V19_STEP_HZ) <= 3.0 * df
    assert psd.level_change_frequency(f, p, band=(20.0, 300.0)) == found


@pytest.mark.parametrize('seed', [0, 1, 2, 3])
def test_rise_on_a_power_law_background_found_within_5_percent(seed):
    # Background f^-3 (an irregularity displacement PSD) rising 10x at 83.3 Hz: a
    # mean-level comparison would be swamped by the slope; the power-law fits are not.
    fs, seconds = 10_000.0, 8.0
    x = band_limited_record(np.random.default_rng(seed), fs, seconds,
                            stepped_density(V19_STEP_HZ, 10.0, exponent=3.0))
    f, p = psd.welch_psd(x, fs)
    for direction in ('up', 'either'):
        # 200 seeds: -1.1 .. +4.9 bins of 0.5 Hz, at most 2.9 %.
        found = psd.level_change_frequency(f, p, band=(20.0, 300.0), direction=direction)
        assert found == pytest.approx(V19_STEP_HZ, rel=0.05)


@pytest.mark.parametrize('seed', [0, 1, 2, 3])
def test_chinese_to_sato_rise_with_the_paper_window_found_within_5_percent(seed):
    # The V19 situation: a 2.7x rise at 83.3 Hz on an f^-3 background, Welch with the
    # paper's 20 m window at 300 km/h (0.24 s, 4.17 Hz bins, ~65 segments in 8 s).
    fs, seconds, segment = 10_000.0, 8.0, 20.0 / (300.0 / 3.6)
    x = band_limited_record(np.random.default_rng(seed), fs, seconds,
                            stepped_density(V19_STEP_HZ, 2.7, exponent=3.0))
    f, p = psd.welch_psd(x, fs, segment_seconds=segment)
    df = f[1] - f[0]
    assert df == pytest.approx(fs / round(segment * fs))
    found = psd.level_change_frequency(f, p, band=(20.0, 300.0), direction='up')
    assert found == pytest.approx(V19_STEP_HZ, rel=0.05)
    assert abs(found - V19_STEP_HZ) <= df                  # 200 seeds: within 0.51 bin


def test_level_change_of_an_exact_step_is_the_bin_boundary():
    f = np.arange(1.0, 201.0)
    p = 1e-3 * f ** -2.5 * np.where(f > 120.0, 0.2, 1.0)
    assert psd.level_change_frequency(f, p, window_bins=10) == 120.5
    assert psd.level_change_frequency(f, p, window_bins=10, direction='down') == 120.5


# --- base-excited SDOF: car-body acceleration peak ----------------------------------------

def transmissibility_peak_hz(natural_hz: float, damping_ratio: float) -> float:
    """
    Return the frequency of the maximum of |T|, T = (k + i c w) / (k - m w^2 + i c w).

    d|T|^2/dr = 0 with r = f / fn gives 2 zeta^2 r^4 + r^2 - 1 = 0, so
    r^2 = (sqrt(1 + 8 zeta^2) - 1) / (4 zeta^2).
    """
    z2 = damping_ratio ** 2
    return natural_hz * math.sqrt((math.sqrt(1.0 + 8.0 * z2) - 1.0) / (4.0 * z2))


@pytest.mark.parametrize('seed', [0, 1])
def test_car_body_acceleration_psd_peaks_at_the_transmissibility_maximum(seed):
    """
    Absolute acceleration of a base-excited SDOF driven by white base acceleration.

    With z = x - x_b:  z'' + 2 zeta w z' + w^2 z = -x_b'', and the body acceleration
    x'' = -(2 zeta w z' + w^2 z) = T(w) x_b''.  Under white base acceleration the PSD of
    x'' is |T|^2 times a constant, whose maximum is at transmissibility_peak_hz
    (0.781 Hz for fn = 0.84 Hz, zeta = 0.3): neither fn (7.5 % higher) nor the damped
    frequency fn sqrt(1 - zeta^2) = 0.801 Hz.

    A single 10 s record places this broad peak (|T|^2 drops only 2 % at +-5 %) with a
    scatter of about 25 %, measured over 100 seeds; so the PSDs of 1024 independent
    10 s records at 200 Hz (like 1024 passages) are averaged.  Welch with 5 s segments
    (0.2 Hz bins) then gives a mean error of -1.7 % (Hann smoothing of the peak) and a
    scatter of 0.6 %, tested against 5 %.
    """
    fn, zeta, fs, seconds, records = V19_CAR_BODY_HZ, 0.3, 200.0, 10.0, 1024
    omega = 2.0 * math.pi * fn
    system = ([2.0 * zeta * omega, omega ** 2], [1.0, 2.0 * zeta * omega, omega ** 2])
    b, a, _ = signal.cont2discrete(system, 1.0 / fs, method='zoh')   # exact for held input
    n = int(fs * seconds)
    base = np.random.default_rng(seed).standard_normal((records, 2 * n))
    body = signal.lfilter(np.ravel(b), a, base, axis=-1)[:, n:]       # drop 10 s start-up
    spectra = [psd.welch_psd(record, fs, segment_seconds=5.0) for record in body]
    f = spectra[0][0]
    mean_psd = np.mean([p for _, p in spectra], axis=0)

    expected = transmissibility_peak_hz(fn, zeta)
    assert expected == pytest.approx(0.7814, abs=1e-4)
    found = psd.peak_frequency(f, mean_psd, band=(0.2, 3.0))
    assert found == pytest.approx(expected, rel=0.05)
    assert abs(found - expected) < abs(found - fn)


# --- input validation --------------------------------------------------------------------

@pytest.mark.parametrize('kwargs, match', [
    ({'signal': np.ones((4, 4))}, 'signal must be a 1-D array'),
    ({'signal': np.ones(5)}, 'signal must have at least 8 samples, got 5'),
    ({'signal': np.r_[np.ones(20), np.nan]}, 'signal must be finite, got nan at sample 20'),
    ({'sample_rate': 0.0}, 'sample_rate must be a finite number > 0, got 0.0'),
    ({'sample_rate': math.inf}, 'sample_rate must be a finite number > 0'),
    ({'segment_seconds': 5.0}, r'segment_seconds must give between 8 and 100 samples'),
    ({'segment_seconds': 0.01}, r'got 0.01 s = 1 samples'),
    ({'detrend': 'quadratic'}, "detrend must be one of 'constant', 'linear' or False"),
])
def test_welch_psd_rejects_bad_input_naming_the_argument(kwargs, match):
    arguments = {'signal': np.ones(100), 'sample_rate': 100.0, **kwargs}
    with pytest.raises(ValueError, match=match):
        psd.welch_psd(**arguments)


def test_padded_periodogram_rejects_a_bad_pad_factor():
    with pytest.raises(ValueError, match='pad_factor must be an integer >= 1, got 0'):
        psd.padded_periodogram(np.ones(100), 100.0, pad_factor=0)


@pytest.mark.parametrize('kwargs, match', [
    ({'p': np.ones(4)}, 'f and p must be 1-D arrays of the same length'),
    ({'p': -np.ones(5)}, 'p must be >= 0'),
    ({'f': np.array([0.0, 2.0, 1.0, 3.0, 4.0])}, 'f must be strictly increasing'),
    ({'band': (3.0, 1.0)}, 'band must satisfy lo < hi'),
    ({'band': (10.0, 20.0)}, r'band \(10.0, 20.0\) Hz holds no bin'),
    ({'fit_bins': 4}, 'fit_bins must be an odd integer >= 3, got 4'),
])
def test_peak_frequency_rejects_bad_input_naming_the_argument(kwargs, match):
    arguments = {'f': np.arange(5.0), 'p': np.ones(5), **kwargs}
    with pytest.raises(ValueError, match=match):
        psd.peak_frequency(**arguments)


@pytest.mark.parametrize('kwargs, match', [
    ({'window_bins': 2}, 'window_bins must be an integer >= 3, got 2'),
    ({'window_bins': 30}, 'must hold at least 2 \\* window_bins = 60 bins, got 49'),
    ({'direction': 'sideways'}, "direction must be one of 'either', 'down', 'up'"),
    ({'band': (0.0, 10.0)}, 'f and p must be > 0 inside band'),
])
def test_level_change_frequency_rejects_bad_input_naming_the_argument(kwargs, match):
    arguments = {'f': np.arange(0.0, 50.0), 'p': np.ones(50), 'band': (1.0, 50.0), **kwargs}
    with pytest.raises(ValueError, match=match):
        psd.level_change_frequency(**arguments)
