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
Synthesis of random rail irregularity profiles from spectra (PHYSICS.md 1.5).

The synthesis is the random-phase spectral representation, evaluated
with one inverse real FFT per rail quantity and derivative order::

    q(x) = sum_k a_k cos(2 pi n_k (x - x_start) + phi_k),   phi_k ~ U(0, 2 pi)

with n_k = k / (N dx).  The amplitude of each bin is a_k = scale * sqrt(2 V_k),
where V_k is the integral of the one-sided PSD G over the part of the bin
[n_k - dn/2, n_k + dn/2] inside the band (not the rectangle G(n_k) dn).  Over
the whole FFT record the sample variance is therefore exactly the integral of
G over the band (V8), whatever the resolution.  The FFT record is at least
``MIN_RECORD_WAVELENGTHS`` times the longest wavelength; a shorter requested
track is the beginning of that record.  First and second derivatives along x
are obtained spectrally (factors i 2 pi n and -(2 pi n)^2).

Spectra may be combined in layers (:class:`IrregularityLayer`); named
combinations are in :data:`PRESETS`.  The rail quantities are composed from
the track-geometry components as described in :mod:`.profile`.

Random streams: layer j, component c (index in ``COMPONENTS``) uses
``np.random.default_rng(np.random.SeedSequence(seed).spawn(n_layers)[j]
.spawn(4)[c])``, so every component has its own independent stream, fixed by
the seed alone (bit-for-bit reproducible).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import logging
import math
from types import MappingProxyType

import numpy as np
from scipy import fft

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity._checks import check_positive, GRID_SLACK, to_float
from ttb_sim.model.irregularity.profile import TrackIrregularity
from ttb_sim.model.irregularity.spectra import get_spectrum, SPECTRA
from ttb_sim.model.irregularity.spectrum_records import (COMPONENTS, SpectrumComponent,
                                                         SpectrumFamily)

__all__ = [
    'IrregularityLayer',
    'MIN_RECORD_WAVELENGTHS',
    'PRESETS',
    'available_spectra',
    'synthesize',
]

_LOG = logging.getLogger(__name__)

#: The FFT record spans at least this many times the longest wavelength.
MIN_RECORD_WAVELENGTHS: int = 8

#: Largest number of grid points a synthesis may allocate.
MAX_POINTS: int = 10_000_000


@dataclass(frozen=True)
class IrregularityLayer:
    """
    One spectrum contributing to a synthesised irregularity.

    Attributes
    ----------
    spectrum : str or SpectrumFamily
        Spectrum family or its registry name (see ``spectra.SPECTRA``).
    wavelength_min, wavelength_max : float or None
        Band (m) applied to every component of the layer; ``None`` keeps the
        default band of each component.
    components : tuple of str or None
        Components to include; ``None`` takes all the family has.

    """

    spectrum: str | SpectrumFamily
    wavelength_min: float | None = None
    wavelength_max: float | None = None
    components: tuple[str, ...] | None = None


#: Named combinations of spectra.  ``paper``: [P] section 4.1 and its Fig. 11,
#: the Chinese HSR vertical profile and alignment over 1-50 m wavelength (one
#: vertical and one lateral series, the same under both rails: [P] shows no
#: cross-level or gauge) plus Sato vertical roughness (A = 4.15e-8) over
#: 0.05-1 m on both rails.  At 1 m the vertical PSD rises 2.7 times from the
#: Chinese to the Sato spectrum (PHYSICS.md 1.2); with TB/T 3352 cross-level
#: extrapolated to 1 m on top, each rail's PSD would instead fall there.
#: ``chinese_sato``: the same with the Chinese layer over 1-200 m, so that
#: wavelengths beyond 50 m (below 1.67 Hz at 300 km/h) excite the car body.
PRESETS: Mapping[str, tuple[IrregularityLayer, ...]] = MappingProxyType({
    'paper': (
        IrregularityLayer('chinese_hsr', 1.0, 50.0, ('vertical', 'alignment')),
        IrregularityLayer('sato', 0.05, 1.0),
    ),
    'chinese_sato': (
        IrregularityLayer('chinese_hsr', 1.0, 200.0, ('vertical', 'alignment')),
        IrregularityLayer('sato', 0.05, 1.0),
    ),
})


def available_spectra() -> tuple[str, ...]:
    """
    Return the names :func:`synthesize` accepts: spectrum families and presets.

    Returns
    -------
    tuple of str
        Sorted names.

    """
    return tuple(sorted({*SPECTRA, *PRESETS}))


def _resolve_layers(
    spectrum: str | SpectrumFamily | IrregularityLayer | Sequence[IrregularityLayer],
    wavelength_min: float | None,
    wavelength_max: float | None,
) -> tuple[tuple[IrregularityLayer, ...], str]:
    """Turn the ``spectrum`` argument of :func:`synthesize` into layers and a label."""
    band_given = wavelength_min is not None or wavelength_max is not None
    if isinstance(spectrum, str) and spectrum in PRESETS:
        if band_given:
            message = (
                f'preset {spectrum!r} fixes its own bands; to change them pass '
                'IrregularityLayer objects instead of wavelength_min/wavelength_max')
            raise ModelError(message)
        return PRESETS[spectrum], spectrum
    if isinstance(spectrum, (str, SpectrumFamily)):
        family = get_spectrum(spectrum)
        return (IrregularityLayer(family, wavelength_min, wavelength_max),), family.name
    if isinstance(spectrum, IrregularityLayer):
        spectrum = (spectrum,)
    layers = tuple(spectrum)
    if band_given:
        raise ModelError('give the bands inside the IrregularityLayer objects')
    if not layers or not all(isinstance(layer, IrregularityLayer) for layer in layers):
        raise ModelError(f'not a spectrum name, family or layers: {spectrum!r}')
    label = '+'.join(get_spectrum(layer.spectrum).name for layer in layers)
    return layers, label


def _n_points(length: float, dx: float) -> int:
    """Return the number of grid points covering ``length`` at spacing ``dx``."""
    return int(math.ceil(length / dx - GRID_SLACK)) + 1


def _check_seed(seed: int) -> int:
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ModelError(f'seed must be an integer >= 0, got {seed!r}')
    return int(seed)


def synthesize(
    spectrum: str | SpectrumFamily | IrregularityLayer | Sequence[IrregularityLayer] = 'paper',
    *,
    length: float,
    dx: float = 0.01,
    seed: int = 0,
    scale: float = 1.0,
    x_start: float = 0.0,
    wavelength_min: float | None = None,
    wavelength_max: float | None = None,
    components: Sequence[str] | None = None,
) -> TrackIrregularity:
    """
    Synthesise a random rail irregularity profile from a spectrum.

    Parameters
    ----------
    spectrum : str, SpectrumFamily, IrregularityLayer or sequence of them
        A family name (``chinese_hsr``, ``sato``, ``german_low``,
        ``german_high``, ``fra1`` ... ``fra6``), a preset name (``paper``), a
        family, or explicit layers whose contributions are added.
    length : float
        Track length to cover (m), from ``x_start``.  The grid has
        ceil(length/dx) + 1 points.
    dx : float
        Grid spacing (m); must resolve the shortest wavelength
        (dx < wavelength_min / 2; 4 or more points per wavelength advised).
    seed : int
        Non-negative seed; the same seed gives bit-for-bit the same profile.
    scale : float
        Amplitude factor (>= 0); 0 gives a perfectly smooth track.
    x_start : float
        Position of the first grid point (m).
    wavelength_min, wavelength_max : float, optional
        Band (m) for a single family; default: each component's default.
    components : sequence of str, optional
        Restrict a single family to these components.

    Returns
    -------
    TrackIrregularity
        The realised rail irregularities on the grid.

    Raises
    ------
    ModelError
        On an unknown spectrum or component, an invalid number, a band the
        grid cannot resolve, or a grid larger than ``MAX_POINTS``.

    """
    layers, label = _resolve_layers(spectrum, wavelength_min, wavelength_max)
    if components is not None:
        if len(layers) != 1:
            raise ModelError('components= applies to a single spectrum family only')
        layers = (IrregularityLayer(layers[0].spectrum, layers[0].wavelength_min,
                                    layers[0].wavelength_max, tuple(components)),)
    length = check_positive('length', length)
    dx = check_positive('dx', dx)
    seed = _check_seed(seed)
    scale = to_float('scale', scale)
    if not (math.isfinite(scale) and scale >= 0.0):
        raise ModelError(f'scale must be a finite number >= 0, got {scale!r}')
    x_start = to_float('x_start', x_start)
    if not math.isfinite(x_start):
        raise ModelError(f'x_start must be finite, got {x_start!r}')
    parts = _parts(layers)
    longest = max(hi for _, _, _, hi in parts)
    n_req = _n_points(length, dx)
    n_fft = max(n_req, _n_points(MIN_RECORD_WAVELENGTHS * longest, dx))
    if n_fft > MAX_POINTS:
        message = (
            f'irregularity grid of {n_fft} points (length {length:g} m, longest wavelength '
            f'{longest:g} m, dx {dx:g} m) exceeds the limit of {MAX_POINTS}; increase dx')
        raise ModelError(message)
    coefficients = _half_spectra(parts, len(layers), seed, scale, n_fft, dx)
    values, slopes, curvatures = _profiles(coefficients, n_fft, n_req, dx)
    _LOG.debug('synthesised %s: %d points (FFT %d), dx %g m, seed %d, scale %g',
               label, n_req, n_fft, dx, seed, scale)
    return TrackIrregularity(x_start, dx, values, slopes, curvatures,
                             source=f'{label} seed={seed} scale={scale:g}')


def _parts(layers: tuple[IrregularityLayer, ...]
           ) -> list[tuple[int, SpectrumComponent, float, float]]:
    """Return every (layer index, component, wavelength_min, wavelength_max) to synthesise."""
    parts: list[tuple[int, SpectrumComponent, float, float]] = []
    for j, layer in enumerate(layers):
        family = get_spectrum(layer.spectrum)
        names = tuple(family.components) if layer.components is None else layer.components
        if len(set(names)) != len(names):
            raise ModelError(f'{family.name}: a component is listed twice in {names}')
        for name in names:
            comp = family.component(name)
            lo, hi = comp.band(layer.wavelength_min, layer.wavelength_max)
            parts.append((j, comp, lo, hi))
    if not parts:
        raise ModelError('no spectrum component selected')
    return parts


def _half_spectra(parts: list[tuple[int, SpectrumComponent, float, float]], n_layers: int,
                  seed: int, scale: float, n_fft: int, dx: float) -> np.ndarray:
    """
    Return the half-spectra (4, n_fft // 2 + 1) of the track-geometry components.

    Rows in :data:`COMPONENTS` order; each bin carries the exact variance of its
    frequency interval, with a random phase from the layer's and component's
    own stream of ``seed``.
    """
    n_half = n_fft // 2 + 1
    top = (n_fft - 1) // 2          # highest bin below Nyquist
    dn = 1.0 / (n_fft * dx)
    streams = [s.spawn(len(COMPONENTS)) for s in np.random.SeedSequence(seed).spawn(n_layers)]
    coefficients = np.zeros((len(COMPONENTS), n_half), dtype=complex)
    for j, comp, lo, hi in parts:
        n_lo, n_hi = 1.0 / hi, 1.0 / lo
        if n_hi > (top + 0.5) * dn:
            message = (
                f'{comp.label}: wavelength_min = {lo:g} m is not resolved by dx = {dx:g} m '
                f'(need dx < wavelength_min / 2)')
            raise ModelError(message)
        c = COMPONENTS.index(comp.name)
        phases = np.random.default_rng(streams[j][c]).uniform(0.0, 2.0 * math.pi, n_half)
        k_first = max(1, math.floor(n_lo / dn + 0.5))
        k_last = min(top, math.ceil(n_hi / dn - 0.5))
        k = np.arange(k_first, k_last + 1)
        lower = np.maximum((k - 0.5) * dn, n_lo)
        upper = np.minimum((k + 0.5) * dn, n_hi)
        var = comp.integrate_intervals(lower, np.maximum(upper, lower))
        amplitude = scale * np.sqrt(2.0 * var)
        # irfft(Y)[m] = sum_k |Y_k| (2 / N) cos(2 pi k m / N + arg Y_k) for 0 < k < N/2
        coefficients[c, k] += 0.5 * n_fft * amplitude * np.exp(1j * phases[k])
    return coefficients


def _profiles(coefficients: np.ndarray, n_fft: int, n_req: int,
              dx: float) -> list[np.ndarray]:
    """Return the rail values, slopes and curvatures (4, n_req each, read-only)."""
    n_half = coefficients.shape[1]
    dn = 1.0 / (n_fft * dx)
    vertical, alignment, cross_level, gauge = coefficients
    rails = np.stack([vertical + 0.5 * cross_level, vertical - 0.5 * cross_level,
                      alignment + 0.5 * gauge, alignment - 0.5 * gauge])
    wavenumber = 2.0 * math.pi * dn * np.arange(n_half)
    arrays = []
    for factor in (1.0, 1j * wavenumber, -wavenumber**2):
        arr = fft.irfft(rails * factor, n=n_fft, axis=-1)[:, :n_req]
        arr = np.ascontiguousarray(arr)
        arr.flags.writeable = False
        arrays.append(arr)
    return arrays
