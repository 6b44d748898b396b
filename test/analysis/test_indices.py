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
Closed-form checks of the analysis metrics on synthetic records of known content.

Every expected value is written here from its definition (sine amplitudes and
frequencies, ISO 2631 tables, PHYSICS.md section 9.6), never read back from
the functions under test: weightings, VAL, Sperling, power flow (V21),
safety indices, deck acceleration, excitation frequencies, rigid displacement.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from ttb_sim.analysis import excitation, levels, power_flow, psd, ride, rigid_displacement, \
    safety, weighting

FS = 1000.0
N = 8000   # 8 s: 1/8 Hz bins, so every tone below is a whole number of periods


def tone(amplitude: float, frequency: float, phase: float = 0.0, n: int = N,
         fs: float = FS) -> np.ndarray:
    t = np.arange(n) / fs
    return amplitude * np.sin(2 * math.pi * frequency * t + phase)


def iso_polynomial_response(f: np.ndarray, f1, f2, f3, f4, q4, f5=None, q5=None, f6=None,
                            q6=None) -> np.ndarray:
    """|H| of the ISO 2631 filter chain from numerator/denominator polynomials (scipy.freqs)."""
    w = [2 * math.pi * x if x else None for x in (f1, f2, f3, f4, f5, f6)]
    num, den = np.array([1.0, 0, 0]), np.array([1.0, math.sqrt(2) * w[0], w[0]**2])
    num = np.polymul(num, [w[1]**2])
    den = np.polymul(den, [1.0, math.sqrt(2) * w[1], w[1]**2])
    num = np.polymul(num, [1 / w[2], 1.0])
    den = np.polymul(den, [1 / w[3]**2, 1 / (q4 * w[3]), 1.0])
    if f5:
        num = np.polymul(num, np.array([1 / w[4]**2, 1 / (q5 * w[4]), 1.0]) * (w[4] / w[5])**2)
        den = np.polymul(den, [1 / w[5]**2, 1 / (q6 * w[5]), 1.0])
    _, h = signal.freqs(num, den, worN=2 * math.pi * np.asarray(f, dtype=float))
    return np.abs(h)


WK = (0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91)
WD = (0.4, 100.0, 2.0, 2.0, 0.63)
WM = (0.7943, 100.0, 5.684, 5.684, 0.5)


@pytest.mark.parametrize('f, expected', [(1.0, 0.482), (6.3, 1.054), (80.0, 0.132)])
def test_wk_matches_iso_table_v22(f, expected):
    """V22: |Wk| at 1, 6.3 and 80 Hz within 1 % of the ISO 2631-1 table values."""
    value = abs(weighting.weighting_response(f, 'Wk'))
    assert value == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize('name, corners', [('Wk', WK), ('Wd', WD), ('Wm', WM)])
def test_weightings_match_polynomial_form(name, corners):
    f = np.geomspace(0.1, 400.0, 200)
    assert np.allclose(np.abs(weighting.weighting_response(f, name)),
                       iso_polynomial_response(f, *corners), rtol=1e-10)


@pytest.mark.parametrize('name, corners, f0', [('Wk', WK, 5.0), ('Wd', WD, 1.5),
                                               ('Wm', WM, 16.0)])
def test_weighted_rms_of_a_sine(name, corners, f0):
    """A sine of amplitude A at f0 has weighted r.m.s. A / sqrt(2) |W(f0)|."""
    expected = 0.7 / math.sqrt(2) * iso_polynomial_response(np.array([f0]), *corners)[0]
    assert weighting.weighted_rms(tone(0.7, f0), FS, name) == pytest.approx(expected, rel=1e-9)


def test_weighting_refuses_unknown_name():
    with pytest.raises(ValueError, match='Wk'):
        weighting.weighting_response(1.0, 'Wz')


def test_third_octave_bands_are_the_nominal_ones():
    centres, lo, hi = levels.third_octave_bands(1.0, 80.0)
    nominal = [1, 1.25, 1.6, 2, 2.5, 3.15, 4, 5, 6.3, 8, 10, 12.5, 16, 20, 25, 31.5, 40, 50,
               63, 80]
    assert len(centres) == len(nominal)
    assert np.allclose(centres, nominal, rtol=0.02)
    assert np.allclose(hi / lo, 2 ** (1 / 3), rtol=1e-3)   # base-10 thirds: 10^(1/10)
    assert np.allclose(lo[1:], hi[:-1])


def test_val_of_a_sine_and_of_two():
    """A sine of amplitude A gives 20 log10(A / sqrt(2) / 1e-6) dB in its band only."""
    a, f0 = 0.02, 6.25
    centres, val = levels.vibration_levels(tone(a, f0), FS)
    band = int(np.argmin(np.abs(np.log(centres / 6.3))))
    assert val[band] == pytest.approx(20 * math.log10(a / math.sqrt(2) / 1e-6), abs=1e-9)
    assert np.all(val[np.arange(val.size) != band] < val[band] - 200)   # no leakage
    both = tone(a, f0) + tone(a, 31.5)
    _, val2 = levels.vibration_levels(both, FS)
    assert levels.total_level(centres, val2) == pytest.approx(val[band] + 10 * math.log10(2),
                                                              abs=1e-9)


def test_band_powers_add_up_to_the_variance():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(N)
    f, p = levels.line_power(x, FS)
    assert p.sum() == pytest.approx(np.var(x), rel=1e-12)
    power, _ = levels.band_sums(f, p, [0.0], [FS])
    assert power[0] == pytest.approx(np.var(x), rel=1e-12)


def test_weighted_total_level_of_one_band():
    centres, val = levels.vibration_levels(tone(0.01, 8.0), FS)
    band = int(np.argmax(val))
    expected = val[band] + 20 * math.log10(iso_polynomial_response(
        np.array([centres[band]]), *WK)[0])
    assert levels.total_level(centres, val, 'Wk') == pytest.approx(expected, abs=1e-6)


@pytest.mark.parametrize('direction, f0, correction', [
    ('vertical', 2.0, 0.325 * 4.0), ('vertical', 10.0, 400 / 100), ('vertical', 30.0, 1.0),
    ('lateral', 1.0, 0.8), ('lateral', 8.0, 650 / 64), ('lateral', 32.0, 1.0)])
def test_sperling_of_a_pure_tone(direction, f0, correction):
    """W = 7.08 (A^3 F(f) / f)^(1/10), A the peak in g (GB 5599-85)."""
    a = 0.15 * 9.81
    expected = 7.08 * ((a / 9.81) ** 3 * correction / f0) ** 0.1
    assert ride.sperling_index(tone(a, f0), FS, direction) == pytest.approx(expected,
                                                                            rel=1e-9)


def test_sperling_combines_bands_as_tenth_power_sum():
    w1 = ride.sperling_index(tone(0.5, 2.0), FS)
    w2 = ride.sperling_index(tone(0.5, 10.0), FS)
    both = ride.sperling_index(tone(0.5, 2.0) + tone(0.5, 10.0), FS)
    assert both == pytest.approx((w1**10 + w2**10) ** 0.1, rel=1e-9)
    assert ride.sperling_grade(2.4) == 'excellent'
    assert ride.sperling_grade(3.2) == 'not acceptable'


def test_power_flow_parseval_v21():
    """V21: the lines sum to the time mean of F v, for any pair of records (0.1 % required)."""
    rng = np.random.default_rng(7)
    for n in (4001, 4000):
        force = rng.standard_normal(n) * 1e4 + 3e3
        velocity = 0.3 * np.roll(force, 3) / 1e4 + rng.standard_normal(n) * 1e-2
        _, p = power_flow.power_flow_spectrum(force, velocity, FS)
        assert p.sum() == pytest.approx(np.mean(force * velocity), rel=1e-10)


def test_power_flow_of_a_known_pair():
    """F = F0 sin(wt), v = V0 sin(wt - phi): one line of F0 V0 cos(phi) / 2 at f."""
    f0, phi = 12.5, 0.7
    freq, p = power_flow.power_flow_spectrum(tone(2e3, f0), tone(0.01, f0, -phi), FS)
    k = int(np.argmax(np.abs(p)))
    assert freq[k] == pytest.approx(f0)
    assert p[k] == pytest.approx(2e3 * 0.01 * math.cos(phi) / 2, rel=1e-9)
    assert np.abs(np.delete(p, k)).max() < 1e-9 * abs(p[k])


def test_damper_power_is_positive_at_every_line():
    """A dashpot F = c v absorbs c |V|^2 / 2 >= 0 at every frequency."""
    rng = np.random.default_rng(11)
    v = rng.standard_normal(2048)
    _, p = power_flow.power_flow_spectrum(5e4 * v, v, FS)
    assert np.all(p >= -1e-9 * p.max())


def test_velocity_from_displacement_error_bound():
    f0 = 50.0
    u = tone(1e-3, f0)
    v = power_flow.velocity_from_displacement(u, FS)
    exact = 2 * math.pi * f0 * 1e-3 * np.cos(2 * math.pi * f0 * np.arange(N) / FS)
    bound = (2 * math.pi * f0 / FS) ** 2 / 6 * 2 * math.pi * f0 * 1e-3
    assert np.max(np.abs(v - exact)[1:-1]) <= 1.01 * bound


def test_derailment_coefficient_and_unloaded_wheel():
    q = np.array([10e3, 20e3, 5e3])
    p = np.array([50e3, 40e3, 0.0])
    qp = safety.derailment_coefficient(q, p)
    assert qp[:2] == pytest.approx([0.2, 0.5])
    assert np.isnan(qp[2])


def test_wheel_load_reduction_forms():
    t = np.arange(1000) / FS
    left = 70e3 + 7e3 * np.sin(2 * math.pi * 5 * t)
    right = 70e3 - 7e3 * np.sin(2 * math.pi * 5 * t)
    gb, dyn = safety.wheel_load_reduction(left, right)
    assert gb.max() == pytest.approx(0.1, rel=1e-4)      # |l - r| / (l + r) = 14 / 140
    assert dyn.max() == pytest.approx(0.1, rel=1e-4)     # 7 / 70 below the mean
    assert safety.lateral_force_limit(140e3) == pytest.approx(10e3 + 140e3 / 3)


def test_deck_acceleration_of_a_sine():
    f0, a = 4.0, 1e-3
    acc = safety.deck_acceleration(tone(a, f0), FS)
    assert np.max(np.abs(acc[100:-100])) == pytest.approx((2 * math.pi * f0) ** 2 * a,
                                                          rel=0.01)
    # 60 Hz is above the 30 Hz low-pass: attenuated by the 8th-order (filtfilt) roll-off
    high = safety.deck_acceleration(tone(a, 60.0), FS)
    assert np.max(np.abs(high[100:-100])) < 0.1 * (2 * math.pi * 60) ** 2 * a


def test_excitation_frequencies_at_300_kmh():
    """PHYSICS.md 9.6: Eq. 19 band 4.58-5.31 Hz; car 3.33, wheelbase 33.3, span 2.60 Hz."""
    marks = excitation.excitation_frequencies(
        300 / 3.6, bogie_semi_spacing=7.85, wheelbase_semi=1.25, car_length=25.0,
        span_length=32.0, fastener_spacing=0.63)
    by = {m.label.split()[0]: m for m in marks}
    assert (by['axle'].low, by['axle'].high) == pytest.approx((4.58, 5.31), abs=0.005)
    assert by['car'].low == pytest.approx(3.33, abs=0.005)
    assert by['wheelbase'].low == pytest.approx(33.3, abs=0.05)
    assert by['span'].low == pytest.approx(2.60, abs=0.005)
    assert by['V/\u03bb'].low == pytest.approx(83.3, abs=0.05)
    assert by['fastener'].low == pytest.approx(132.0, abs=0.5)
    lo, hi = excitation.axle_band(400 / 3.6, 7.85, 1.25)
    assert (lo, hi) == pytest.approx((6.11, 7.08), abs=0.005)


def test_rigid_displacement_eq16():
    n = 5
    left = np.tile([-2e-3, -4e-3, -3e-3], (n, 1))
    right = np.tile([-1e-3, -1e-3], (n, 1))
    est = rigid_displacement.rigid_midspan_displacement(left, right)
    assert est == pytest.approx(np.full(n, 0.5 * (-3e-3 - 1e-3)))
    one = rigid_displacement.rigid_midspan_displacement(left, None)
    assert one == pytest.approx(np.full(n, 0.5 * -3e-3))
    with pytest.raises(ValueError):
        rigid_displacement.rigid_midspan_displacement(None, None)


def test_resolving_segment():
    assert psd.resolving_segment_seconds(0.84, 60.0) == pytest.approx(6 / 0.84)
    assert psd.resolving_segment_seconds(0.84, 6.4) == pytest.approx(6.4)
    # [P]'s 20 m window at 300 km/h: 0.24 s, 4.2 Hz bins, cannot resolve 0.84 Hz
    assert 1 / 0.24 > 0.84
