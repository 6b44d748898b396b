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
Component validation cases V4, V5, V8, V9 and V10 (VALIDATION.md).

Every number comes from the package code a simulation uses: the car matrices
and their eigen-analysis (:mod:`ttb_sim.model.vehicle.car`), the Hertz contact law
(:mod:`ttb_sim.model.wheel_rail`) and the irregularity synthesis
(:mod:`ttb_sim.model.irregularity`).  Only the
post-processing (naming modes by their shape, Welch PSD per octave band) is
written here.

Rows
----
V4  one row per mode group (car-body bounce and pitch, bogie pitch and
    bounce); the bogie groups hold two modes (front and rear bogie in and out
    of phase), the row shows the one farther from the reference.
V5  static compression and linearised stiffness of the LM tread.
V8  one row per spectrum family: the component whose ensemble variance is
    farthest from the PSD integral (all components are checked).
V9  one row per spectrum family: the octave band and component whose Welch /
    target ratio is farthest from 1.
V10 RMS of the synthesised Chinese HSR vertical profiles and of the PSD
    integral over 2-200 m.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
import math

import numpy as np
from scipy import signal

from ttb_sim.model.irregularity import SPECTRA, synthesize
import ttb_sim.model.vehicle as car
from ttb_sim.model.wheel_rail import hertz_constant, linearised_stiffness, static_compression
from ttb_sim.validation.references.irregularity import check_variance, VarianceCheck
from ttb_sim.validation.rows import Case, relative_row, Row

#: Car body and bogies: the bodies left free in V4 (wheelsets held).
V4_BODIES = ('car_body', 'bogie_1', 'bogie_2')

#: V4 reference frequencies (Hz), PHYSICS.md 3.1.
V4_REFERENCE: Mapping[str, float] = {
    'car_body_bounce': 0.840, 'car_body_pitch': 0.952,
    'bogie_pitch': 4.78, 'bogie_bounce': 6.27}

#: Number of modes of each V4 group (one per bogie for the bogie groups).
V4_MODE_COUNT: Mapping[str, int] = {
    'car_body_bounce': 1, 'car_body_pitch': 1, 'bogie_pitch': 2, 'bogie_bounce': 2}

#: Smallest kinetic-energy share that names a mode after a DOF group.
MODE_SHARE = 0.5

#: Seeds of the V8 / V10 ensembles (seeds 0 ... n-1).
ENSEMBLE_SEEDS = 20

#: Seed of the V9 profile.
WELCH_SEED = 11


def _groups() -> dict[str, list[int]]:
    """DOF indices of each V4 mode group."""
    bogies = V4_BODIES[1:]
    return {'car_body_bounce': [car.dof('car_body', 'z')],
            'car_body_pitch': [car.dof('car_body', 'pitch')],
            'bogie_bounce': [car.dof(b, 'z') for b in bogies],
            'bogie_pitch': [car.dof(b, 'pitch') for b in bogies]}


def vertical_modes(params: car.CarParameters | None = None) -> dict[str, list[float]]:
    """
    Return the vertical modes of car body and bogies, wheelsets held, named by shape.

    The z and pitch DOFs of the car body and both bogies are kept free
    (:func:`ttb_sim.model.vehicle.car.eigenfrequencies`); every mode is named after
    the DOF group (car-body bounce, car-body pitch, bogie bounce, bogie
    pitch) holding more than ``MODE_SHARE`` of its kinetic energy.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    dict
        Frequencies (Hz, ascending) by group name; modes that no group
        dominates are listed under ``'mixed'``.

    """
    matrices = car.car_matrices(params)
    subset = car.dofs(V4_BODIES, ['z', 'pitch'])
    freq, modes = car.eigenfrequencies(matrices.mass, matrices.stiffness, subset)
    energy = np.diag(matrices.mass)[:, np.newaxis] * modes**2
    energy /= energy.sum(axis=0)
    names = list(_groups())
    shares = np.array([energy[idx].sum(axis=0) for idx in _groups().values()])
    named: dict[str, list[float]] = {name: [] for name in [*names, 'mixed']}
    for f, column in zip(freq, shares.T):
        best = int(np.argmax(column))
        named[names[best] if column[best] > MODE_SHARE else 'mixed'].append(float(f))
    return named


def v4_rows(params: car.CarParameters | None = None,
            reference: Mapping[str, float] = V4_REFERENCE) -> list[Row]:
    """
    Build the V4 rows: vertical car frequencies vs PHYSICS.md 3.1 (1 %).

    A group with the wrong number of modes gives a NaN (failing) row.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.
    reference : Mapping[str, float]
        Reference frequency (Hz) of each group.

    Returns
    -------
    list of Row
        Car-body bounce, car-body pitch, bogie pitch, bogie bounce.

    """
    named = vertical_modes(params)
    rows = []
    for group in ('car_body_bounce', 'car_body_pitch', 'bogie_pitch', 'bogie_bounce'):
        freqs, f_ref = named[group], reference[group]
        if len(freqs) == V4_MODE_COUNT[group]:
            computed = max(freqs, key=lambda f: abs(f - f_ref))
        else:
            computed = math.nan
        label = group.replace('car_body', 'car-body').replace('_', ' ')
        if V4_MODE_COUNT[group] > 1:
            label += f' (worst of {V4_MODE_COUNT[group]})'
        rows.append(relative_row('V4', label, computed, f_ref, 0.01, 'Hz'))
    return rows


def v5_rows(params: car.CarParameters | None = None, tread: str = 'lm',
            compression_reference: float = 77e-6,
            stiffness_reference: float = 1.52e9) -> list[Row]:
    """
    Build the V5 rows: Hertz contact at the car's static wheel load (1 %).

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters (static wheel load, wheel radius); Table 1 if omitted.
    tread : {'lm', 'conical'}
        Tread type of the contact constant.
    compression_reference : float
        Reference static compression (m), PHYSICS.md 2.1.
    stiffness_reference : float
        Reference linearised stiffness (N/m), PHYSICS.md 2.1.

    Returns
    -------
    list of Row
        Static compression (um) and linearised stiffness (N/m).

    """
    p = params or car.CarParameters()
    g = hertz_constant(p.wheel_radius, tread)
    load = p.static_wheel_load
    compression = float(static_compression(load, g))
    stiffness = float(linearised_stiffness(load, g))
    name = 'LM' if tread == 'lm' else tread
    return [relative_row('V5', f'static compression, {name} tread', compression * 1e6,
                         compression_reference * 1e6, 0.01, 'um'),
            relative_row('V5', f'linearised stiffness, {name} tread', stiffness,
                         stiffness_reference, 0.01, 'N/m')]


def _label(family: str, component: str, n_components: int) -> str:
    """Row label of the worst component of a family."""
    return f'{family}.{component}' + (' (worst)' if n_components > 1 else '')


def variance_checks(seeds: int = ENSEMBLE_SEEDS) -> dict[str, list[VarianceCheck]]:
    """
    Run :func:`ttb_sim.validation.references.irregularity.check_variance` on every component.

    Parameters
    ----------
    seeds : int
        Realisations per component (seeds 0 ... seeds-1), default band.

    Returns
    -------
    dict
        Checks of every component, by spectrum family.

    """
    return {family: [check_variance(family, c, seeds=seeds) for c in spec.components]
            for family, spec in SPECTRA.items()}


def variance_row(checks: Sequence[VarianceCheck]) -> Row:
    """
    Build the V8 row of one family: the component farthest from its PSD integral.

    Parameters
    ----------
    checks : sequence of VarianceCheck
        The checks of every component of one family.

    Returns
    -------
    Row
        Ensemble sample variance vs integral of G (mm^2), tolerance 2 %.

    """
    worst = max(checks, key=lambda c: abs(c.relative_error))
    return relative_row('V8', _label(worst.spectrum, worst.component, len(checks)),
                        worst.sample_variance * 1e6, worst.target_variance * 1e6, 0.02, 'mm^2')


def v8_rows() -> list[Row]:
    """Build the V8 rows: one per spectrum family, all components checked."""
    return [variance_row(checks) for checks in variance_checks().values()]


def octave_ratios(family: str, component: str, seed: int = WELCH_SEED,
                  scale: float = 1.0) -> np.ndarray:
    """
    Return the Welch PSD / target PSD ratio averaged over octave bands.

    One profile of the component alone is synthesised at 8 points per shortest
    wavelength, 16 segments long; segments (Hann window, half overlap) span at
    least 4 longest wavelengths.  Octave bands run from 2/lambda_max up to
    1/lambda_min of the component's default band.

    Parameters
    ----------
    family, component : str
        Spectrum family and component.
    seed : int
        Synthesis seed.
    scale : float
        Amplitude scale passed to the synthesis (1 for the validation).

    Returns
    -------
    numpy.ndarray
        Mean Welch PSD over mean target G, one value per octave band.

    """
    comp = SPECTRA[family].components[component]
    lam_min, lam_max = comp.wavelength_min, comp.wavelength_max
    dx = lam_min / 8.0
    nperseg = 2 ** math.ceil(math.log2(4.0 * lam_max / dx))
    profile = synthesize(family, length=16 * nperseg * dx, dx=dx, seed=seed, scale=scale,
                         components=(component,))
    freq, psd = signal.welch(profile.geometry(component), fs=1.0 / dx, window='hann',
                             nperseg=nperseg, detrend=False)   # one-sided, m^2/(cycle/m)
    n_octaves = math.floor(math.log2(lam_max / (2.0 * lam_min)) + 1e-9)
    lower = (2.0 / lam_max) * 2.0 ** np.arange(n_octaves)
    band = (freq >= lower[:, np.newaxis]) & (freq < 2.0 * lower[:, np.newaxis])
    target = np.zeros_like(freq)
    target[1:] = comp.psd(freq[1:])
    return (band @ psd) / (band @ target)


def octave_row(family: str, ratios: Mapping[str, Sequence[float] | np.ndarray]) -> Row:
    """
    Build the V9 row of one family: the band ratio farthest from 1.

    Parameters
    ----------
    family : str
        Spectrum family.
    ratios : Mapping[str, sequence of float]
        Octave-band ratios by component.

    Returns
    -------
    Row
        Worst ratio vs 1.0, tolerance 20 %; NaN (failing) if there is no band.

    """
    pairs = [(float(r), c) for c, values in ratios.items() for r in values]
    ratio, component = max(pairs, key=lambda p: abs(p[0] - 1.0), default=(math.nan, '-'))
    return relative_row('V9', _label(family, component, len(ratios)), ratio, 1.0, 0.20, '-')


def v9_rows() -> list[Row]:
    """Build the V9 rows: one per spectrum family, every component and band checked."""
    return [octave_row(family, {c: octave_ratios(family, c) for c in spec.components})
            for family, spec in SPECTRA.items()]


def v10_rows(wavelength_min: float = 2.0, wavelength_max: float = 200.0,
             reference_mm: float = 1.22) -> list[Row]:
    """
    Build the V10 rows: Chinese HSR vertical RMS over a band vs 1.22 mm (2 %).

    Parameters
    ----------
    wavelength_min, wavelength_max : float
        Band (m), 2-200 m for V10.
    reference_mm : float
        Reference RMS (mm), PHYSICS.md 1.1.

    Returns
    -------
    list of Row
        RMS of ``ENSEMBLE_SEEDS`` synthesised profiles, RMS of the PSD integral.

    """
    check = check_variance('chinese_hsr', 'vertical', wavelength_min=wavelength_min,
                           wavelength_max=wavelength_max, seeds=ENSEMBLE_SEEDS)
    band = f'{wavelength_min:g}-{wavelength_max:g} m'
    return [relative_row('V10', f'RMS {band}, {check.seeds} profiles', check.sample_rms * 1e3,
                         reference_mm, 0.02, 'mm'),
            relative_row('V10', f'RMS {band}, PSD integral', check.target_rms * 1e3,
                         reference_mm, 0.02, 'mm')]


COMPONENT_CASES: tuple[Case, ...] = (
    Case('V4', 'car of Table 1, eigen-analysis', v4_rows),
    Case('V5', 'Hertz contact at static wheel load', v5_rows),
    Case('V8', 'synthesis from each spectrum (Chinese HSR four components, Sato, '
               'German low/high, FRA 1-6)', v8_rows),
    Case('V9', 'Welch PSD of a synthesised profile', v9_rows),
    Case('V10', 'Chinese HSR vertical, 2-200 m', v10_rows),
)
