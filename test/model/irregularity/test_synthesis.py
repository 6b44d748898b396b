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
Tests of irregularity synthesis: presets, composition, determinism (VALIDATION.md V8, V9).

The PSDs themselves are checked against the PHYSICS.md formulas in
``test_spectra.py``; here the reference integrals are computed with
``scipy.integrate.quad`` on those PSDs, independently of the synthesis code
(which integrates each FFT bin with Gauss-Legendre quadrature).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import signal

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity import spectra, spectrum_records, synthesis

ALL_COMPONENTS = [(f, c) for f, fam in spectra.SPECTRA.items() for c in fam.components]


def test_v8_paper_preset_adds_chinese_and_sato(quad_variance):
    """
    V8 for the paper preset: vertical variance = Chinese (1-50 m) + Sato (0.05-1 m).

    Reference: quad of the two PSDs; alignment: Chinese alone; cross-level and
    gauge: zero (the preset has none).  Tolerance: 2 %.  One realisation over a
    whole FFT record (8 x 50 m) is enough because the record variance is
    deterministic: measured error < 1e-12 for alignment, 1e-5 for vertical,
    where the one FFT bin containing n = 1/m is shared by the two layers with
    independent phases (their cross term is the only deviation from additivity).
    """
    prof = synthesis.synthesize('paper', length=400.0, dx=0.01, seed=3)
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


def test_chinese_sato_preset_extends_the_chinese_band_to_200_m(quad_variance):
    """
    chinese_sato = paper preset with the Chinese layer over 1-200 m (V8 variance, 2 %).

    One realisation over a whole FFT record (8 x 200 m) has the deterministic
    record variance (as for the paper preset above).
    """
    prof = synthesis.synthesize('chinese_sato', length=1600.0, dx=0.02, seed=5)
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
    prof = synthesis.synthesize(family, length=16 * nperseg * dx, dx=dx, seed=11,
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


def test_short_track_has_the_right_variance_on_average(quad_variance):
    """
    A track shorter than the FFT record is a window of it: mean square over seeds.

    Chinese vertical 2-200 m on a 100 m track (record 1600 m), 400 seeds: the
    ensemble mean of the mean square (no mean removal) estimates the variance.
    Reference: quad of G. Tolerance: 10 % (sampling scatter of a 100 m window
    of long waves; measured -1.4 %).
    """
    comp = spectra.SPECTRA['chinese_hsr'].components['vertical']
    squares = [np.mean(synthesis.synthesize('chinese_hsr', length=100.0, dx=0.5, seed=s,
                                            components=('vertical',)).z_left ** 2)
               for s in range(400)]
    assert np.mean(squares) == pytest.approx(quad_variance(comp, 2.0, 200.0), rel=0.10)


def test_rail_composition_and_signs():
    """
    Cross-level raises the left rail, gauge widens (left +y, right -y), vertical common.

    z_L,R = z_v +/- z_c/2, y_L,R = y_a +/- y_g/2. Tolerance: exact to 1e-15 m.
    """
    kw = {'length': 50.0, 'dx': 0.1, 'seed': 5}
    cross = synthesis.synthesize('chinese_hsr', components=('cross_level',), **kw)
    np.testing.assert_array_equal(cross.z_left, -cross.z_right)
    np.testing.assert_array_equal(cross.y_left, 0.0)
    np.testing.assert_allclose(cross.geometry('cross_level'), 2.0 * cross.z_left, atol=1e-15)
    gauge = synthesis.synthesize('chinese_hsr', components=('gauge',), **kw)
    np.testing.assert_array_equal(gauge.y_left, -gauge.y_right)
    np.testing.assert_array_equal(gauge.z_left, 0.0)
    np.testing.assert_allclose(gauge.geometry('gauge'), 2.0 * gauge.y_left, atol=1e-15)
    vert = synthesis.synthesize('chinese_hsr', components=('vertical',), **kw)
    np.testing.assert_array_equal(vert.z_left, vert.z_right)
    align = synthesis.synthesize('chinese_hsr', components=('alignment',), **kw)
    np.testing.assert_array_equal(align.y_left, align.y_right)
    full = synthesis.synthesize('chinese_hsr', **kw)
    total = vert.values + align.values + cross.values + gauge.values
    np.testing.assert_allclose(full.values, total, rtol=0.0, atol=1e-15)


def test_paper_preset_sato_is_common_to_both_rails(quad_variance):
    """
    Paper preset = Chinese vertical + alignment 1-50 m + Sato 0.05-1 m on both rails' vertical.

    Reference: the Chinese layer synthesised alone with the same seed (its
    random streams do not depend on the other layers). Tolerance: 1e-15 m.
    Without cross-level and gauge both rails carry the same profile and alignment.
    """
    kw = {'length': 60.0, 'dx': 0.01, 'seed': 8}
    paper = synthesis.synthesize('paper', **kw)
    layer = synthesis.IrregularityLayer('chinese_hsr', 1.0, 50.0, ('vertical', 'alignment'))
    chinese = synthesis.synthesize([layer], **kw)
    np.testing.assert_array_equal(paper.values[0], paper.values[1])
    np.testing.assert_array_equal(paper.values[2], paper.values[3])
    extra = paper.values - chinese.values
    np.testing.assert_allclose(extra[0], extra[1], atol=1e-15)
    np.testing.assert_allclose(extra[2:], 0.0, atol=1e-15)
    sato_var = quad_variance(spectra.SPECTRA['sato'].components['vertical'], 0.05, 1.0)
    assert np.var(extra[0]) == pytest.approx(sato_var, rel=0.2)
    assert 'paper' in synthesis.available_spectra()


def test_same_seed_is_bit_identical_and_other_seed_differs():
    """Determinism: equal seeds give identical arrays bit for bit; seeds 1 and 2 differ."""
    kw = {'length': 120.0, 'dx': 0.02}
    a = synthesis.synthesize('chinese_hsr', seed=1, **kw)
    b = synthesis.synthesize('chinese_hsr', seed=1, **kw)
    c = synthesis.synthesize('chinese_hsr', seed=2, **kw)
    for name in ('values', 'slopes', 'curvatures'):
        assert getattr(a, name).tobytes() == getattr(b, name).tobytes()
        assert not np.any(getattr(a, name) == getattr(c, name))
    # The four components have independent streams: weakly correlated.
    corr = np.corrcoef([a.geometry(comp) for comp in spectrum_records.COMPONENTS])
    assert np.max(np.abs(corr - np.eye(4))) < 0.5


def test_scale_multiplies_amplitudes_and_zero_is_smooth():
    """Scale 0 gives exact zeros (value and derivatives); scale 2 doubles everything."""
    kw = {'length': 100.0, 'dx': 0.05, 'seed': 4}
    zero = synthesis.synthesize('german_high', scale=0.0, **kw)
    for arr in (zero.values, zero.slopes, zero.curvatures):
        assert not np.any(arr)
    sample = zero.sample(np.linspace(0.0, 100.0, 33))
    assert not np.any(sample.value) and not np.any(sample.slope)
    one = synthesis.synthesize('german_high', scale=1.0, **kw)
    two = synthesis.synthesize('german_high', scale=2.0, **kw)
    np.testing.assert_allclose(two.values, 2.0 * one.values, rtol=1e-12, atol=0.0)
    np.testing.assert_allclose(two.curvatures, 2.0 * one.curvatures, rtol=1e-12, atol=0.0)


def test_three_km_paper_track_has_every_point():
    """
    3 km at 0.01 m (paper preset) gives 300 001 points ending at 3000 m.

    No wall-time assertion: speed is measured by ``ttb-sim bench``, never by a
    test (a loaded CI machine must not fail the suite).
    """
    prof = synthesis.synthesize('paper', length=3000.0, dx=0.01, seed=0)
    assert prof.n_points == 300_001
    assert prof.x_end == pytest.approx(3000.0)


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
    """Bad synthesis arguments raise ModelError with a message naming the problem."""
    args = {'spectrum': 'chinese_hsr', 'length': 10.0, 'dx': 0.1, 'seed': 0} | kwargs
    spectrum = args.pop('spectrum')
    with pytest.raises(ModelError, match=message):
        synthesis.synthesize(spectrum, **args)
