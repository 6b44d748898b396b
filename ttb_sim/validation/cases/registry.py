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
The validation suite behind ``ttb-sim validate`` (VALIDATION.md).

Every case runs the user pipeline (built-in scenario -> Simulation -> frames)
and compares with an independent reference from :mod:`ttb_sim.validation.references.structural`.
"""

from __future__ import annotations

import math
import time
from typing import Callable, Sequence

import numpy as np
import scipy.sparse as sp

from ttb_sim.config import load_scenario, Scenario
from ttb_sim.sim import Newmark, Simulation
from ttb_sim.validation.cases.analysis import ANALYSIS_CASES
from ttb_sim.validation.cases.components import COMPONENT_CASES
from ttb_sim.validation.cases.conditions import CONDITION_CASES
from ttb_sim.validation.cases.coupled import COUPLED_CASES
from ttb_sim.validation.cases.damage import DAMAGE_CASES
from ttb_sim.validation.cases.half_space import HALF_SPACE_CASES
from ttb_sim.validation.cases.modal import MODAL_CASES
from ttb_sim.validation.cases.pile_group import PILE_GROUP_CASES
from ttb_sim.validation.cases.pile_soil import PILE_SOIL_CASES
from ttb_sim.validation.cases.sensors import SENSOR_CASES
from ttb_sim.validation.cases.slab_plate import SLAB_PLATE_CASES
from ttb_sim.validation.cases.system import SYSTEM_CASES
from ttb_sim.validation.cases.track import TRACK_CASES
from ttb_sim.validation.cases.twin import TWIN_CASES
from ttb_sim.validation.references.structural import (Beam, fryba_peak, QuarterCar,
                                                      sprung_mass_modal)
from ttb_sim.validation.rows import Case, relative_row, Row

V1_ALPHAS = (0.1, 0.3, 0.5, 0.62, 1.0)


def midspan_history(scenario: Scenario) -> tuple[np.ndarray, Simulation]:
    """Run a scenario through the pipeline; return span 1 mid-span z per frame."""
    sim = Simulation(scenario)
    z = np.array([f.midspan[0, 2] for f in sim.frames()])
    return z, sim


def beam_of(scenario: Scenario) -> Beam:
    """Return the reference beam of a scenario's span."""
    b = scenario.bridge
    return Beam(b.span_length, b.bending_stiffness, b.mass_per_length, b.damping_ratio)


def moving_force_daf(alpha: float, overrides: Sequence[str] = ()) -> tuple[float, float]:
    """
    Return (pipeline DAF, Fryba DAF) of ``moving_force_beam`` at speed parameter alpha.

    alpha = v / (2 f1 L); the DAF is the peak mid-span deflection over the run
    divided by F L^3 / (48 EI).
    """
    base = load_scenario('moving_force_beam', overrides)
    beam = beam_of(base)
    speed = alpha * 2 * beam.f1 * beam.length
    scenario = load_scenario('moving_force_beam', overrides,
                             [('train.speed_kmh', speed * 3.6)])
    z, _ = midspan_history(scenario)
    force = scenario.train.axle_load
    static = beam.static_midspan(force)
    reference = fryba_peak(beam, force, speed, scenario.solver.free_vibration_periods)
    return float(-z.min()) / static, reference / static


def _v1() -> list[Row]:
    rows = []
    for alpha in V1_ALPHAS:
        computed, reference = moving_force_daf(alpha)
        rows.append(relative_row('V1', f'DAF at alpha = {alpha:g}', computed, reference, 0.01))
    return rows


def sprung_mass_comparison(overrides: Sequence[str] = ()) -> dict[str, float]:
    """
    Run ``sprung_mass_beam`` and its independent modal reference.

    Returns
    -------
    dict
        Peak mid-span deflection and peak sprung-mass acceleration, computed
        and reference (m, m/s^2).

    """
    scenario = load_scenario('sprung_mass_beam', overrides)
    sim = Simulation(scenario)
    frames = list(sim.frames())
    z = np.array([f.midspan[0, 2] for f in frames])
    acc = np.array([f.body_acceleration[0, 2] for f in frames])
    tr = scenario.train
    car = QuarterCar(tr.sprung_mass, tr.suspension_stiffness, tr.suspension_damping,
                     tr.unsprung_mass)
    ref = sprung_mass_modal(beam_of(scenario), car, tr.speed, sim.duration, n_modes=20,
                            rayleigh=sim.structure.rayleigh)
    return {'deflection': float(-z.min()), 'deflection_ref': float(-ref['midspan'].min()),
            'acceleration': float(np.abs(acc).max()),
            'acceleration_ref': float(np.abs(ref['acceleration']).max())}


def _v3() -> list[Row]:
    r = sprung_mass_comparison()
    return [relative_row('V3', 'max mid-span deflection', r['deflection'] * 1e3,
                         r['deflection_ref'] * 1e3, 0.02, 'mm'),
            relative_row('V3', 'peak sprung-mass acceleration', r['acceleration'],
                         r['acceleration_ref'], 0.05, 'm/s^2')]


def newmark_sdof(omega: float, dt: float, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Integrate u'' + omega^2 u = 0, u(0) = 1, v(0) = 0 with :class:`Newmark`."""
    one = sp.csr_matrix([[1.0]])
    nm = Newmark(one, sp.csr_matrix((1, 1)), omega**2 * one, dt)
    u, v = np.array([1.0]), np.array([0.0])
    a = nm.initial_acceleration(u, v, np.zeros(1))
    us, vs = [u[0]], [v[0]]
    for _ in range(n_steps):
        u, v, a = nm.step(u, v, a, np.zeros(1))
        us.append(u[0])
        vs.append(v[0])
    return np.array(us), np.array(vs)


def newmark_order(omega: float = 2 * math.pi, periods: float = 2.25) -> float:
    """
    Return the observed order of the displacement error at t = periods T.

    The default instant is a zero crossing of cos, where the error is the phase
    error itself (at a crest it would be its square).
    """
    errors = []
    for n in (200, 400):
        t_end = periods * 2 * math.pi / omega
        u, _ = newmark_sdof(omega, t_end / n, n)
        errors.append(abs(u[-1] - math.cos(omega * t_end)))
    return math.log2(errors[0] / errors[1])


def newmark_energy_drift(omega: float = 2 * math.pi, steps: int = 10_000) -> float:
    """Return max |E(t) / E(0) - 1| over ``steps`` steps of 1/20 period."""
    u, v = newmark_sdof(omega, (2 * math.pi / omega) / 20, steps)
    energy = 0.5 * v**2 + 0.5 * omega**2 * u**2
    return float(np.max(np.abs(energy / energy[0] - 1.0)))


def _v7() -> list[Row]:
    order = newmark_order()
    drift = newmark_energy_drift()
    return [Row('V7', 'Newmark order, SDOF', order, 2.0, abs(order - 2.0), 0.1,
                abs(order - 2.0) <= 0.1, '-', 'absolute'),
            Row('V7', 'energy drift over 1e4 steps', drift, 0.0, drift, 1e-6, drift < 1e-6,
                '-', 'absolute')]


CASES: dict[str, Case] = {c.case_id: c for c in sorted((
    Case('V1', 'moving constant force on a simply supported beam (Fryba)', _v1),
    Case('V3', 'sprung mass crossing a simply supported beam (Yang & Yau)', _v3),
    Case('V7', 'Newmark average acceleration: order and energy', _v7),
    *COMPONENT_CASES, *SLAB_PLATE_CASES, *SYSTEM_CASES, *TRACK_CASES, *PILE_SOIL_CASES,
    *PILE_GROUP_CASES, *ANALYSIS_CASES, *COUPLED_CASES, *DAMAGE_CASES, *SENSOR_CASES,
    *CONDITION_CASES, *MODAL_CASES, *TWIN_CASES, *HALF_SPACE_CASES),
    key=lambda c: (c.case_id[0] != 'V', int(c.case_id[1:])))}
"""Cases by id: V* are VALIDATION.md's, X* are extra checks of modelling choices."""


def run_cases(case_ids: Sequence[str],
              progress: Callable[[int, int, str, list[Row] | None, float], None] | None = None
              ) -> list[Row]:
    """
    Run the named cases and return all their rows.

    Parameters
    ----------
    case_ids : sequence of str
        Case ids, run in this order.
    progress : callable, optional
        Called before each case as ``progress(i, n, case_id, None, 0.0)`` and
        after it as ``progress(i, n, case_id, rows, seconds)`` (i from 1).

    """
    rows: list[Row] = []
    n = len(case_ids)
    for i, case_id in enumerate(case_ids, start=1):
        if progress is not None:
            progress(i, n, case_id, None, 0.0)
        start = time.perf_counter()
        case_rows = CASES[case_id].run()
        rows.extend(case_rows)
        if progress is not None:
            progress(i, n, case_id, case_rows, time.perf_counter() - start)
    return rows


def format_table(rows: Sequence[Row]) -> str:
    """Format rows as a fixed-width table."""
    head = (f'{"case":5s} {"quantity":34s} {"computed":>12s} {"reference":>12s} '
            f'{"error":>10s} {"tolerance":>10s} {"unit":6s} result')
    lines = [head, '-' * len(head)]
    for r in rows:
        err = f'{r.error * 100:.3f}%' if r.error_kind == 'relative' else f'{r.error:.2e}'
        tol = f'{r.tolerance * 100:g}%' if r.error_kind == 'relative' else f'{r.tolerance:g}'
        lines.append(f'{r.case:5s} {r.quantity:34s} {r.computed:12.6g} {r.reference:12.6g} '
                     f'{err:>10s} {tol:>10s} {r.unit:6s} {"pass" if r.passed else "FAIL"}')
    return '\n'.join(lines)
