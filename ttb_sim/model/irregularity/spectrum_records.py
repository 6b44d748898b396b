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
A track irregularity spectrum: its components and families (PHYSICS.md section 1).

A :class:`SpectrumComponent` is one ONE-SIDED spatial PSD G(n) in
m^2 / (cycle/m) of the spatial frequency n (cycles/m), with its default
wavelength band and the integrals over a band (adaptive quadrature) and over
many frequency intervals at once (Gauss-Legendre, for the synthesis). A
:class:`SpectrumFamily` is a named set of components among :data:`COMPONENTS`.
The published spectra and their registry are in :mod:`.spectra`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
import math
from types import MappingProxyType

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import integrate

from ttb_sim.errors import ModelError

__all__ = ['COMPONENTS', 'PsdFunction', 'SpectrumComponent', 'SpectrumFamily']

#: Names of the track-geometry components, in the canonical order.
COMPONENTS: tuple[str, ...] = ('vertical', 'alignment', 'cross_level', 'gauge')

_GAUSS_NODES, _GAUSS_WEIGHTS = np.polynomial.legendre.leggauss(8)

PsdFunction = Callable[[NDArray[np.float64]], NDArray[np.float64]]


@dataclass(frozen=True)
class SpectrumComponent:
    """
    One component of a track irregularity spectrum.

    Attributes
    ----------
    family : str
        Name of the spectrum family, e.g. ``'chinese_hsr'``.
    name : str
        Component name, one of :data:`COMPONENTS`.
    density : callable
        Function of n (cycles/m, array, n > 0) returning G(n) in m^2/(cycle/m).
        Prefer :meth:`psd`, which validates its argument.
    wavelength_min, wavelength_max : float
        Default band (m) used when a synthesis does not give one.
    breakpoints : tuple of float
        Spatial frequencies (cycles/m) where the PSD changes formula; the
        integrators split their intervals there.
    units : str
        Human-readable note on the source units and the conversion applied.

    """

    family: str
    name: str
    density: PsdFunction = field(repr=False)
    wavelength_min: float
    wavelength_max: float
    breakpoints: tuple[float, ...] = ()
    units: str = ''

    def __post_init__(self) -> None:
        if not 0.0 < self.wavelength_min < self.wavelength_max:
            message = (
                f'{self.family}.{self.name}: need 0 < wavelength_min < wavelength_max, '
                f'got {self.wavelength_min} and {self.wavelength_max} m')
            raise ModelError(message)

    @property
    def label(self) -> str:
        """Return ``'family.component'``."""
        return f'{self.family}.{self.name}'

    def psd(self, n: ArrayLike) -> NDArray[np.float64]:
        """
        Evaluate the one-sided PSD.

        Parameters
        ----------
        n : array_like
            Spatial frequency (cycles/m), every value > 0.

        Returns
        -------
        numpy.ndarray
            G(n) in m^2/(cycle/m), same shape as ``n``.

        Raises
        ------
        ModelError
            If any frequency is not a positive finite number.

        """
        freq = np.asarray(n, dtype=float)
        if not np.all(np.isfinite(freq) & (freq > 0.0)):
            raise ModelError(f'{self.label}: spatial frequencies must be finite and > 0')
        return self.density(freq)

    def band(
        self, wavelength_min: float | None = None, wavelength_max: float | None = None,
    ) -> tuple[float, float]:
        """
        Return a wavelength band, falling back to the component defaults.

        Parameters
        ----------
        wavelength_min, wavelength_max : float, optional
            Band limits (m); ``None`` takes the default of the component.

        Returns
        -------
        tuple of float
            ``(wavelength_min, wavelength_max)`` in m.

        Raises
        ------
        ModelError
            If the band is empty or not positive.

        """
        lo = self.wavelength_min if wavelength_min is None else float(wavelength_min)
        hi = self.wavelength_max if wavelength_max is None else float(wavelength_max)
        if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
            message = (
                f'{self.label}: wavelength band must satisfy 0 < wavelength_min < '
                f'wavelength_max, got {lo} m and {hi} m')
            raise ModelError(message)
        return lo, hi

    def variance(
        self, wavelength_min: float | None = None, wavelength_max: float | None = None,
    ) -> float:
        """
        Integrate G(n) over a wavelength band with adaptive quadrature.

        Parameters
        ----------
        wavelength_min, wavelength_max : float, optional
            Band limits (m); ``None`` takes the default of the component.

        Returns
        -------
        float
            Variance (m^2) of the irregularity restricted to the band.

        """
        lo, hi = self.band(wavelength_min, wavelength_max)
        n_lo, n_hi = 1.0 / hi, 1.0 / lo
        inner = [b for b in self.breakpoints if n_lo < b < n_hi]
        # Integrate over log(n): the spectra are close to power laws, so the
        # integrand G(n) n varies slowly in log(n).
        edges = [math.log(n_lo), *(math.log(b) for b in inner), math.log(n_hi)]
        total = 0.0
        for a, b in zip(edges[:-1], edges[1:]):
            value, _ = integrate.quad(
                lambda s: float(self.density(np.exp(s)) * math.exp(s)),
                a, b, epsabs=0.0, epsrel=1e-11, limit=200)
            total += value
        return total

    def rms(
        self, wavelength_min: float | None = None, wavelength_max: float | None = None,
    ) -> float:
        """
        Return the RMS (m) of the component over a wavelength band.

        Parameters
        ----------
        wavelength_min, wavelength_max : float, optional
            Band limits (m); ``None`` takes the default of the component.

        Returns
        -------
        float
            Square root of :meth:`variance`, in m.

        """
        return math.sqrt(self.variance(wavelength_min, wavelength_max))

    def integrate_intervals(
        self, lower: NDArray[np.float64], upper: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """
        Integrate G(n) over many frequency intervals at once.

        Used by the synthesis to give each discrete frequency bin the exact
        variance it represents.  Each interval is split at the breakpoints and
        integrated with 8-point Gauss-Legendre quadrature (vectorised).

        Parameters
        ----------
        lower, upper : numpy.ndarray
            Interval limits (cycles/m), same shape, 0 < lower <= upper.

        Returns
        -------
        numpy.ndarray
            Integral of G over each interval (m^2).

        """
        lower = np.asarray(lower, dtype=float)
        upper = np.asarray(upper, dtype=float)
        total = np.zeros(np.broadcast(lower, upper).shape)
        edges = (-np.inf, *self.breakpoints, np.inf)
        for seg_lo, seg_hi in zip(edges[:-1], edges[1:]):
            a = np.clip(lower, seg_lo, seg_hi)
            b = np.clip(upper, seg_lo, seg_hi)
            half = 0.5 * (b - a)
            used = half > 0.0
            if not np.any(used):
                continue
            mid = 0.5 * (a + b)[used]
            nodes = mid[:, np.newaxis] + half[used][:, np.newaxis] * _GAUSS_NODES
            total[used] += half[used] * (self.density(nodes) @ _GAUSS_WEIGHTS)
        return total


@dataclass(frozen=True)
class SpectrumFamily:
    """
    A named spectrum with one or more components.

    Attributes
    ----------
    name : str
        Registry name, e.g. ``'german_low'``.
    description : str
        Source and scope, one line.
    components : Mapping[str, SpectrumComponent]
        Components by name (a subset of :data:`COMPONENTS`).

    """

    name: str
    description: str
    components: Mapping[str, SpectrumComponent]

    def __post_init__(self) -> None:
        unknown = set(self.components) - set(COMPONENTS)
        if unknown:
            raise ModelError(f'{self.name}: unknown components {sorted(unknown)}')
        ordered = {c: self.components[c] for c in COMPONENTS if c in self.components}
        object.__setattr__(self, 'components', MappingProxyType(ordered))

    def component(self, name: str) -> SpectrumComponent:
        """
        Return one component.

        Parameters
        ----------
        name : str
            Component name, one of :data:`COMPONENTS`.

        Returns
        -------
        SpectrumComponent
            The component.

        Raises
        ------
        ModelError
            If this family has no such component.

        """
        try:
            return self.components[name]
        except KeyError:
            message = (
                f'spectrum {self.name!r} has no component {name!r}; '
                f'it has {", ".join(self.components)}')
            raise ModelError(message) from None
