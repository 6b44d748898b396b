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
Validation quantities of the synthesis (VALIDATION.md V8, V10).

The variance of a spectrum component synthesised by
:mod:`ttb_sim.model.irregularity.synthesis`,
averaged over seeds, against the integral of its PSD over the band.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity.spectra import get_spectrum
from ttb_sim.model.irregularity.spectrum_records import SpectrumFamily
from ttb_sim.model.irregularity.synthesis import MIN_RECORD_WAVELENGTHS, synthesize

__all__ = [
    'VarianceCheck',
    'check_variance',
]


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
        raise ModelError('need seeds >= 1 and points_per_wavelength >= 3')
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
