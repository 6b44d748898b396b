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
Tests of irregularity synthesis, sampling and CSV input (VALIDATION.md V8-V10).

The PSDs themselves are checked against the PHYSICS.md formulas in
``test_spectra.py``; here the reference integrals are computed with
``scipy.integrate.quad`` on those PSDs, independently of the synthesis code
(which integrates each FFT bin with Gauss-Legendre quadrature).
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from scipy import integrate, signal

from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity import profile as irr, spectra

ALL_COMPONENTS = [(f, c) for f, fam in spectra.SPECTRA.items() for c in fam.components]
RAILS = irr.RAIL_QUANTITIES


def quad_variance(comp: spectra.SpectrumComponent, lam_min: float, lam_max: float) -> float:
    """Integrate G over [1/lam_max, 1/lam_min] with scipy quad (m^2)."""
    n_lo, n_hi = 1.0 / lam_max, 1.0 / lam_min
    inner = [b for b in comp.breakpoints if n_lo < b < n_hi] or None
    value, _ = integrate.quad(lambda n: float(comp.psd(n)), n_lo, n_hi, points=inner,
                              limit=400, epsabs=0.0, epsrel=1e-10)
    return value


# --- V8, V9, V10 ---------------------------------------------------------------------------------

@pytest.mark.parametrize(('family', 'component'), ALL_COMPONENTS)
def test_v8_ensemble_variance_equals_psd_integral(family, component):
    """
    V8: mean sample variance of 20 realisations equals the integral of G over the band.

    Every spectrum and component (Chinese four, Sato, German low/high four
    each, FRA 1-6 four each), default band, seeds 0-19, full FFT record.
    Reference: quad of G(n) dn. Tolerance: 2 %.  Measured worst case over all
    37 components: |error| < 1e-14 (the bin amplitudes carry the exact bin
    integrals, so the record variance is the band integral by construction).
    """
    comp = spectra.SPECTRA[family].components[component]
    check = irr.check_variance(family, component, seeds=20)
    reference = quad_variance(comp, comp.wavelength_min, comp.wavelength_max)
    assert check.seeds == 20
    assert check.target_variance == pytest.approx(reference, rel=1e-8)
    assert check.sample_variance == pytest.approx(reference, rel=0.02)
    assert abs(check.relative_error) < 0.02


def test_v8_paper_preset_adds_chinese_and_sato():
    """
    V8 for the paper preset: vertical variance = Chinese (1-50 m) + Sato (0.05-1 m).

    Reference: quad of the two PSDs; alignment: Chinese alone; cross-level and
    gauge: zero (the preset has none).  Tolerance: 2 %.  One realisation over a
    whole FFT record (8 x 50 m) is enough because the record variance is
    deterministic: measured error < 1e-12 for alignment, 1e-5 for vertical,
    where the one FFT bin containing n = 1/m is shared by the two layers with
    independent phases (their cross term is the only deviation from additivity).
    """
    prof = irr.synthesize('paper', length=400.0, dx=0.01, seed=3)
    chinese = spectra.SPECTRA['chinese_hsr'].components
    sato = spectra.SPECTRA['sato'].components['vertical']
    expected = {c: quad_variance(chinese[c], 1.0, 50.0) for c in ('vertical', 'alignment')}
    expected['vertical'] += quad_variance(sato, 0.05, 1.0)
    for c in ('cross_level', 'gauge'):
        assert not np.any(prof.geometry(c))
    for c, var in expected.items():
        assert np.var(prof.geometry(c)) == pytest.approx(var, rel=0.02)
        exact = 1e-4 if c == 'vertical' else 1e-8
        assert np.var(prof.geometry(c)) == pytest.approx(var, rel=exact)


def test_chinese_sato_preset_extends_the_chinese_band_to_200_m():
    """
    chinese_sato = paper preset with the Chinese layer over 1-200 m (V8 variance, 2 %).

    One realisation over a whole FFT record (8 x 200 m) has the deterministic
    record variance (as for the paper preset above).
    """
    prof = irr.synthesize('chinese_sato', length=1600.0, dx=0.02, seed=5)
    chinese = spectra.SPECTRA['chinese_hsr'].components
    sato = spectra.SPECTRA['sato'].components['vertical']
    vertical = quad_variance(chinese['vertical'], 1.0, 200.0) + quad_variance(sato, 0.05, 1.0)
    assert np.var(prof.geometry('vertical')) == pytest.approx(vertical, rel=0.02)
    assert np.var(prof.geometry('alignment')) == pytest.approx(
        quad_variance(chinese['alignment'], 1.0, 200.0), rel=0.02)
    assert not np.any(prof.geometry('cross_level')) and not np.any(prof.geometry('gauge'))


def octave_ratios(family: str, component: str) -> list[float]:
    """Welch PSD / target PSD averaged over octave bands inside the default band."""
    comp = spectra.SPECTRA[family].components[component]
    lam_min, lam_max = comp.wavelength_min, comp.wavelength_max
    dx = lam_min / 8.0
    nperseg = 2 ** math.ceil(math.log2(4.0 * lam_max / dx))
    prof = irr.synthesize(family, length=16 * nperseg * dx, dx=dx, seed=11,
                          components=(component,))
    freq, psd = signal.welch(prof.geometry(component), fs=1.0 / dx, window='hann',
                             nperseg=nperseg, detrend=False)   # one-sided, m^2/(cycle/m)
    ratios = []
    lower = 2.0 / lam_max
    while 2.0 * lower <= 1.0 / lam_min:
        band = (freq >= lower) & (freq < 2.0 * lower)
        ratios.append(float(np.mean(psd[band]) / np.mean(comp.psd(freq[band]))))
        lower *= 2.0
    return ratios


@pytest.mark.parametrize(('family', 'component'), ALL_COMPONENTS)
def test_v9_welch_psd_matches_target_per_octave(family, component):
    """
    V9: Welch PSD of a synthesised profile, averaged per octave band, vs target G.

    Hann window, segments of >= 4 longest wavelengths, 31 half-overlapping
    segments, octave bands from 2/lambda_max up to 1/lambda_min (3-6 bands).
    Reference: G(n) of the spectrum.  Tolerance: ratio 1.0 +/- 20 % in every
    band.  Measured (seed 11), min-max per family: Chinese 0.960-1.027, Sato
    0.974-1.030, German low/high 0.954-1.028, FRA 1-6 0.960-1.028.
    """
    ratios = octave_ratios(family, component)
    assert len(ratios) >= 3
    for ratio in ratios:
        assert ratio == pytest.approx(1.0, abs=0.20)


def test_v10_chinese_vertical_rms_from_profiles():
    """
    V10: RMS of synthesised Chinese HSR vertical profiles over 2-200 m = 1.22 mm.

    Reference: PHYSICS.md 1.1 [derived] 1.22 mm. Tolerance: 2 %.
    Measured: 1.2203 mm from 20 realisations and from the PSD integral.
    """
    check = irr.check_variance('chinese_hsr', 'vertical', wavelength_min=2.0,
                               wavelength_max=200.0, seeds=20)
    assert check.sample_rms * 1e3 == pytest.approx(1.22, rel=0.02)
    assert check.target_rms * 1e3 == pytest.approx(1.22, rel=0.02)


def test_short_track_has_the_right_variance_on_average():
    """
    A track shorter than the FFT record is a window of it: mean square over seeds.

    Chinese vertical 2-200 m on a 100 m track (record 1600 m), 400 seeds: the
    ensemble mean of the mean square (no mean removal) estimates the variance.
    Reference: quad of G. Tolerance: 10 % (sampling scatter of a 100 m window
    of long waves; measured -1.4 %).
    """
    comp = spectra.SPECTRA['chinese_hsr'].components['vertical']
    squares = [np.mean(irr.synthesize('chinese_hsr', length=100.0, dx=0.5, seed=s,
                                      components=('vertical',)).z_left ** 2)
               for s in range(400)]
    assert np.mean(squares) == pytest.approx(quad_variance(comp, 2.0, 200.0), rel=0.10)


# --- composition, determinism, scale -------------------------------------------------------------

def test_rail_composition_and_signs():
    """
    Cross-level raises the left rail, gauge widens (left +y, right -y), vertical common.

    z_L,R = z_v +/- z_c/2, y_L,R = y_a +/- y_g/2. Tolerance: exact to 1e-15 m.
    """
    kw = {'length': 50.0, 'dx': 0.1, 'seed': 5}
    cross = irr.synthesize('chinese_hsr', components=('cross_level',), **kw)
    np.testing.assert_array_equal(cross.z_left, -cross.z_right)
    np.testing.assert_array_equal(cross.y_left, 0.0)
    np.testing.assert_allclose(cross.geometry('cross_level'), 2.0 * cross.z_left, atol=1e-15)
    gauge = irr.synthesize('chinese_hsr', components=('gauge',), **kw)
    np.testing.assert_array_equal(gauge.y_left, -gauge.y_right)
    np.testing.assert_array_equal(gauge.z_left, 0.0)
    np.testing.assert_allclose(gauge.geometry('gauge'), 2.0 * gauge.y_left, atol=1e-15)
    vert = irr.synthesize('chinese_hsr', components=('vertical',), **kw)
    np.testing.assert_array_equal(vert.z_left, vert.z_right)
    align = irr.synthesize('chinese_hsr', components=('alignment',), **kw)
    np.testing.assert_array_equal(align.y_left, align.y_right)
    full = irr.synthesize('chinese_hsr', **kw)
    total = vert.values + align.values + cross.values + gauge.values
    np.testing.assert_allclose(full.values, total, rtol=0.0, atol=1e-15)


def test_paper_preset_sato_is_common_to_both_rails():
    """
    Paper preset = Chinese vertical + alignment 1-50 m + Sato 0.05-1 m on both rails' vertical.

    Reference: the Chinese layer synthesised alone with the same seed (its
    random streams do not depend on the other layers). Tolerance: 1e-15 m.
    Without cross-level and gauge both rails carry the same profile and alignment.
    """
    kw = {'length': 60.0, 'dx': 0.01, 'seed': 8}
    paper = irr.synthesize('paper', **kw)
    chinese = irr.synthesize([irr.IrregularityLayer('chinese_hsr', 1.0, 50.0,
                                                    ('vertical', 'alignment'))], **kw)
    np.testing.assert_array_equal(paper.values[0], paper.values[1])
    np.testing.assert_array_equal(paper.values[2], paper.values[3])
    extra = paper.values - chinese.values
    np.testing.assert_allclose(extra[0], extra[1], atol=1e-15)
    np.testing.assert_allclose(extra[2:], 0.0, atol=1e-15)
    sato_var = quad_variance(spectra.SPECTRA['sato'].components['vertical'], 0.05, 1.0)
    assert np.var(extra[0]) == pytest.approx(sato_var, rel=0.2)
    assert 'paper' in irr.available_spectra()


def test_same_seed_is_bit_identical_and_other_seed_differs():
    """Determinism: equal seeds give identical arrays bit for bit; seeds 1 and 2 differ."""
    kw = {'length': 120.0, 'dx': 0.02}
    a = irr.synthesize('chinese_hsr', seed=1, **kw)
    b = irr.synthesize('chinese_hsr', seed=1, **kw)
    c = irr.synthesize('chinese_hsr', seed=2, **kw)
    for name in ('values', 'slopes', 'curvatures'):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
        assert not np.any(getattr(a, name) == getattr(c, name))
    # The four components have independent streams: weakly correlated.
    corr = np.corrcoef([a.geometry(comp) for comp in spectra.COMPONENTS])
    assert np.max(np.abs(corr - np.eye(4))) < 0.5


def test_scale_multiplies_amplitudes_and_zero_is_smooth():
    """Scale 0 gives exact zeros (value and derivatives); scale 2 doubles everything."""
    kw = {'length': 100.0, 'dx': 0.05, 'seed': 4}
    zero = irr.synthesize('german_high', scale=0.0, **kw)
    for arr in (zero.values, zero.slopes, zero.curvatures):
        assert not np.any(arr)
    sample = zero.sample(np.linspace(0.0, 100.0, 33))
    assert not np.any(sample.value) and not np.any(sample.slope)
    one = irr.synthesize('german_high', scale=1.0, **kw)
    two = irr.synthesize('german_high', scale=2.0, **kw)
    np.testing.assert_allclose(two.values, 2.0 * one.values, rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(two.curvatures, 2.0 * one.curvatures, rtol=1e-12, atol=0.0)


def test_three_km_paper_track_is_fast():
    """3 km at 0.01 m (300 001 points, paper preset) synthesises in < 2 s (measured 0.15 s)."""
    start = time.perf_counter()
    prof = irr.synthesize('paper', length=3000.0, dx=0.01, seed=0)
    assert time.perf_counter() - start < 2.0
    assert prof.n_points == 300_001
    assert prof.x_end == pytest.approx(3000.0)


# --- sampling and derivatives --------------------------------------------------------------------

@pytest.fixture(scope='module')
def chinese_profile() -> irr.TrackIrregularity:
    """Chinese HSR 2-200 m, 400 m at 0.02 m (100 points per shortest wavelength)."""
    return irr.synthesize('chinese_hsr', length=400.0, dx=0.02, seed=21, x_start=-50.0)


def test_sample_reproduces_grid_values(chinese_profile):
    """Sampling at grid points returns the stored values and derivatives (1e-12 rel)."""
    prof = chinese_profile
    got = prof.sample(prof.x[::97])
    for arr, ref in ((got.value, prof.values), (got.slope, prof.slopes),
                     (got.curvature, prof.curvatures)):
        np.testing.assert_allclose(arr, ref[:, ::97], rtol=1e-12,
                                   atol=1e-12 * np.max(np.abs(ref)))
    assert got.rail('y_right')[0] is not None
    np.testing.assert_array_equal(got.rail('z_right')[1], got.slope[1])


def test_spectral_derivatives_match_finite_differences_of_the_grid(chinese_profile):
    """
    Slopes and curvatures at the nodes are the derivatives of the node values.

    Reference: central differences of the grid values (and of the slopes).
    Tolerance: 0.2 % of the peak (central-difference error at the shortest
    wavelength, 2 m at dx = 0.02 m, is 0.066 %).
    """
    prof = chinese_profile
    fd1 = (prof.values[:, 2:] - prof.values[:, :-2]) / (2 * prof.dx)
    fd2 = (prof.slopes[:, 2:] - prof.slopes[:, :-2]) / (2 * prof.dx)
    for fd, ref in ((fd1, prof.slopes[:, 1:-1]), (fd2, prof.curvatures[:, 1:-1])):
        peak = np.max(np.abs(ref), axis=1, keepdims=True)
        assert np.all(np.abs(fd - ref) <= 2e-3 * peak)


def test_sampled_derivatives_are_derivatives_of_sampled_value(chinese_profile):
    """
    Derivatives returned by ``sample`` equal finite differences of ``sample``.

    Between grid points (random positions), central difference with h = 1e-4 m.
    Tolerance: 1e-5 of the peak value of each derivative.
    """
    prof = chinese_profile
    x = np.random.default_rng(0).uniform(prof.x_start + 1.0, prof.x_end - 1.0, size=(5, 40))
    h = 1e-4
    mid, plus, minus = prof.sample(x), prof.sample(x + h), prof.sample(x - h)
    assert mid.value.shape == (4, 5, 40)
    fd1 = (plus.value - minus.value) / (2 * h)
    fd2 = (plus.slope - minus.slope) / (2 * h)
    for fd, ref in ((fd1, mid.slope), (fd2, mid.curvature)):
        peak = np.max(np.abs(ref), axis=(1, 2), keepdims=True)
        assert np.all(np.abs(fd - ref) <= 1e-5 * peak)


def test_quintic_hermite_interpolation_is_accurate():
    """
    Sampling between nodes reproduces a known smooth profile and its derivatives.

    Profile: sum of sines of wavelength 2-200 m stored with exact derivatives
    at dx = 0.25 m (8 points per shortest wavelength); ``sample`` at random
    positions vs the analytic values.  Tolerance (of each peak): 1e-6 value,
    1e-4 slope, 1e-3 curvature; measured 6.5e-8, 4.5e-6, 8.8e-5.
    """
    waves = np.array([200.0, 37.0, 9.0, 3.3, 2.0])
    k = 2 * np.pi / waves
    amp = np.array([1.0, 0.5, 0.2, 0.05, 0.02])[:, np.newaxis] * 1e-3
    phase = np.arange(5)[:, np.newaxis] * 0.7

    def series(x):
        arg = k[:, np.newaxis] * x + phase
        return (np.sum(amp * np.sin(arg), axis=0),
                np.sum(amp * k[:, np.newaxis] * np.cos(arg), axis=0),
                np.sum(-amp * k[:, np.newaxis] ** 2 * np.sin(arg), axis=0))

    grid = 0.25 * np.arange(1601)
    node = [np.tile(arr, (4, 1)) * np.array([[1.0], [-1.0], [2.0], [0.5]])
            for arr in series(grid)]
    prof = irr.TrackIrregularity(0.0, 0.25, *node)
    x = np.random.default_rng(3).uniform(0.0, 400.0, 500)
    got = prof.sample(x)
    for arr, ref, tol in zip((got.value, got.slope, got.curvature), series(x),
                             (1e-6, 1e-4, 1e-3)):
        assert np.max(np.abs(arr[0] - ref)) <= tol * np.max(np.abs(ref))
        np.testing.assert_allclose(arr[1], -arr[0], rtol=1e-12)


def test_outside_range_raises_or_gives_zeros(chinese_profile):
    """Outside [x_start, x_end]: ScenarioError by default, zeros with outside='zero'."""
    prof = chinese_profile
    with pytest.raises(ScenarioError, match=r'covers x = -50 to 350 m; position x = 351'):
        prof.sample([0.0, 351.0])
    with pytest.raises(ScenarioError, match='outside'):
        prof.sample(-50.5)
    with pytest.raises(ScenarioError, match='outside'):
        prof.sample(np.nan)
    edge = prof.sample([prof.x_start, prof.x_end])
    np.testing.assert_allclose(edge.value, prof.values[:, [0, -1]], rtol=1e-12)
    got = prof.sample(np.array([-60.0, 10.0, 400.0]), outside='zero')
    ref = prof.sample(10.0)
    for arr, value in ((got.value, ref.value), (got.slope, ref.slope),
                       (got.curvature, ref.curvature)):
        np.testing.assert_array_equal(arr[:, [0, 2]], 0.0)
        np.testing.assert_allclose(arr[:, 1], value, rtol=1e-12)


def test_irregularity_is_immutable(chinese_profile):
    """Arrays of a TrackIrregularity are read-only."""
    with pytest.raises(ValueError):
        chinese_profile.values[0, 0] = 1.0
    with pytest.raises(AttributeError):
        chinese_profile.dx = 1.0


@pytest.mark.parametrize(('kwargs', 'message'), [
    ({'spectrum': 'nope'}, 'unknown irregularity spectrum'),
    ({'seed': -1}, 'seed must be an integer'),
    ({'seed': 1.5}, 'seed must be an integer'),
    ({'scale': -0.5}, 'scale must be'),
    ({'length': 0.0}, 'length must be'),
    ({'dx': 1.2}, 'not resolved by dx'),
    ({'spectrum': 'paper', 'wavelength_min': 1.0}, 'preset'),
    ({'components': ('torsion',)}, "no component 'torsion'"),
    ({'wavelength_min': 5.0, 'wavelength_max': 4.0}, 'wavelength band'),
    ({'length': 1e6, 'dx': 0.05}, 'exceeds the limit'),
    ({'scale': 'big'}, 'scale must be a number'),
    ({'components': ()}, 'no spectrum component'),
    ({'components': ('gauge', 'gauge')}, 'listed twice'),
])
def test_synthesize_refuses_bad_arguments(kwargs, message):
    """Bad synthesis arguments raise ScenarioError with a message naming the problem."""
    args = {'spectrum': 'chinese_hsr', 'length': 10.0, 'dx': 0.1, 'seed': 0} | kwargs
    spectrum = args.pop('spectrum')
    with pytest.raises(ScenarioError, match=message):
        irr.synthesize(spectrum, **args)


# --- CSV -----------------------------------------------------------------------------------------

def test_csv_round_trip(tmp_path, chinese_profile):
    """
    save_csv then load_csv gives back the grid and the values exactly.

    Slopes and curvatures come from a cubic spline of the values; they match
    the spectral ones to 1e-3 / 2e-2 of the peak (at 100 points per shortest
    wavelength).
    """
    path = tmp_path / 'profile.csv'
    irr.save_csv(chinese_profile, path)
    assert path.read_text().splitlines()[0] == 'x,z_left,z_right,y_left,y_right'
    loaded = irr.load_csv(path, min_length=400.0)
    assert loaded.n_points == chinese_profile.n_points
    assert loaded.x_start == chinese_profile.x_start
    assert loaded.dx == pytest.approx(chinese_profile.dx, rel=1e-12)
    np.testing.assert_array_equal(loaded.values, chinese_profile.values)
    for arr, ref, tol in ((loaded.slopes, chinese_profile.slopes, 1e-3),
                          (loaded.curvatures, chinese_profile.curvatures, 2e-2)):
        peak = np.max(np.abs(ref), axis=1, keepdims=True)
        assert np.all(np.abs(arr - ref)[:, 5:-5] <= tol * peak)
    assert loaded.source == f'csv:{path}'


def test_csv_nonuniform_rows_are_resampled(tmp_path):
    """
    Non-uniform x is resampled onto a uniform grid (median spacing, or dx given).

    Reference: analytic sine profiles. Tolerance: 1e-6 m on values (spline error).
    """
    x = np.sort(np.random.default_rng(1).uniform(0.0, 20.0, 400))
    x[0], x[-1] = 0.0, 20.0
    shapes = [np.sin(2 * np.pi * x / 10.0) * 1e-3, np.cos(2 * np.pi * x / 8.0) * 1e-3,
              np.sin(2 * np.pi * x / 12.0) * 5e-4, np.zeros_like(x)]
    path = tmp_path / 'uneven.csv'
    lines = ['y_right, x, z_left, z_right, y_left, comment']
    lines += [f'{d},{a},{b},{c},{e},hello' for a, b, c, e, d in zip(x, *shapes)]
    path.write_text('\n'.join(lines) + '\n')
    prof = irr.load_csv(path, dx=0.1)
    assert prof.dx == 0.1 and prof.n_points == 201 and prof.x_start == 0.0
    np.testing.assert_allclose(prof.z_left, np.sin(2 * np.pi * prof.x / 10.0) * 1e-3, atol=1e-6)
    np.testing.assert_allclose(prof.z_right, np.cos(2 * np.pi * prof.x / 8.0) * 1e-3, atol=1e-6)
    np.testing.assert_allclose(prof.slopes[0], np.cos(2 * np.pi * prof.x / 10.0) * 2e-4 * np.pi,
                               atol=1e-5)
    default = irr.load_csv(path)
    assert default.dx == pytest.approx(np.median(np.diff(x)))


GOOD_ROWS = ['0.0,0,0,0,0', '0.5,1e-3,0,0,0', '1.0,0,0,0,0', '1.5,0,0,0,0', '2.0,0,0,0,0']


@pytest.mark.parametrize(('lines', 'kwargs', 'message'), [
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.5,0,nan,0,0', GOOD_ROWS[4]], {},
     r'row 5: value .nan. in column z_right is not a finite number'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:2], '1.0,abc,0,0,0', *GOOD_ROWS[3:]], {},
     r'row 4: non-numeric value .abc. in column z_left'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.5,0,,0,0', GOOD_ROWS[4]], {},
     r'row 5: non-numeric value .. in column z_right'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '0.9,0,0,0,0', GOOD_ROWS[4]], {},
     r'row 5: x = 0.9 m does not increase strictly'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.0,0,0,0,0', GOOD_ROWS[4]], {},
     r'row 5: x = 1 m does not increase strictly'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3]], {},
     r'row 4: too few rows: 3 data row'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS], {'min_length': 10.0},
     r'row 6: profile too short: it covers 2 m'),
    (['x,z_left,z_right,y_left', *GOOD_ROWS], {},
     r'row 1: header is missing column\(s\) y_right'),
    (['# measured 2026', '', 'x,z_left,z_right,yleft,y_right', *GOOD_ROWS], {},
     r'row 3: header is missing column\(s\) y_left'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:2], '1.0,0,0,0', *GOOD_ROWS[3:]], {},
     r'row 4: expected 5 fields as in the header, found 4'),
    ([], {}, r'row 1: no header'),
])
def test_csv_refusals_name_file_and_row(tmp_path, lines, kwargs, message):
    """Each bad CSV raises ScenarioError naming the file and the row (file line number)."""
    path = tmp_path / 'bad.csv'
    path.write_text('\n'.join(lines) + '\n')
    with pytest.raises(ScenarioError, match=f'bad.csv: {message}'):
        irr.load_csv(path, **kwargs)


def test_csv_unreadable_file_is_refused(tmp_path):
    """A missing file, a directory and a binary file are refused naming the path."""
    for path in (tmp_path / 'missing.csv', tmp_path):
        with pytest.raises(ScenarioError, match=f'{path}: cannot read irregularity file'):
            irr.load_csv(path)
    binary = tmp_path / 'binary.csv'
    binary.write_bytes(b'\xff\xfe\x00\x81' * 10)
    with pytest.raises(ScenarioError, match='binary.csv: cannot read'):
        irr.load_csv(binary)


def test_csv_skips_comments_and_blank_lines(tmp_path):
    """Comment and blank lines and a UTF-8 byte-order mark are skipped."""
    path = tmp_path / 'ok.csv'
    lines = ['# track km 12', 'x,z_left,z_right,y_left,y_right', '', *GOOD_ROWS, '']
    path.write_text('\ufeff' + '\n'.join(lines), encoding='utf-8')
    prof = irr.load_csv(path, min_length=2.0)
    assert prof.n_points == 5 and prof.dx == 0.5
    assert prof.z_left[1] == 1e-3
