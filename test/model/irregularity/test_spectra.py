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
Tests of the track irregularity spectra (PHYSICS.md 1.1-1.4, VALIDATION.md V10).

The reference spectra below are typed again from PHYSICS.md in their SOURCE
units (mm^2/(1/m), m^2/(rad/m), cm^2/(rad/m), rad^2/(rad/m)); the conversion
to the one-sided G(n) in m^2/(cycle/m) is written out here independently of
``ttb_sim.model.irregularity.spectra``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity import spectra, spectrum_records

TWO_PI = 2.0 * math.pi
HALF_SPACING = 0.75          # b (m), PHYSICS.md 1.3

# PHYSICS.md 1.1: break points (1/m), A_i, k_i; S = A / n^k in mm^2/(1/m).
CHINESE = {
    'vertical': ([0.0187, 0.0474, 0.1533], [1.0544e-5, 3.5588e-3, 1.9784e-2, 3.9488e-4],
                 [3.3891, 1.9271, 1.3643, 3.4516]),
    'alignment': ([0.0450, 0.1234], [3.9513e-3, 1.1047e-2, 7.5633e-4], [1.8670, 1.5354, 2.8171]),
    'cross_level': ([0.0258, 0.1163], [3.6148e-3, 4.3685e-2, 4.5867e-3],
                    [1.7278, 1.0461, 2.0939]),
    'gauge': ([0.1090, 0.2938], [5.4978e-2, 5.0701e-3, 1.8778e-4], [0.8282, 1.9037, 4.5948]),
}
# PHYSICS.md 1.3 (m^2 rad/m) and 1.4 (cm^2 rad/m).
GERMAN = {'low': (4.032e-7, 2.119e-7, 0.532e-7), 'high': (10.80e-7, 6.125e-7, 1.032e-7)}
FRA = {1: (1.2107, 3.3634, 0.6046), 2: (1.0181, 1.2107, 0.9308), 3: (0.6816, 0.4128, 0.8520),
       4: (0.5376, 0.3027, 1.1312), 5: (0.2095, 0.0762, 0.8209), 6: (0.0339, 0.0339, 0.4380)}


def chinese_mm2(component: str, n: float) -> float:
    """Chinese S(n) in mm^2/(1/m), last segments extended."""
    breaks, coeffs, exps = CHINESE[component]
    i = sum(n >= b for b in breaks)
    return coeffs[i] / n ** exps[i]


def reference_g(family: str, component: str, n: float) -> float:
    """
    Evaluate the one-sided G(n) in m^2/(cycle/m), derived from PHYSICS.md.

    Per rad/m -> per cycle/m: G(n) = 2 pi S(Omega = 2 pi n).
    """
    w = TWO_PI * n
    if family == 'chinese_hsr':
        return 1e-6 * chinese_mm2(component, n)
    if family.startswith('sato'):
        return TWO_PI * spectra.SATO_DEFAULT_ROUGHNESS / w**3
    if family.startswith('german'):
        av, aa, ag = GERMAN[family.split('_')[1]]
        wc, wr, ws = 0.8246, 0.0206, 0.4380
        base = wc**2 / ((w**2 + wr**2) * (w**2 + wc**2))
        s = {
            'vertical': av * base,
            'alignment': aa * base,
            # roll angle rad^2/(rad/m) -> rail height difference: x (2b)^2
            'cross_level': (2 * HALF_SPACING) ** 2 * (av / HALF_SPACING**2) * base
            * w**2 / (w**2 + ws**2),
            'gauge': ag * base * w**2 / (w**2 + ws**2),
        }[component]
        return TWO_PI * s
    av, aa, ws = FRA[int(family[3:])]
    k, wc = 0.25, 0.8245
    s_cm2 = {
        'vertical': k * av * wc**2 / (w**2 * (w**2 + wc**2)),
        'alignment': k * aa * wc**2 / (w**2 * (w**2 + wc**2)),
        'cross_level': 4 * k * av * wc**2 / ((w**2 + wc**2) * (w**2 + ws**2)),
        'gauge': 4 * k * av * wc**2 / ((w**2 + wc**2) * (w**2 + ws**2)),
    }[component]
    return TWO_PI * 1e-4 * s_cm2


def reference_rms(family: str, component: str, lam_min: float, lam_max: float) -> float:
    """RMS (m) by adaptive quadrature of :func:`reference_g`."""
    n_lo, n_hi = 1.0 / lam_max, 1.0 / lam_min
    points = [b for b in CHINESE[component][0] if n_lo < b < n_hi] \
        if family == 'chinese_hsr' else None
    var, _ = integrate.quad(lambda n: reference_g(family, component, n), n_lo, n_hi,
                            points=points, limit=400, epsabs=0.0, epsrel=1e-10)
    return math.sqrt(var)


ALL_COMPONENTS = [(f, c) for f, fam in spectra.SPECTRA.items() for c in fam.components]


def test_registry_names_and_components():
    """Registry holds every spectrum of PHYSICS.md 1.1-1.4 with its components."""
    expected = {'chinese_hsr', 'sato', 'german_low', 'german_high'} | {f'fra{c}' for c in FRA}
    assert set(spectra.SPECTRA) == expected
    assert tuple(spectra.get_spectrum('sato').components) == ('vertical',)
    for name in expected - {'sato'}:
        assert tuple(spectra.get_spectrum(name).components) == spectrum_records.COMPONENTS
    assert len(ALL_COMPONENTS) == 37
    with pytest.raises(ModelError, match='unknown irregularity spectrum .*chinese_hsr'):
        spectra.get_spectrum('chinese')
    with pytest.raises(ModelError, match="no component 'gauge'"):
        spectra.get_spectrum('sato').component('gauge')


@pytest.mark.parametrize(('family', 'component'), ALL_COMPONENTS)
def test_psd_matches_source_formula_in_si_units(family, component):
    """
    PSD of every component equals the PHYSICS.md formula converted to m^2/(cycle/m).

    Reference: :func:`reference_g` (source units converted in this test).
    Tolerance: 1e-12 relative, over n = 1e-3 ... 50 cycles/m.
    """
    comp = spectra.get_spectrum(family).component(component)
    n = np.geomspace(1e-3, 50.0, 97)
    expected = np.array([reference_g(family, component, v) for v in n])
    np.testing.assert_allclose(comp.psd(n), expected, rtol=1e-12, atol=0.0)


def test_default_bands():
    """Default bands: Chinese 2-200 m, Sato 0.05-1 m, German 1-80 m, FRA 1.524-304.8 m."""
    bands = {'chinese_hsr': (2.0, 200.0), 'sato': (0.05, 1.0), 'german_low': (1.0, 80.0),
             'german_high': (1.0, 80.0), **{f'fra{c}': (1.524, 304.8) for c in FRA}}
    for family, component in ALL_COMPONENTS:
        comp = spectra.SPECTRA[family].components[component]
        assert (comp.wavelength_min, comp.wavelength_max) == bands[family]


@pytest.mark.parametrize('component', list(CHINESE))
def test_chinese_segments_continuous_at_breaks(component):
    """
    Adjacent Chinese HSR segments agree at every break point (PHYSICS.md 1.1).

    Reference: left and right segment formulas at n_b. Tolerance: 0.4 %.
    Worst case measured: vertical at n = 0.0187, 0.399 %.
    """
    breaks, coeffs, exps = CHINESE[component]
    comp = spectra.SPECTRA['chinese_hsr'].components[component]
    for i, b in enumerate(breaks):
        left = coeffs[i] / b ** exps[i]
        right = coeffs[i + 1] / b ** exps[i + 1]
        assert abs(right / left - 1.0) < 0.004
        below, above = comp.psd([b * (1 - 1e-12), b * (1 + 1e-12)])
        assert abs(above / below - 1.0) < 0.004


# PHYSICS.md [derived] RMS values: (family, component, band (m), RMS (mm)).
SPEC_RMS = [
    ('chinese_hsr', 'vertical', (2.0, 200.0), 1.22),      # V10
    ('chinese_hsr', 'alignment', (2.0, 200.0), 0.67),
    ('chinese_hsr', 'cross_level', (2.0, 200.0), 0.52),
    ('chinese_hsr', 'gauge', (2.0, 200.0), 0.34),
    ('chinese_hsr', 'vertical', (1.0, 50.0), 0.39),
    ('chinese_hsr', 'alignment', (1.0, 50.0), 0.36),
    ('sato', 'vertical', (0.05, 1.0), 0.023),
    ('german_low', 'vertical', (1.0, 80.0), 2.07),
    ('german_high', 'vertical', (1.0, 80.0), 3.39),
    ('german_low', 'alignment', (1.0, 80.0), 1.50),
    ('german_high', 'alignment', (1.0, 80.0), 2.56),
    ('fra6', 'vertical', (1.5, 300.0), 6.2),
]


@pytest.mark.parametrize(('family', 'component', 'band', 'rms_mm'), SPEC_RMS)
def test_band_rms_against_physics_values(family, component, band, rms_mm):
    """
    V10 and the other PHYSICS.md [derived] RMS values, from the integral of G.

    Reference: PHYSICS.md 1.1-1.4 (values rounded to 2-3 digits).
    Tolerance: 2 %.  Both the independent quadrature of the source formula and
    ``spectra.band_rms`` are checked; they must also agree with each other to
    1e-8.  Measured (mm): Chinese 2-200 m 1.2203 / 0.6678 / 0.5235 / 0.3437,
    1-50 m 0.3907 / 0.3632; Sato 0.02290; German 2.0740 / 3.3943, 1.5035 /
    2.5562; FRA 6 6.2349.
    """
    independent = reference_rms(family, component, *band)
    library = spectra.band_rms(family, component, *band)
    assert independent * 1e3 == pytest.approx(rms_mm, rel=0.02)
    assert library * 1e3 == pytest.approx(rms_mm, rel=0.02)
    assert library == pytest.approx(independent, rel=1e-8)


def test_sato_large_roughness_coefficient():
    """
    Sato with A = 5e-7: RMS 0.079 mm over 0.05-1 m, G(1 m) = 1.27e-2 mm^2/(1/m).

    Reference: PHYSICS.md 1.2 [derived]. Tolerance: 2 %.
    """
    rough = spectra.sato_spectrum(5e-7, name='sato_rough')
    assert spectra.band_rms(rough, 'vertical') * 1e3 == pytest.approx(0.079, rel=0.02)
    assert rough.component('vertical').psd(1.0) * 1e6 == pytest.approx(1.27e-2, rel=0.02)
    smooth_at_1m = spectra.SPECTRA['sato'].components['vertical'].psd(1.0) * 1e6
    assert smooth_at_1m == pytest.approx(1.05e-3, rel=0.02)
    chinese_at_1m = spectra.SPECTRA['chinese_hsr'].components['vertical'].psd(1.0) * 1e6
    assert smooth_at_1m / chinese_at_1m == pytest.approx(2.7, rel=0.02)
    with pytest.raises(ModelError, match='roughness coefficient'):
        spectra.sato_spectrum(-1.0)


def test_german_cross_level_is_rail_height_difference():
    """
    German cross-level: roll angle PSD times (2b)^2 = 2.25 m^2 (PHYSICS.md 1.3).

    Reference: the rad^2/(rad/m) formula at Omega = 1 rad/m. Tolerance: 1e-12.
    """
    av = GERMAN['low'][0]
    w = 1.0
    wc, wr, ws = 0.8246, 0.0206, 0.4380
    angle = (av / 0.75**2) * wc**2 * w**2 / ((w**2 + wr**2) * (w**2 + wc**2) * (w**2 + ws**2))
    comp = spectra.SPECTRA['german_low'].components['cross_level']
    assert comp.psd(w / TWO_PI) == pytest.approx(TWO_PI * 1.5**2 * angle, rel=1e-12)


def test_integrate_intervals_matches_quadrature():
    """
    Vectorised bin integration equals adaptive quadrature, across break points.

    Reference: scipy.integrate.quad on the PSD. Tolerance: 1e-9 relative.
    """
    for family, component in [('chinese_hsr', 'vertical'), ('chinese_hsr', 'gauge'),
                              ('german_high', 'cross_level'), ('fra1', 'vertical'),
                              ('sato', 'vertical')]:
        comp = spectra.SPECTRA[family].components[component]
        lower = np.array([0.0180, 0.0470, 0.15, 0.29, 0.5, 1.0, 3.0])
        upper = np.array([0.0190, 0.0480, 0.16, 0.30, 0.6, 1.1, 3.0])
        got = comp.integrate_intervals(lower, upper)
        for lo, hi, value in zip(lower, upper, got):
            inner = [b for b in comp.breakpoints if lo < b < hi] or None
            ref = integrate.quad(comp.psd, lo, hi, points=inner, epsabs=0.0,
                                 epsrel=1e-12)[0] if hi > lo else 0.0
            assert value == pytest.approx(ref, rel=1e-9, abs=0.0)


def test_invalid_arguments_are_refused():
    """Non-positive frequencies and empty bands are refused."""
    comp = spectra.SPECTRA['chinese_hsr'].components['vertical']
    with pytest.raises(ValueError, match='> 0'):
        comp.psd([0.1, 0.0])
    with pytest.raises(ModelError, match='wavelength band'):
        comp.variance(10.0, 5.0)
