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
Track irregularity power spectral densities (PHYSICS.md section 1).

Every spectrum component here returns the ONE-SIDED spatial PSD

    G(n)  in  m^2 / (cycle/m),

as a function of the spatial frequency n in cycles/m, whatever the units of
its source.  The variance of the irregularity over a wavelength band is then
``integral of G(n) dn`` from 1/wavelength_max to 1/wavelength_min.

Conversions applied (Omega = 2 pi n in rad/m):

- A density per rad/m becomes a density per cycle/m by ``G_n(n) = 2 pi
  G_Omega(2 pi n)`` (the same variance is spread over a 2 pi times narrower
  frequency interval).  Multiplying by 1/(2 pi) instead is a known error.
- mm^2 -> m^2: 1e-6; cm^2 -> m^2: 1e-4.
- German cross-level is a rail-plane ROLL ANGLE (rad^2/(rad/m)); it is turned
  into the height difference between the two rails with the contact-point
  spacing 2b = 1.5 m: delta_z = 2b * angle, so G_dz = (2b)^2 G_angle.
- Chinese (TB/T 3352) and FRA cross-level are already height differences
  between the rails (mm and cm respectively); only the length unit changes.
- All source spectra (Chinese, Sato, German, FRA) are taken as one-sided, which
  is what reproduces the [derived] RMS values of PHYSICS.md.

Components are named ``vertical`` (mean vertical profile of the two rails),
``alignment`` (mean lateral position), ``cross_level`` (height of the left rail
minus height of the right rail, m) and ``gauge`` (gauge widening, m).  How the
four are combined into rail irregularities is defined in
:mod:`ttb_sim.model.irregularity.synthesis`.

Each component has a default wavelength band (its range of validity, or the
band used by the source).  ``psd`` is nevertheless defined for every n > 0 so
that a band may be extended (the paper uses the Chinese spectrum down to 1 m,
which extrapolates its last power-law segment).

Registry (``SPECTRA``): ``chinese_hsr``, ``sato``, ``german_low``,
``german_high``, ``fra1`` ... ``fra6``.  Use :func:`get_spectrum` to look a
name up and :func:`band_rms` / :func:`band_variance` for the reference
integrals of the validation cases V8 and V10.
"""

from __future__ import annotations

from collections.abc import Mapping
import math
from types import MappingProxyType

import numpy as np
from numpy.typing import NDArray

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity.spectrum_records import (PsdFunction, SpectrumComponent,
                                                         SpectrumFamily)

__all__ = [
    'CONTACT_SPACING',
    'SATO_DEFAULT_ROUGHNESS',
    'SPECTRA',
    'band_rms',
    'band_variance',
    'get_spectrum',
    'sato_spectrum',
]

#: Distance 2b between the wheel-rail contact points of the two rails (m).
CONTACT_SPACING: float = 1.5

#: Default Sato wheel-rail roughness coefficient A (m^2 rad/m).
SATO_DEFAULT_ROUGHNESS: float = 4.15e-8

_TWO_PI = 2.0 * math.pi


# --- Chinese HSR ballastless track, TB/T 3352-2014 (PHYSICS.md 1.1) -----------------------

_CHINESE_TABLE: dict[str, tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]] = {
    # component: (break points n_b in 1/m, A_i in mm^2 (1/m)^(k-1), k_i)
    'vertical': (
        (0.0187, 0.0474, 0.1533),
        (1.0544e-5, 3.5588e-3, 1.9784e-2, 3.9488e-4),
        (3.3891, 1.9271, 1.3643, 3.4516)),
    'alignment': (
        (0.0450, 0.1234),
        (3.9513e-3, 1.1047e-2, 7.5633e-4),
        (1.8670, 1.5354, 2.8171)),
    'cross_level': (
        (0.0258, 0.1163),
        (3.6148e-3, 4.3685e-2, 4.5867e-3),
        (1.7278, 1.0461, 2.0939)),
    'gauge': (
        (0.1090, 0.2938),
        (5.4978e-2, 5.0701e-3, 1.8778e-4),
        (0.8282, 1.9037, 4.5948)),
}


def _piecewise_power_law(
    breaks: tuple[float, ...], coeffs: tuple[float, ...], exponents: tuple[float, ...],
) -> PsdFunction:
    """
    Build G(n) = 1e-6 A_i / n^k_i (mm^2 -> m^2), segment i between break points.

    Parameters
    ----------
    breaks : tuple of float
        Break points (cycles/m), increasing.
    coeffs, exponents : tuple of float
        A_i (mm^2 per cycle/m at n = 1) and k_i, one more than ``breaks``.

    Returns
    -------
    callable
        G(n) in m^2/(cycle/m).

    """
    b = np.asarray(breaks)
    a = np.asarray(coeffs) * 1e-6
    k = np.asarray(exponents)

    def density(n: NDArray[np.float64]) -> NDArray[np.float64]:
        i = np.searchsorted(b, n, side='right')
        return a[i] * n ** (-k[i])

    return density


def _chinese_hsr() -> SpectrumFamily:
    components = {}
    for name, (breaks, coeffs, exponents) in _CHINESE_TABLE.items():
        components[name] = SpectrumComponent(
            family='chinese_hsr', name=name,
            density=_piecewise_power_law(breaks, coeffs, exponents),
            wavelength_min=2.0, wavelength_max=200.0, breakpoints=breaks,
            units='TB/T 3352 S(n) = A/n^k in mm^2/(1/m), one-sided; x 1e-6 -> m^2/(1/m)'
                  + ('; height difference of the rails' if name == 'cross_level' else ''))
    return SpectrumFamily(
        'chinese_hsr',
        'Chinese HSR ballastless track, TB/T 3352-2014 (Kang Xi fit); valid 2-200 m',
        components)


# --- Sato short-wave rail-surface spectrum (PHYSICS.md 1.2) --------------------------------

def sato_spectrum(
    roughness_coefficient: float = SATO_DEFAULT_ROUGHNESS, *, name: str = 'sato',
) -> SpectrumFamily:
    """
    Build the Sato rail-surface roughness spectrum.

    Source form S(Omega) = A / Omega^3 (m^2/(rad/m), one-sided, Omega in rad/m),
    so that G(n) = 2 pi S(2 pi n) = A / (4 pi^2 n^3).  It has a ``vertical``
    component only; the synthesis adds it to the mean vertical profile, i.e.
    identically to both rails (see :mod:`ttb_sim.model.irregularity.synthesis`).

    Parameters
    ----------
    roughness_coefficient : float
        A in m^2 rad/m.  Published values range from 4.15e-8 (default; the
        smaller value joins the Chinese spectrum at 1 m with the smaller jump,
        a factor 2.7) to 5.0e-7.
    name : str
        Name given to the family.

    Returns
    -------
    SpectrumFamily
        Family with the ``vertical`` component, default band 0.05-1 m (the
        band used by the seed paper).

    Raises
    ------
    ModelError
        If the coefficient is not a positive finite number.

    """
    a = float(roughness_coefficient)
    if not (math.isfinite(a) and a > 0.0):
        raise ModelError(f'Sato roughness coefficient must be > 0, got {roughness_coefficient}')
    scale = a / _TWO_PI**2

    def density(n: NDArray[np.float64]) -> NDArray[np.float64]:
        return scale / n**3

    component = SpectrumComponent(
        family=name, name='vertical', density=density, wavelength_min=0.05, wavelength_max=1.0,
        units=f'Sato S(Omega) = A/Omega^3, A = {a:g} m^2 rad/m, m^2/(rad/m); x 2 pi at 2 pi n')
    description = f'Sato rail-surface roughness, A = {a:g} m^2 rad/m; 0.05-1 m'
    return SpectrumFamily(name, description, {'vertical': component})


# --- German high-speed spectra (PHYSICS.md 1.3) --------------------------------------------

_GERMAN_OMEGA_C = 0.8246
_GERMAN_OMEGA_R = 0.0206
_GERMAN_OMEGA_S = 0.4380
_GERMAN_COEFFS: dict[str, tuple[float, float, float]] = {
    # level: (Av, Aa, Ag) in m^2 rad/m
    'low': (4.032e-7, 2.119e-7, 0.532e-7),
    'high': (10.80e-7, 6.125e-7, 1.032e-7),
}


def _german(level: str) -> SpectrumFamily:
    av, aa, ag = _GERMAN_COEFFS[level]
    wc2, wr2, ws2 = _GERMAN_OMEGA_C**2, _GERMAN_OMEGA_R**2, _GERMAN_OMEGA_S**2
    half_spacing = 0.5 * CONTACT_SPACING

    def base(n: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        w2 = (_TWO_PI * n) ** 2
        return w2, wc2 / ((w2 + wr2) * (w2 + wc2))

    def vertical(n: NDArray[np.float64]) -> NDArray[np.float64]:
        return _TWO_PI * av * base(n)[1]

    def alignment(n: NDArray[np.float64]) -> NDArray[np.float64]:
        return _TWO_PI * aa * base(n)[1]

    def cross_level(n: NDArray[np.float64]) -> NDArray[np.float64]:
        w2, b = base(n)
        angle = (av / half_spacing**2) * b * w2 / (w2 + ws2)   # rad^2/(rad/m)
        return _TWO_PI * CONTACT_SPACING**2 * angle

    def gauge(n: NDArray[np.float64]) -> NDArray[np.float64]:
        w2, b = base(n)
        return _TWO_PI * ag * b * w2 / (w2 + ws2)

    name = f'german_{level}'
    units = 'S(Omega) in m^2/(rad/m), one-sided; x 2 pi at Omega = 2 pi n'
    components = {
        'vertical': SpectrumComponent(name, 'vertical', vertical, 1.0, 80.0, units=units),
        'alignment': SpectrumComponent(name, 'alignment', alignment, 1.0, 80.0, units=units),
        'cross_level': SpectrumComponent(
            name, 'cross_level', cross_level, 1.0, 80.0,
            units='source: roll angle in rad^2/(rad/m); x (2b)^2 = 2.25 m^2 -> height '
                  'difference of the rails; x 2 pi at Omega = 2 pi n'),
        'gauge': SpectrumComponent(name, 'gauge', gauge, 1.0, 80.0, units=units),
    }
    return SpectrumFamily(
        name, f'German high-speed spectrum, {level} interference (Guo et al. 2012); 1-80 m',
        components)


# --- US FRA classes 1-6 (PHYSICS.md 1.4) ---------------------------------------------------

_FRA_K = 0.25
_FRA_OMEGA_C = 0.8245
_FRA_CLASSES: dict[int, tuple[float, float, float]] = {
    # class: (Av, Aa in cm^2 rad/m, Omega_s in rad/m)
    1: (1.2107, 3.3634, 0.6046),
    2: (1.0181, 1.2107, 0.9308),
    3: (0.6816, 0.4128, 0.8520),
    4: (0.5376, 0.3027, 1.1312),
    5: (0.2095, 0.0762, 0.8209),
    6: (0.0339, 0.0339, 0.4380),
}
_FRA_WAVELENGTHS = (1.524, 304.8)   # 5 ft to 1000 ft


def _fra(track_class: int) -> SpectrumFamily:
    av, aa, omega_s = _FRA_CLASSES[track_class]
    wc2, ws2 = _FRA_OMEGA_C**2, omega_s**2
    to_si = _TWO_PI * 1e-4   # per rad/m -> per cycle/m, and cm^2 -> m^2

    def vertical(n: NDArray[np.float64]) -> NDArray[np.float64]:
        w2 = (_TWO_PI * n) ** 2
        return to_si * _FRA_K * av * wc2 / (w2 * (w2 + wc2))

    def alignment(n: NDArray[np.float64]) -> NDArray[np.float64]:
        w2 = (_TWO_PI * n) ** 2
        return to_si * _FRA_K * aa * wc2 / (w2 * (w2 + wc2))

    def cross_level(n: NDArray[np.float64]) -> NDArray[np.float64]:
        w2 = (_TWO_PI * n) ** 2
        return to_si * 4.0 * _FRA_K * av * wc2 / ((w2 + wc2) * (w2 + ws2))

    name = f'fra{track_class}'
    lo, hi = _FRA_WAVELENGTHS
    units = 'S(Omega) in cm^2/(rad/m), one-sided; x 1e-4 x 2 pi at Omega = 2 pi n'
    components = {
        'vertical': SpectrumComponent(name, 'vertical', vertical, lo, hi, units=units),
        'alignment': SpectrumComponent(name, 'alignment', alignment, lo, hi, units=units),
        'cross_level': SpectrumComponent(
            name, 'cross_level', cross_level, lo, hi,
            units=units + '; height difference of the rails'),
        # FRA gauge has the same formula as cross-level (PHYSICS.md 1.4).
        'gauge': SpectrumComponent(name, 'gauge', cross_level, lo, hi, units=units),
    }
    return SpectrumFamily(
        name, f'US FRA class {track_class} (k = 0.25); 1.524-304.8 m', components)


def _build_registry() -> Mapping[str, SpectrumFamily]:
    families = [_chinese_hsr(), sato_spectrum(), _german('low'), _german('high')]
    families += [_fra(c) for c in sorted(_FRA_CLASSES)]
    return MappingProxyType({f.name: f for f in families})


#: Every built-in spectrum family by name.
SPECTRA: Mapping[str, SpectrumFamily] = _build_registry()


def get_spectrum(name: str | SpectrumFamily) -> SpectrumFamily:
    """
    Look a spectrum family up by name.

    Parameters
    ----------
    name : str or SpectrumFamily
        Registry name (see :data:`SPECTRA`); a family is returned unchanged.

    Returns
    -------
    SpectrumFamily
        The family.

    Raises
    ------
    ModelError
        If the name is unknown; the message lists the known names.

    """
    if isinstance(name, SpectrumFamily):
        return name
    try:
        return SPECTRA[name]
    except (KeyError, TypeError):
        message = f'unknown irregularity spectrum {name!r}; known: {", ".join(SPECTRA)}'
        raise ModelError(message) from None


def band_variance(
    spectrum: str | SpectrumFamily,
    component: str,
    wavelength_min: float | None = None,
    wavelength_max: float | None = None,
) -> float:
    """
    Return the variance of a spectrum component over a wavelength band.

    This is the reference of validation cases V8 and V10:
    integral of G(n) dn for n from 1/wavelength_max to 1/wavelength_min.

    Parameters
    ----------
    spectrum : str or SpectrumFamily
        Spectrum family or its registry name.
    component : str
        One of :data:`COMPONENTS` that the family has.
    wavelength_min, wavelength_max : float, optional
        Band (m); ``None`` takes the component default.

    Returns
    -------
    float
        Variance in m^2.

    """
    return get_spectrum(spectrum).component(component).variance(wavelength_min, wavelength_max)


def band_rms(
    spectrum: str | SpectrumFamily,
    component: str,
    wavelength_min: float | None = None,
    wavelength_max: float | None = None,
) -> float:
    """
    Return the RMS of a spectrum component over a wavelength band.

    Parameters
    ----------
    spectrum : str or SpectrumFamily
        Spectrum family or its registry name.
    component : str
        One of :data:`COMPONENTS` that the family has.
    wavelength_min, wavelength_max : float, optional
        Band (m); ``None`` takes the component default.

    Returns
    -------
    float
        RMS in m (e.g. 1.22e-3 for ``chinese_hsr`` vertical over 2-200 m).

    """
    return math.sqrt(band_variance(spectrum, component, wavelength_min, wavelength_max))
