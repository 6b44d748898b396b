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
Rail irregularity profiles: synthesis from spectra, measured CSV, sampling.

Frame and signs (REP 103 track frame: x along the track, y to the LEFT, z UP):

- ``z_left``, ``z_right``: vertical irregularity of each rail (m); positive
  raises the rail.
- ``y_left``, ``y_right``: lateral irregularity of each rail (m); positive
  moves the rail to the left (+y).
- Composition from the track-geometry components of :mod:`.spectra`::

      z_left  = vertical + cross_level / 2      z_right = vertical - cross_level / 2
      y_left  = alignment + gauge / 2           y_right = alignment - gauge / 2

  so a positive cross-level raises the LEFT rail (cross_level = z_left -
  z_right) and a positive gauge irregularity widens the gauge (left rail to
  +y, right rail to -y; gauge = y_left - y_right).  PHYSICS.md 1.1 writes the
  combination with the opposite signs (``z_v -/+ z_c/2``); for a spectrum only
  the sign convention of the realisation changes, not its statistics.
- The Sato short-wave spectrum has a vertical component only; it is added to
  ``vertical``, i.e. identically to both rails (as a common rail-surface
  roughness; it adds nothing to cross-level).

Synthesis (PHYSICS.md 1.5) is the random-phase spectral representation
evaluated with one inverse real FFT per rail quantity and derivative order::

    q(x) = sum_k a_k cos(2 pi n_k (x - x_start) + phi_k),   phi_k ~ U(0, 2 pi)

with n_k = k / (N dx).  The amplitude of each bin is a_k = scale * sqrt(2 V_k),
where V_k is the integral of the one-sided PSD G over the part of the bin
[n_k - dn/2, n_k + dn/2] inside the band (not the rectangle G(n_k) dn).  Over
the whole FFT record the sample variance is therefore exactly the integral of
G over the band (V8), whatever the resolution.  The FFT record is at least
``MIN_RECORD_WAVELENGTHS`` times the longest wavelength; a shorter requested
track is the beginning of that record.  First and second derivatives along x
are obtained spectrally (factors i 2 pi n and -(2 pi n)^2).

Between grid points :meth:`TrackIrregularity.sample` uses the quintic Hermite
interpolant of the node values, slopes and curvatures: it passes through the
grid values, is twice continuously differentiable, and the slope and curvature
it returns are the exact derivatives of the value it returns.  Positions
outside the grid raise :class:`~ttb_sim.errors.ScenarioError` by default, or
give zeros (value and derivatives) with ``outside='zero'``.

Random streams: layer j, component c (index in ``COMPONENTS``) uses
``np.random.default_rng(np.random.SeedSequence(seed).spawn(n_layers)[j]
.spawn(4)[c])``, so every component has its own independent stream, fixed by
the seed alone (bit-for-bit reproducible).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import csv
from dataclasses import dataclass
import logging
import math
import operator
from os import PathLike
from pathlib import Path
from types import MappingProxyType
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft
from scipy.interpolate import CubicSpline

from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity.spectra import (COMPONENTS, get_spectrum, SPECTRA,
                                                SpectrumComponent, SpectrumFamily)

__all__ = [
    'CSV_COLUMNS',
    'IrregularityLayer',
    'IrregularitySample',
    'MIN_CSV_ROWS',
    'MIN_RECORD_WAVELENGTHS',
    'PRESETS',
    'RAIL_QUANTITIES',
    'TrackIrregularity',
    'VarianceCheck',
    'available_spectra',
    'check_variance',
    'load_csv',
    'save_csv',
    'synthesize',
]

_LOG = logging.getLogger(__name__)

#: Rail quantities, in the order of the first axis of every array here.
RAIL_QUANTITIES: tuple[str, ...] = ('z_left', 'z_right', 'y_left', 'y_right')

#: Columns a measured-profile CSV must have (any order; others are ignored).
CSV_COLUMNS: tuple[str, ...] = ('x', *RAIL_QUANTITIES)

#: Fewest data rows accepted from a CSV (a cubic spline needs four).
MIN_CSV_ROWS: int = 4

#: The FFT record spans at least this many times the longest wavelength.
MIN_RECORD_WAVELENGTHS: int = 8

#: Largest number of grid points a synthesis may allocate.
MAX_POINTS: int = 10_000_000

_GRID_SLACK = 1e-9   # tolerance, in grid steps, for positions and lengths


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


@dataclass(frozen=True)
class IrregularitySample:
    """
    Rail irregularities and their x-derivatives at a set of positions.

    The first axis of every array follows :data:`RAIL_QUANTITIES`
    (z_left, z_right, y_left, y_right); the other axes follow the shape of the
    positions asked for.

    Attributes
    ----------
    value : numpy.ndarray
        Irregularity (m).
    slope : numpy.ndarray
        First derivative d/dx (m/m).  Multiply by the speed V for a rate (m/s).
    curvature : numpy.ndarray
        Second derivative d^2/dx^2 (1/m).  Multiply by V^2 for m/s^2.

    """

    value: NDArray[np.float64]
    slope: NDArray[np.float64]
    curvature: NDArray[np.float64]

    def rail(
        self, name: str,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """
        Return (value, slope, curvature) of one rail quantity.

        Parameters
        ----------
        name : str
            One of :data:`RAIL_QUANTITIES`.

        Returns
        -------
        tuple of numpy.ndarray
            Value (m), slope (-), curvature (1/m).

        """
        i = RAIL_QUANTITIES.index(name)
        return self.value[i], self.slope[i], self.curvature[i]


@dataclass(frozen=True, eq=False)
class TrackIrregularity:
    """
    Realised rail irregularities on a uniform grid along the track.

    Attributes
    ----------
    x_start : float
        Position of the first grid point along the track (m).
    dx : float
        Grid spacing (m).
    values : numpy.ndarray
        Shape (4, N): z_left, z_right, y_left, y_right at the grid points (m).
    slopes : numpy.ndarray
        Shape (4, N): their first derivatives d/dx (-).
    curvatures : numpy.ndarray
        Shape (4, N): their second derivatives d^2/dx^2 (1/m).
    source : str
        Provenance, e.g. ``'paper seed=3 scale=1'`` or ``'csv:/path/file.csv'``.

    Notes
    -----
    The arrays are stored read-only.  Sign conventions are given in the
    module docstring.

    """

    x_start: float
    dx: float
    values: NDArray[np.float64]
    slopes: NDArray[np.float64]
    curvatures: NDArray[np.float64]
    source: str = ''

    def __post_init__(self) -> None:
        if not (math.isfinite(self.x_start) and math.isfinite(self.dx) and self.dx > 0.0):
            raise ValueError(f'need finite x_start and dx > 0, got {self.x_start}, {self.dx}')
        shape = None
        for name in ('values', 'slopes', 'curvatures'):
            arr = getattr(self, name)
            if not (isinstance(arr, np.ndarray) and arr.dtype == np.float64
                    and not arr.flags.writeable):
                arr = np.array(arr, dtype=np.float64)
                arr.flags.writeable = False
                object.__setattr__(self, name, arr)
            if arr.ndim != 2 or arr.shape[0] != len(RAIL_QUANTITIES) or arr.shape[1] < 2:
                raise ValueError(f'{name} must have shape (4, N) with N >= 2, got {arr.shape}')
            if shape is not None and arr.shape != shape:
                raise ValueError(f'{name} has shape {arr.shape}, values has {shape}')
            if not np.all(np.isfinite(arr)):
                raise ValueError(f'{name} contains non-finite numbers')
            shape = arr.shape

    @property
    def n_points(self) -> int:
        """Return the number of grid points."""
        return int(self.values.shape[1])

    @property
    def x_end(self) -> float:
        """Return the position of the last grid point (m)."""
        return self.x_start + (self.n_points - 1) * self.dx

    @property
    def length(self) -> float:
        """Return the covered length x_end - x_start (m)."""
        return (self.n_points - 1) * self.dx

    @property
    def x(self) -> NDArray[np.float64]:
        """Return the grid positions (m)."""
        return self.x_start + self.dx * np.arange(self.n_points)

    @property
    def z_left(self) -> NDArray[np.float64]:
        """Return the vertical irregularity of the left rail at the grid (m, up)."""
        return self.values[0]

    @property
    def z_right(self) -> NDArray[np.float64]:
        """Return the vertical irregularity of the right rail at the grid (m, up)."""
        return self.values[1]

    @property
    def y_left(self) -> NDArray[np.float64]:
        """Return the lateral irregularity of the left rail at the grid (m, to the left)."""
        return self.values[2]

    @property
    def y_right(self) -> NDArray[np.float64]:
        """Return the lateral irregularity of the right rail at the grid (m, to the left)."""
        return self.values[3]

    def geometry(self, component: str) -> NDArray[np.float64]:
        """
        Return a track-geometry component recovered from the rails.

        Parameters
        ----------
        component : str
            ``vertical`` = (z_left + z_right)/2, ``cross_level`` = z_left -
            z_right, ``alignment`` = (y_left + y_right)/2 or ``gauge`` =
            y_left - y_right.

        Returns
        -------
        numpy.ndarray
            The component at the grid points (m).

        Raises
        ------
        ValueError
            If the component name is unknown.

        """
        z_l, z_r, y_l, y_r = self.values
        if component == 'vertical':
            return 0.5 * (z_l + z_r)
        if component == 'cross_level':
            return z_l - z_r
        if component == 'alignment':
            return 0.5 * (y_l + y_r)
        if component == 'gauge':
            return y_l - y_r
        raise ValueError(f'unknown component {component!r}; expected one of {COMPONENTS}')

    def sample(
        self, x: ArrayLike, *, outside: Literal['raise', 'zero'] = 'raise',
    ) -> IrregularitySample:
        """
        Evaluate the rail irregularities and their derivatives at positions.

        Parameters
        ----------
        x : array_like
            Positions along the track (m), any shape.
        outside : {'raise', 'zero'}
            What to do with positions outside [x_start, x_end]: raise
            :class:`ScenarioError` (default), or return zero value, slope and
            curvature there (a smooth track before and after the profile).

        Returns
        -------
        IrregularitySample
            Arrays of shape (4,) + x.shape.

        Raises
        ------
        ScenarioError
            With ``outside='raise'``, if a position is outside the profile or
            not finite.

        """
        xq = np.asarray(x, dtype=float)
        s = (xq - self.x_start) / self.dx
        last = self.n_points - 1
        inside = (s >= -_GRID_SLACK) & (s <= last + _GRID_SLACK)
        all_inside = bool(np.all(inside))
        if not all_inside:
            if outside == 'raise':
                bad = xq[~inside].flat[0]
                message = (
                    f'irregularity profile covers x = {self.x_start:g} to {self.x_end:g} m; '
                    f'position x = {bad:g} m is outside it (generate or load a longer profile)')
                raise ScenarioError(message)
            if outside != 'zero':
                raise ValueError(f"outside must be 'raise' or 'zero', got {outside!r}")
            s = np.where(inside, s, 0.0)
        i = np.clip(np.floor(s), 0, last - 1).astype(np.intp)
        t = s - i
        h = self.dx
        p0, p1 = self.values[:, i], self.values[:, i + 1]
        m0, m1 = h * self.slopes[:, i], h * self.slopes[:, i + 1]
        c0, c1 = h * h * self.curvatures[:, i], h * h * self.curvatures[:, i + 1]
        # Quintic Hermite on [0, 1]: p = a0 + a1 t + ... + a5 t^5 matching
        # value, first and second derivative at both ends.
        a2 = 0.5 * c0
        d0 = p1 - (p0 + m0 + a2)
        d1 = m1 - (m0 + c0)
        d2 = c1 - c0
        a3 = 10.0 * d0 - 4.0 * d1 + 0.5 * d2
        a4 = -15.0 * d0 + 7.0 * d1 - d2
        a5 = 6.0 * d0 - 3.0 * d1 + 0.5 * d2
        value = p0 + t * (m0 + t * (a2 + t * (a3 + t * (a4 + t * a5))))
        slope = (m0 + t * (2.0 * a2 + t * (3.0 * a3 + t * (4.0 * a4 + t * 5.0 * a5)))) / h
        curvature = (2.0 * a2 + t * (6.0 * a3 + t * (12.0 * a4 + t * 20.0 * a5))) / (h * h)
        if not all_inside:
            value = np.where(inside, value, 0.0)
            slope = np.where(inside, slope, 0.0)
            curvature = np.where(inside, curvature, 0.0)
        return IrregularitySample(value, slope, curvature)


# --- synthesis -----------------------------------------------------------------------------

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
            raise ScenarioError(message)
        return PRESETS[spectrum], spectrum
    if isinstance(spectrum, (str, SpectrumFamily)):
        family = get_spectrum(spectrum)
        return (IrregularityLayer(family, wavelength_min, wavelength_max),), family.name
    if isinstance(spectrum, IrregularityLayer):
        spectrum = (spectrum,)
    layers = tuple(spectrum)
    if band_given:
        raise ScenarioError('give the bands inside the IrregularityLayer objects')
    if not layers or not all(isinstance(layer, IrregularityLayer) for layer in layers):
        raise ScenarioError(f'not a spectrum name, family or layers: {spectrum!r}')
    label = '+'.join(get_spectrum(layer.spectrum).name for layer in layers)
    return layers, label


def _n_points(length: float, dx: float) -> int:
    """Return the number of grid points covering ``length`` at spacing ``dx``."""
    return int(math.ceil(length / dx - _GRID_SLACK)) + 1


def _to_float(name: str, value: float) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ScenarioError(f'{name} must be a number, got {value!r}') from None


def _check_positive(name: str, value: float) -> float:
    number = _to_float(name, value)
    if not (math.isfinite(number) and number > 0.0):
        raise ScenarioError(f'{name} must be a finite number > 0, got {value!r}')
    return number


def _check_seed(seed: int) -> int:
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ScenarioError(f'seed must be an integer >= 0, got {seed!r}')
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
    ScenarioError
        On an unknown spectrum or component, an invalid number, a band the
        grid cannot resolve, or a grid larger than ``MAX_POINTS``.

    """
    layers, label = _resolve_layers(spectrum, wavelength_min, wavelength_max)
    if components is not None:
        if len(layers) != 1:
            raise ScenarioError('components= applies to a single spectrum family only')
        layers = (IrregularityLayer(layers[0].spectrum, layers[0].wavelength_min,
                                    layers[0].wavelength_max, tuple(components)),)
    length = _check_positive('length', length)
    dx = _check_positive('dx', dx)
    seed = _check_seed(seed)
    scale = _to_float('scale', scale)
    if not (math.isfinite(scale) and scale >= 0.0):
        raise ScenarioError(f'scale must be a finite number >= 0, got {scale!r}')
    x_start = _to_float('x_start', x_start)
    if not math.isfinite(x_start):
        raise ScenarioError(f'x_start must be finite, got {x_start!r}')

    # Resolve every (layer, component) and its band.
    parts: list[tuple[int, SpectrumComponent, float, float]] = []
    for j, layer in enumerate(layers):
        family = get_spectrum(layer.spectrum)
        names = tuple(family.components) if layer.components is None else layer.components
        if len(set(names)) != len(names):
            raise ScenarioError(f'{family.name}: a component is listed twice in {names}')
        for name in names:
            comp = family.component(name)
            lo, hi = comp.band(layer.wavelength_min, layer.wavelength_max)
            parts.append((j, comp, lo, hi))
    if not parts:
        raise ScenarioError('no spectrum component selected')
    longest = max(hi for _, _, _, hi in parts)

    n_req = _n_points(length, dx)
    n_fft = max(n_req, _n_points(MIN_RECORD_WAVELENGTHS * longest, dx))
    if n_fft > MAX_POINTS:
        message = (
            f'irregularity grid of {n_fft} points (length {length:g} m, longest wavelength '
            f'{longest:g} m, dx {dx:g} m) exceeds the limit of {MAX_POINTS}; increase dx')
        raise ScenarioError(message)
    n_half = n_fft // 2 + 1
    top = (n_fft - 1) // 2          # highest bin below Nyquist
    dn = 1.0 / (n_fft * dx)

    streams = [s.spawn(len(COMPONENTS)) for s in np.random.SeedSequence(seed).spawn(len(layers))]
    # Half-spectra of the track-geometry components, in COMPONENTS order.
    coefficients = np.zeros((len(COMPONENTS), n_half), dtype=complex)
    for j, comp, lo, hi in parts:
        n_lo, n_hi = 1.0 / hi, 1.0 / lo
        if n_hi > (top + 0.5) * dn:
            message = (
                f'{comp.label}: wavelength_min = {lo:g} m is not resolved by dx = {dx:g} m '
                f'(need dx < wavelength_min / 2)')
            raise ScenarioError(message)
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
    _LOG.debug('synthesised %s: %d points (FFT %d), dx %g m, seed %d, scale %g',
               label, n_req, n_fft, dx, seed, scale)
    return TrackIrregularity(x_start, dx, *arrays, source=f'{label} seed={seed} scale={scale:g}')


# --- validation quantities (V8, V10) -------------------------------------------------------

@dataclass(frozen=True)
class VarianceCheck:
    """
    Synthesised variance of one spectrum component against its PSD integral.

    Attributes
    ----------
    spectrum, component : str
        What was checked.
    wavelength_min, wavelength_max : float
        Band (m).
    seeds : int
        Number of realisations (seeds 0 ... seeds-1).
    target_variance : float
        Integral of G(n) dn over the band, by adaptive quadrature (m^2).
    sample_variance : float
        Mean over the realisations of the sample variance of the component
        recovered from the synthesised rails (m^2).

    """

    spectrum: str
    component: str
    wavelength_min: float
    wavelength_max: float
    seeds: int
    target_variance: float
    sample_variance: float

    @property
    def relative_error(self) -> float:
        """Return sample_variance / target_variance - 1."""
        return self.sample_variance / self.target_variance - 1.0

    @property
    def target_rms(self) -> float:
        """Return the RMS (m) from the PSD integral."""
        return math.sqrt(self.target_variance)

    @property
    def sample_rms(self) -> float:
        """Return the RMS (m) from the synthesised profiles."""
        return math.sqrt(self.sample_variance)


def check_variance(
    spectrum: str | SpectrumFamily,
    component: str,
    *,
    wavelength_min: float | None = None,
    wavelength_max: float | None = None,
    seeds: int = 20,
    points_per_wavelength: int = 8,
) -> VarianceCheck:
    """
    Compute the V8/V10 quantities for one spectrum component.

    Synthesises ``seeds`` profiles of that component alone with
    :func:`synthesize` (record of ``MIN_RECORD_WAVELENGTHS`` longest
    wavelengths, ``points_per_wavelength`` points per shortest wavelength),
    recovers the component from the rails and compares the mean sample
    variance with the integral of the PSD over the band.

    Parameters
    ----------
    spectrum : str or SpectrumFamily
        Spectrum family or its registry name.
    component : str
        Component name.
    wavelength_min, wavelength_max : float, optional
        Band (m); default: the component's default band.
    seeds : int
        Number of realisations.
    points_per_wavelength : int
        Grid points per shortest wavelength (>= 3).

    Returns
    -------
    VarianceCheck
        Target and synthesised variances.

    """
    family = get_spectrum(spectrum)
    comp = family.component(component)
    lo, hi = comp.band(wavelength_min, wavelength_max)
    if int(seeds) < 1 or int(points_per_wavelength) < 3:
        raise ScenarioError('need seeds >= 1 and points_per_wavelength >= 3')
    dx = lo / points_per_wavelength
    variances = [
        np.var(synthesize(family, length=MIN_RECORD_WAVELENGTHS * hi, dx=dx, seed=seed,
                          wavelength_min=lo, wavelength_max=hi,
                          components=(component,)).geometry(component))
        for seed in range(seeds)
    ]
    return VarianceCheck(
        spectrum=family.name, component=component, wavelength_min=lo, wavelength_max=hi,
        seeds=seeds, target_variance=comp.variance(lo, hi),
        sample_variance=float(np.mean(variances)))


# --- measured profiles ---------------------------------------------------------------------

def save_csv(irregularity: TrackIrregularity, path: str | PathLike[str]) -> None:
    """
    Write the grid values of a profile as CSV readable by :func:`load_csv`.

    Parameters
    ----------
    irregularity : TrackIrregularity
        Profile to write; values are written with 17 significant digits.
    path : str or os.PathLike
        Output file.

    Raises
    ------
    ScenarioError
        If the file cannot be written.

    """
    table = np.column_stack([irregularity.x, irregularity.values.T])
    try:
        np.savetxt(path, table, fmt='%.17g', delimiter=',', header=','.join(CSV_COLUMNS),
                   comments='')
    except OSError as exc:
        raise ScenarioError(f'{path}: cannot write irregularity file: {exc}') from None


def _refuse(path: str | PathLike[str], row: int | None, problem: str) -> ScenarioError:
    where = f'{path}' if row is None else f'{path}: row {row}'
    return ScenarioError(f'{where}: {problem}')


def load_csv(
    path: str | PathLike[str],
    *,
    min_length: float | None = None,
    dx: float | None = None,
) -> TrackIrregularity:
    """
    Load a measured rail irregularity profile from CSV.

    The file has a header row naming at least the columns ``x, z_left,
    z_right, y_left, y_right`` (any order; other columns are ignored), then one
    row per position: x along the track (m, strictly increasing) and the rail
    irregularities (m, signs as in the module docstring).  Blank lines and
    lines starting with ``#`` are skipped.  Row numbers in messages are line
    numbers of the file, counting from 1 (the header is usually row 1).

    A not-a-knot cubic spline through the data gives slopes and curvatures.
    If the rows are uniformly spaced (relative spread of the spacing below
    1e-6) and ``dx`` is not given, the grid is the rows themselves and the
    values are kept exactly; otherwise the spline is resampled onto a uniform
    grid of spacing ``dx`` (default: the median spacing of the rows) starting
    at the first x.

    Parameters
    ----------
    path : str or os.PathLike
        CSV file.
    min_length : float, optional
        Length (m) the profile must cover, x_last - x_first.
    dx : float, optional
        Spacing (m) of the uniform grid to resample onto.

    Returns
    -------
    TrackIrregularity
        The profile.

    Raises
    ------
    ScenarioError
        If the file cannot be read, a required column is missing, a row has
        the wrong number of fields or a non-numeric / non-finite value, x does
        not strictly increase, there are fewer than ``MIN_CSV_ROWS`` rows, or
        the profile is shorter than ``min_length``.  The message names the
        file and the row.

    """
    try:
        text = Path(path).read_text(encoding='utf-8-sig')
    except (OSError, UnicodeDecodeError) as exc:
        raise _refuse(path, None, f'cannot read irregularity file ({exc})') from None
    lines = text.splitlines()
    rows = list(csv.reader(lines))
    if len(rows) != len(lines):   # a quoted field spanning lines
        raise _refuse(path, None, 'unbalanced quotes; cannot parse as CSV')
    stripped = np.char.strip(np.array(lines, dtype=str)) if lines else np.array([], dtype=str)
    content = np.flatnonzero((stripped != '') & ~np.char.startswith(stripped, '#'))
    if content.size == 0:
        raise _refuse(path, 1, f'no header; expected columns {", ".join(CSV_COLUMNS)}')

    header_index = int(content[0])
    header = [name.strip() for name in rows[header_index]]
    missing = [name for name in CSV_COLUMNS if name not in header]
    if missing:
        message = (
            f'header is missing column(s) {", ".join(missing)}; '
            f'expected {", ".join(CSV_COLUMNS)}, found {", ".join(header)}')
        raise _refuse(path, header_index + 1, message)
    duplicated = sorted({name for name in CSV_COLUMNS if header.count(name) > 1})
    if duplicated:
        raise _refuse(path, header_index + 1, f'duplicated column(s) {", ".join(duplicated)}')

    data_index = content[1:]
    row_numbers = data_index + 1
    if data_index.size < MIN_CSV_ROWS:
        last = f'last data row {row_numbers[-1]}' if data_index.size else 'no data rows'
        message = (
            f'too few rows: {data_index.size} data row(s) ({last}), need at least '
            f'{MIN_CSV_ROWS}')
        raise _refuse(path, int(row_numbers[-1]) if data_index.size else header_index + 1,
                      message)
    widths = np.fromiter(map(len, rows), dtype=np.intp, count=len(rows))[data_index]
    wrong = np.flatnonzero(widths != len(header))
    if wrong.size:
        r = wrong[0]
        message = f'expected {len(header)} fields as in the header, found {widths[r]}'
        raise _refuse(path, int(row_numbers[r]), message)
    table = np.array(operator.itemgetter(*data_index)(rows), dtype=str)
    cells = np.char.strip(table[:, [header.index(name) for name in CSV_COLUMNS]])
    try:
        numbers = cells.astype(np.float64)
    except ValueError:
        parsed = np.frompyfunc(_parses_as_float, 1, 1)(cells).astype(bool)
        r, c = np.argwhere(~parsed)[0]
        message = f'non-numeric value {str(cells[r, c])!r} in column {CSV_COLUMNS[c]}'
        raise _refuse(path, int(row_numbers[r]), message) from None
    bad = np.argwhere(~np.isfinite(numbers))
    if bad.size:
        r, c = bad[0]
        message = f'value {str(cells[r, c])!r} in column {CSV_COLUMNS[c]} is not a finite number'
        raise _refuse(path, int(row_numbers[r]), message)

    x = numbers[:, 0]
    rails = numbers[:, 1:].T
    steps = np.diff(x)
    decreasing = np.flatnonzero(steps <= 0.0)
    if decreasing.size:
        r = decreasing[0] + 1
        message = (
            f'x = {x[r]:g} m does not increase strictly (previous data row {row_numbers[r - 1]} '
            f'has x = {x[r - 1]:g} m)')
        raise _refuse(path, int(row_numbers[r]), message)
    covered = x[-1] - x[0]
    if min_length is not None and covered < float(min_length) * (1.0 - _GRID_SLACK):
        message = (
            f'profile too short: it covers {covered:g} m (x = {x[0]:g} to {x[-1]:g} m, last '
            f'data row {row_numbers[-1]}), {float(min_length):g} m is needed')
        raise _refuse(path, int(row_numbers[-1]), message)

    spacing = float(np.median(steps))
    uniform = bool(np.max(np.abs(steps - spacing)) <= 1e-6 * spacing)
    spline = CubicSpline(x, rails, axis=1)
    if dx is None and uniform:
        grid_dx = covered / (x.size - 1)
        values = rails
        grid = x
    else:
        grid_dx = spacing if dx is None else _check_positive('dx', dx)
        grid = x[0] + grid_dx * np.arange(int(math.floor(covered / grid_dx + _GRID_SLACK)) + 1)
        if grid.size < 2:
            raise _refuse(path, None, f'dx = {grid_dx:g} m is longer than the profile')
        values = spline(grid)
        _LOG.info('%s: resampled %d rows onto %d points at dx = %g m',
                  path, x.size, grid.size, grid_dx)
    return TrackIrregularity(
        float(x[0]), grid_dx, values, spline(grid, 1), spline(grid, 2), source=f'csv:{path}')


def _parses_as_float(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True
