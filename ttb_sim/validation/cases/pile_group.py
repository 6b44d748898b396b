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
V15 (VALIDATION.md): [P]'s harmonic check of the pile group, restated so that it can fail.

``pile_harmonic``: 5 x 3 piles (3 m spacing, d = 1.0 m, L = 12 m) in [P]
Table 5's soil, 10 kN at 20 Hz vertical on pile 5 from rest, ground observed
midway between piles 4 and 5.

Amplitude rows: the steady 20 Hz amplitudes of the pile-5 head and of the
ground point from the time-domain run users make (``ttb-sim run``, the
piles bonded to the soil) against an independent 3-D FE of the same block
and boundary in the frequency domain
(:mod:`ttb_sim.validation.references.independent_fe`, scikit-fem), within
5 %. The Desai run (as shipped) is reported beside them, with its
difference from the bonded one.

Transient rows: the low-frequency transient the start from rest leaves,
for each boundary option: a damped cosine fitted to the load-period moving
average (where that average lies inside the record: its half-window at
either end averages over the record's edge, a hump ten times the ringing),
its natural frequency (the fitted damped frequency over sqrt(1 - zeta^2))
beside the closed-form frequencies of the 22 m stratum on a rigid base
(layer transfer matrices: shear modes with G, vertical ones with the
constrained modulus). Where the base is rigid (``fixed``, ``rigid_base``;
runs of 4 s) the loaded pile's natural frequency must lie within 10 % of the
closed form of the domain used: with ``fixed`` sides (normal motion held,
vertical motion free) the stratum's first vertical mode; with
``rigid_base``'s viscous-spring sides the same column restrained along its
depth by the sides' tangential springs and dashpots ([P] Eq. 3) spread over
the plan (:func:`restrained_stratum`), whose damping ratio is reported beside
the fitted one. With an absorbing base (``viscoelastic``, ``lysmer``) the
stratum has no resonance and the fit is reported. [P]'s 1.2 Hz (Fig. 10; [P]
states neither its block nor its boundary) is reported, not a target: the
model's counterpart is V12, the deposit's second shear mode (1.27 Hz).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import math
from typing import Mapping, Optional, Sequence
import warnings

import numpy as np
from scipy.optimize import curve_fit, OptimizeWarning

from ttb_sim.config import load_scenario, Scenario
from ttb_sim.model.foundation.records import SoilLayer
from ttb_sim.sim import SubstructureRun
from ttb_sim.validation.cases.pile_soil import load_period_samples, split_response
from ttb_sim.validation.references.independent_fe import IndependentBlock
from ttb_sim.validation.references.pile_soil import (restrained_column_root,
                                                     shear_column_frequencies)
from ttb_sim.validation.rows import Case, relative_row, report_row, Row

LOG = logging.getLogger(__name__)

AMPLITUDE_TOLERANCE = 0.05
"""V15: steady amplitude against the independent FE (relative)."""
TRANSIENT_TOLERANCE = 0.10
"""V15: the transient's natural frequency against the closed form of the rigid-base domain."""
BOUNDARIES = ('viscoelastic', 'lysmer', 'fixed', 'rigid_base')
"""The boundary options of the transient table."""
RIGID_BASE = ('fixed', 'rigid_base')
"""Boundary options under which the stratum has its own resonances."""
RINGING_SECONDS = 4.0
"""Duration (s) of the rigid-base runs."""
PAPER_TRANSIENT_HZ = 1.2
"""[P] Fig. 10's transient (reported only)."""
RINGING_DAMPING = 0.5
"""Damping ratio from which a fitted cosine is no ringing: one period later 2.6 % is left."""


@dataclass(frozen=True)
class Transient:
    """A damped mode: the damped frequency (Hz) and damping ratio (NaN: no oscillation fitted)."""

    frequency: float
    damping: float = math.nan

    @classmethod
    def of_root(cls, root: complex) -> Transient:
        """Return the mode of a complex root s (1/s): damped |Im s| / 2 pi, zeta -Re s / |s|."""
        return cls(abs(root.imag) / (2 * math.pi), -root.real / abs(root))

    @property
    def natural(self) -> float:
        """Return the natural frequency (Hz): the damped one over sqrt(1 - zeta^2)."""
        if not 0.0 <= self.damping < 1.0:
            return self.frequency
        return self.frequency / math.sqrt(1.0 - self.damping**2)


def fit_transient(t: np.ndarray, slow: np.ndarray) -> Transient:
    """
    Return the damped mode fitted to a slow record.

    The model: a damped cosine, a decaying exponential and an offset. A load
    started from rest gives the pile head an impulse: the soil around it
    settles within tenths of a second without ringing (the exponential), while
    the domain's first mode rings on (the cosine). The fit starts from the
    spectral peak between 0.3 and 5 Hz; when it lands outside that band, or
    at a damping ratio of :data:`RINGING_DAMPING` or more (no damped oscillation
    in the record), the spectral peak is returned, its damping unknown (NaN).
    """
    def model(tt: np.ndarray, a: float, zeta: float, f: float, phase: float, b: float,
              tau: float, c: float) -> np.ndarray:
        w = 2 * math.pi * f
        return (a * np.exp(-zeta * w * tt) * np.cos(w * tt + phase)
                + b * np.exp(-tt / np.maximum(tau, 1e-6)) + c)

    tt = t - t[0]
    spectrum = np.abs(np.fft.rfft((slow - slow.mean()) * np.hanning(len(slow)), 16 * len(tt)))
    freqs = np.fft.rfftfreq(16 * len(tt), tt[1] - tt[0])
    band = (freqs > 0.3) & (freqs < 5.0)
    guess = float(freqs[band][np.argmax(spectrum[band])])
    p0 = [float(np.ptp(slow)) / 4, 0.1, guess, 0.0, float(slow[0]), 0.1, float(slow.mean())]
    try:
        with np.errstate(over='ignore', invalid='ignore'), warnings.catch_warnings():
            warnings.simplefilter('ignore', OptimizeWarning)   # an unused term's covariance
            p, _ = curve_fit(model, tt, slow, p0=p0, maxfev=40000)
    except RuntimeError:  # pragma: no cover - fall back on the spectral peak
        return Transient(guess)
    fitted = float(abs(p[2]))
    # a record without a damped oscillation (a single decaying hump) fits a near-zero
    # frequency or a damping that leaves nothing of a second swing: report the spectral
    # peak of the searched band instead
    if 0.3 < fitted < 5.0 and 0.0 <= p[1] < RINGING_DAMPING:
        return Transient(fitted, float(p[1]))
    return Transient(guess)


def averaged_part(t: np.ndarray, slow: np.ndarray, frequency: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the samples of a load-period moving average that lie inside the record.

    :func:`~ttb_sim.validation.cases.pile_soil.split_response` averages over one
    load period centred on each sample; within half a period of either end that
    window runs over the record's edge, and a harmonic started from rest leaves
    a hump there (about 2 / pi of half its amplitude) that a fit would chase.
    """
    edge = load_period_samples(t, frequency) // 2 + 1
    return t[edge:len(t) - edge], slow[edge:len(slow) - edge]


@dataclass(frozen=True)
class HarmonicRecord:
    """
    What V15 reads from a time-domain harmonic run.

    Attributes
    ----------
    pile, ground : float
        Steady amplitudes (m) at the load frequency of the loaded pile head and
        of the last user soil point, along the load.
    pile_transient, ground_transient : Transient
        Their low-frequency transients.
    dofs : int
        Model DOFs.
    nodes, cells : arrays
        The mesh (for the independent FE).

    """

    pile: float
    ground: float
    pile_transient: Transient
    ground_transient: Transient
    dofs: int
    nodes: np.ndarray
    cells: np.ndarray


def harmonic_run(scenario: Scenario) -> HarmonicRecord:
    """Run a harmonic pile-group scenario in the time domain, as ``ttb-sim run`` does."""
    runner = SubstructureRun(scenario)
    load = scenario.load
    axis = 'xyz'.index(load.direction)
    t, pile, ground = [], [], []
    for frame in runner.frames():
        t.append(frame.time)
        pile.append(frame.pile_displacement[load.pile - 1, axis])
        ground.append(frame.soil_points[-1, 3 + axis])  # the last user point: x y z ux uy uz
    time = np.array(t)
    amp_p, slow_p = split_response(time, np.array(pile), load.frequency)
    amp_g, slow_g = split_response(time, np.array(ground), load.frequency)
    mesh = runner.model.mesh
    return HarmonicRecord(amp_p, amp_g,
                          fit_transient(*averaged_part(time, slow_p, load.frequency)),
                          fit_transient(*averaged_part(time, slow_g, load.frequency)),
                          runner.model.n_dofs, mesh.nodes, mesh.cells)


def independent_amplitudes(scenario: Scenario, nodes: np.ndarray,
                           cells: np.ndarray) -> tuple[float, float]:
    """Return the steady pile-head and ground amplitudes (m) of the independent FE."""
    load = scenario.load
    axis = 'xyz'.index(load.direction)
    block = IndependentBlock(scenario.substructure(), nodes, cells)
    head = block.head_weights(load.pile, axis)
    point = np.array([scenario.output.soil_points[-1]], dtype=float)
    response = block.response(load.frequency, load.amplitude * head, head, point)
    LOG.info('V15 independent FE: %d unknowns', response.dofs)
    return abs(response.head), float(abs(response.points[0, axis]))


def amplitude_rows(overrides: Sequence[str] = (),
                   shipped: Optional[HarmonicRecord] = None) -> list[Row]:
    """
    Rows of the time-domain amplitudes against the independent FE, and the Desai run's.

    The time-domain run and the reference both bond the piles to the soil;
    ``shipped``, the same scenario's run with its own (Desai) interface, is
    reported with its difference from the bonded run.
    """
    bonded = load_scenario('pile_harmonic', [*overrides, 'interface.model=bonded'])
    run = harmonic_run(bonded)
    pile, ground = independent_amplitudes(bonded, run.nodes, run.cells)
    f, n = bonded.load.frequency, bonded.load.pile
    rows = [relative_row('V15', f'pile {n} head amplitude ({f:g} Hz)', run.pile, pile,
                         AMPLITUDE_TOLERANCE, 'm'),
            relative_row('V15', f'ground amplitude ({f:g} Hz)', run.ground, ground,
                         AMPLITUDE_TOLERANCE, 'm')]
    if shipped is not None:
        rows += [report_row('V15', f'pile {n} amplitude, Desai interface ({f:g} Hz)',
                            shipped.pile, 'm', run.pile),
                 report_row('V15', f'ground amplitude, Desai interface ({f:g} Hz)',
                            shipped.ground, 'm', run.ground)]
    return rows


def stratum_frequencies(layers: Sequence[SoilLayer], n: int = 2) -> dict[str, np.ndarray]:
    """
    Return the first ``n`` shear and vertical frequencies (Hz) of the layers on a rigid base.

    Laterally unbounded layers, free surface: shear waves with G, vertical
    (compression) waves with the constrained modulus E (1 - nu) / ((1 + nu) (1 - 2 nu)).
    """
    thickness = [lay.thickness for lay in layers]
    rho = [lay.rho for lay in layers]
    shear = [lay.G for lay in layers]
    constrained = [lay.constrained_modulus for lay in layers]
    return {'shear': shear_column_frequencies(thickness, shear, rho, n),
            'vertical': shear_column_frequencies(thickness, constrained, rho, n)}


def boundary_runs(overrides: Sequence[str] = (), boundaries: Sequence[str] = BOUNDARIES
                  ) -> dict[str, HarmonicRecord]:
    """
    Run the scenario once per boundary option (its own interface); records by option.

    Under a rigid base the stratum rings for several seconds: those runs last
    :data:`RINGING_SECONDS` (about three periods of its first vertical mode),
    the others the scenario's own duration.
    """
    runs = {}
    for b in boundaries:
        longer = [f'solver.duration={RINGING_SECONDS:g}'] if b in RIGID_BASE else []
        runs[b] = harmonic_run(load_scenario('pile_harmonic',
                                             [*overrides, f'soil.boundary={b}', *longer]))
    return runs


SIDE_POINTS = 400
"""Points along each side face in :func:`restrained_stratum`'s mean of 1 / R."""


def restrained_stratum(layers: Sequence[SoilLayer], lx: float, ly: float,
                       centre: Sequence[float] = (0.0, 0.0), alpha_t: float = 0.67) -> Transient:
    """
    Return the stratum's first vertical mode under viscous-spring sides spread over the plan.

    The layers on a rigid base, moving vertically as one column (constrained
    modulus), restrained along their depth by the four side faces' tangential
    springs alpha_t G / R and dashpots rho Vs ([P] Eq. 3; R from the group
    centre at the surface to the face point) spread over the block's plan
    lx x ly: per unit volume, k(z) = (1 / A) sum over the faces of the integral
    of alpha_t G / R along the face, c(z) = (perimeter / A) rho Vs.
    The model's own boundary (:func:`~ttb_sim.fe.boundary.viscoelastic_coefficients`)
    is not used: the coefficients are [P]'s.
    """
    tops = np.cumsum([0.0] + [lay.thickness for lay in layers])
    cx, cy = float(centre[0]), float(centre[1])
    along = (np.arange(SIDE_POINTS) + 0.5) / SIDE_POINTS - 0.5
    faces = [(np.full(SIDE_POINTS, x - cx), along * ly - cy, ly) for x in (-lx / 2, lx / 2)]
    faces += [(along * lx - cx, np.full(SIDE_POINTS, y - cy), lx) for y in (-ly / 2, ly / 2)]
    area = lx * ly

    def layer(z: float) -> SoilLayer:
        return layers[min(int(np.searchsorted(tops, z, side='right')) - 1, len(layers) - 1)]

    def springs(z: float) -> float:
        inverse = sum(width * float(np.mean(1.0 / np.sqrt(dx * dx + dy * dy + z * z)))
                      for dx, dy, width in faces)
        return alpha_t * layer(z).G * inverse / area

    def dashpots(z: float) -> float:
        lay = layer(z)
        return 2 * (lx + ly) / area * lay.rho * lay.vs

    thickness = [lay.thickness for lay in layers]
    moduli = [lay.constrained_modulus for lay in layers]
    rho = [lay.rho for lay in layers]
    guess = float(shear_column_frequencies(thickness, moduli, rho, 1)[0])
    return Transient.of_root(
        restrained_column_root(thickness, moduli, rho, springs, dashpots, guess))


def domain_modes(scenario: Scenario) -> dict[str, Transient]:
    """
    Return the closed-form first vertical mode of each rigid-base domain option.

    ``fixed`` holds the sides' normal motion only: the column's vertical mode is
    the stratum's (:func:`stratum_frequencies`, undamped). ``rigid_base`` puts
    [P]'s viscous-spring boundary on the sides (:func:`restrained_stratum`).
    """
    soil = scenario.soil
    first = float(stratum_frequencies(soil.layers, 1)['vertical'][0])
    centre = scenario.piles.centre if scenario.piles is not None else (0.0, 0.0)
    return {'fixed': Transient(first, 0.0),
            'rigid_base': restrained_stratum(soil.layers, soil.block.lx, soil.block.ly,
                                             centre, soil.alpha_t)}


def transient_rows(layers: Sequence[SoilLayer], runs: Mapping[str, HarmonicRecord],
                   domains: Mapping[str, Transient]) -> list[Row]:
    """
    Rows of the low-frequency transient per boundary option, beside the closed forms.

    Under a rigid base (``domains``, :func:`domain_modes`) the loaded pile
    head's natural frequency must lie within 10 % of the domain's, and the
    fitted damping ratio is reported beside the domain's; otherwise the
    transient is reported against the stratum's first vertical frequency. The
    ground point's is reported: midway between two piles it also carries the
    block's higher modes.
    """
    closed = stratum_frequencies(layers)
    rows = [report_row('V15', f'stratum {kind} mode {k + 1} (closed form)', float(f), 'Hz',
                       float(f))
            for kind in ('shear', 'vertical') for k, f in enumerate(closed[kind])]
    rows.append(report_row('V15', "[P]'s transient: V12's 2nd shear mode",
                           float(closed['shear'][1]), 'Hz', PAPER_TRANSIENT_HZ))
    first = float(closed['vertical'][0])
    for boundary, run in runs.items():
        label = f'pile transient, {boundary}'
        domain = domains.get(boundary)
        if domain is not None:
            rows.append(relative_row('V15', f'{label}: natural frequency',
                                     run.pile_transient.natural, domain.natural,
                                     TRANSIENT_TOLERANCE, 'Hz'))
            if math.isfinite(run.pile_transient.damping):
                rows.append(report_row('V15', f'{label}: damping ratio',
                                       run.pile_transient.damping, '-', domain.damping))
        else:
            rows.append(report_row('V15', label, run.pile_transient.natural, 'Hz', first))
        rows.append(report_row('V15', f'ground transient, {boundary}',
                               run.ground_transient.natural, 'Hz', first))
    return rows


def v15(overrides: Sequence[str] = ()) -> list[Row]:
    """[P]'s 10 kN, 20 Hz check on pile 5, restated (module docstring)."""
    runs = boundary_runs(overrides)
    scenario = load_scenario('pile_harmonic', overrides)
    return [*amplitude_rows(overrides, runs.get('viscoelastic')),
            *transient_rows(scenario.soil.layers, runs, domain_modes(scenario))]


PILE_GROUP_CASES = (
    Case('V15', "[P]'s 10 kN 20 Hz check on pile 5: amplitudes against an independent FE "
         '(scikit-fem), transient per boundary option (about 1 h of CPU, 9 GB; the '
         "independent solve needs MKL PARDISO: pip install 'ttb_sim[pardiso]')", v15),
)
"""The pile-group case, registered with the validation suite."""
