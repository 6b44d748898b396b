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
Pile-soil validation cases V11-V14, V16 (VALIDATION.md) and the mesh convergence check.

V15, the pile group, is in :mod:`.pile_group`.

Each case builds its substructure from the records users give
(:mod:`ttb_sim.model.foundation.records` -> :func:`~ttb_sim.model.foundation.substructure.build`)
and takes the computed number from the model's operators or from the same
stepping and static code users run (:mod:`ttb_sim.sim.substructure.stepping`,
:mod:`ttb_sim.sim.substructure.statics`); the references come from
:mod:`ttb_sim.validation.references.pile_soil`, which shares no code with them.

V11  Homogeneous column (H = 20 m, E = 5 MPa, nu = 0.25, rho = 1937 kg/m^3,
     Vs = 32.13 m/s) on a rigid base: a laterally periodic column of 40
     bricks of 0.5 m (one brick in plan, lumped mass), base fixed; first
     natural frequency of the assembled K, M against Vs / (4 H).
V12  [P]'s three-layer 22 m deposit, same column with 88 bricks of 0.25 m;
     second shear mode against 1.25 Hz (travel-time average Vs), and the
     exact layered-column value (1.2724 Hz) as an extra row.
V13  Viscous-spring base of a 40 m periodic column (middle-layer soil, no
     material damping, 0.25 m bricks): a one-cycle 5 Hz shear traction on the
     surface sends an S pulse down; the energy left in the column (kinetic +
     strain + boundary spring) after the pulse has passed the base, over the
     energy of the incident pulse.
V14  Single pile d = 1.0 m (0.886 m square), L = 12 m, E = 1e11 Pa in the
     Table 5 soil, block 40 x 40 x 22 m with the viscous-spring boundary
     (its springs stand for the half-space beyond), h = 0.443 m growing by
     1.3 to 3 m, Desai interface; static head stiffness under 1 kN against
     Randolph-Wroth (layered form, 4.96e7 N/m).
V16  Desai law of the V14 model at a shaft Gauss point of the middle layer,
     sheared monotonically at its geostatic normal stress: max of tau / tau_f
     (must not exceed 1 + 1e-6) and the largest relative error of stress and
     tangent against the capped Clough-Duncan hyperbola (1e-6).
"""

from __future__ import annotations

from dataclasses import replace
import logging
import math
from typing import Optional, Sequence

import numpy as np
import scipy.linalg as sla

from ttb_sim.config import load_scenario, Scenario
from ttb_sim.model.foundation.records import (BlockSize, EQUAL_AREA_SIDE, MeshSize, Observation,
                                              PAPER_LAYERS, PileLoad, SoilLayer, SoilParameters,
                                              Substructure)
from ttb_sim.model.foundation.substructure import build, PileSoilModel
from ttb_sim.sim import Frame, SubstructureRun
from ttb_sim.sim.substructure import observe, states, static_solve
from ttb_sim.validation.references.pile_soil import (hyperbola_stress, hyperbola_tangent,
                                                     layered_pile_stiffness,
                                                     quarter_wavelength_frequencies,
                                                     shear_column_frequencies)
from ttb_sim.validation.rows import Case, relative_row, Row

LOG = logging.getLogger(__name__)

#: The homogeneous soil of V11 and V13 ([P] Table 5 middle layer).
MIDDLE = PAPER_LAYERS[1]
NO_POINTS = Observation(line_points=0, val_points=False)


def column(layers: tuple[SoilLayer, ...], h: float, boundary: str = 'fixed') -> Substructure:
    """Return a laterally periodic soil column of bricks of size h (one brick in plan)."""
    soil = SoilParameters(layers, BlockSize(h, h), MeshSize(h=h, growth=1.0, h_max=h),
                          boundary=boundary, periodic=True)
    return Substructure(soil=soil, piles=None, observation=NO_POINTS)


def shear_frequencies(model: PileSoilModel, n: int) -> np.ndarray:
    """Return the first n natural frequencies (Hz) of x-polarised modes of a free-DOF model."""
    free = np.flatnonzero(model.free)
    k = model.linear_stiffness()[free][:, free].toarray()
    w2, vectors = sla.eigh(k, np.diag(model.mass[free]))
    x_part = (vectors[free % 3 == 0, :]**2).sum(axis=0) / (vectors**2).sum(axis=0)
    picked = np.sqrt(np.abs(w2[x_part > 0.99])) / (2 * math.pi)
    return picked[:n]


def v11() -> list[Row]:
    """First resonance of a homogeneous column on a rigid base."""
    layer = SoilLayer(20.0, MIDDLE.E, MIDDLE.nu, MIDDLE.rho, damping_ratio=0.0)
    f1 = shear_frequencies(build(column((layer,), 0.5)), 1)[0]
    return [relative_row('V11', 'column f1 (40 bricks)', f1, layer.vs / (4 * 20.0), 0.02,
                         'Hz')]


def v12() -> list[Row]:
    """Second shear mode of [P]'s three-layer deposit."""
    f = shear_frequencies(build(column(PAPER_LAYERS, 0.25)), 2)
    t = [la.thickness for la in PAPER_LAYERS]
    quarter = quarter_wavelength_frequencies(t, [la.vs for la in PAPER_LAYERS], 2)
    exact = shear_column_frequencies(t, [la.G for la in PAPER_LAYERS],
                                     [la.rho for la in PAPER_LAYERS], 2)
    return [relative_row('V12', 'deposit f2 vs (2n-1)Vs/4H', f[1], float(quarter[1]), 0.05,
                         'Hz'),
            relative_row('V12', 'deposit f2 vs layered exact', f[1], float(exact[1]), 0.01,
                         'Hz')]


def boundary_reflection(frequency: float = 5.0, depth: float = 40.0, h: float = 0.25,
                        boundary: str = 'viscoelastic') -> float:
    """Return the V13 reflected over incident energy ratio."""
    layer = SoilLayer(depth, MIDDLE.E, MIDDLE.nu, MIDDLE.rho, damping_ratio=0.0)
    model = build(column((layer,), h, boundary))
    load = PileLoad('pulse', 1e3, frequency, direction='x', target='surface')
    force = model.load_vector(load)
    k = model.linear_stiffness()
    travel = depth / layer.vs
    dt = 1.0 / (40 * frequency)
    times, energy = [], []
    for s in states(model, force, load.history, 2 * travel, dt, scheme='implicit'):
        times.append(s.time)
        energy.append(0.5 * s.v @ (model.mass * s.v) + 0.5 * s.u @ (k @ s.u))
    t = np.array(times)
    e = np.array(energy)
    pulse = 1.0 / frequency
    incident = e[(t > pulse) & (t < travel)].max()
    after = e[t > pulse + travel + 0.25 * travel].max()
    return float(after / incident)


def v13() -> list[Row]:
    """Energy reflected by the viscous-spring base."""
    ratio = boundary_reflection()
    return [Row('V13', 'reflected / incident energy', ratio, 0.0, ratio, 0.05, ratio < 0.05,
                '-', 'absolute')]


def single_pile_scenario(h: float = 0.443, growth: float = 1.3, h_max: float = 3.0,
                         block: float = 40.0, interface: str = 'desai',
                         max_aspect: float = 12.0, force: float = 1e3) -> Scenario:
    """Return the built-in ``single_pile`` scenario (V14) with its mesh and block set."""
    return load_scenario('single_pile', values=[
        ('soil.mesh.h', h), ('soil.mesh.growth', growth), ('soil.mesh.h_max', h_max),
        ('soil.mesh.max_aspect', max_aspect), ('soil.block.lx', block),
        ('soil.block.ly', block), ('interface.model', interface), ('load.type', 'static'),
        ('load.amplitude', force), ('load.direction', 'z')])


def single_pile(h: float = 0.443, growth: float = 1.3, h_max: float = 3.0,
                block: float = 40.0, interface: str = 'desai',
                max_aspect: float = 12.0) -> Substructure:
    """Return the V14 single pile: d = 1.0 m, L = 12 m in the Table 5 soil."""
    scenario = single_pile_scenario(h, growth, h_max, block, interface, max_aspect)
    return replace(scenario.substructure(), observation=NO_POINTS)


def scenario_frames(scenario: Scenario) -> tuple[SubstructureRun, list[Frame]]:
    """Run a substructure scenario as ``ttb-sim run`` does; return the run and its frames."""
    runner = SubstructureRun(scenario)
    return runner, list(runner.frames())


def head_stiffness(spec: Substructure, force: float = 1e3) -> float:
    """Return the static vertical head stiffness F / w (N/m) of pile 1 under a head load."""
    model = build(spec)
    state = static_solve(model, model.load_vector(PileLoad('static', force, pile=1)),
                         increments=1)
    return force / float(observe(model, state).pile_displacement[0, 2])


def scenario_head_stiffness(scenario: Scenario) -> float:
    """Return F / w (N/m) of the loaded pile from the static frame of a scenario run."""
    _, frames = scenario_frames(scenario)
    load = scenario.load
    axis = 'xyz'.index(load.direction)
    return load.amplitude / float(frames[0].pile_displacement[load.pile - 1, axis])


def randolph_wroth_reference(spec: Substructure) -> float:
    """Return Randolph-Wroth for the spec's pile and layers (N/m)."""
    assert spec.piles is not None
    layers = spec.soil.layers
    diameter = spec.piles.width / EQUAL_AREA_SIDE
    return layered_pile_stiffness([la.thickness for la in layers], [la.G for la in layers],
                                  layers[-1].nu, spec.piles.length, diameter,
                                  spec.piles.E)


def v14() -> list[Row]:
    """Compare the static head stiffness of a single pile with Randolph-Wroth."""
    scenario = single_pile_scenario()
    return [relative_row('V14', 'single-pile head stiffness', scenario_head_stiffness(scenario),
                         randolph_wroth_reference(scenario.substructure()), 0.15, 'N/m')]


def load_period_samples(t: np.ndarray, frequency: float) -> int:
    """Return the samples of the record ``t`` in one load period (at least one)."""
    return max(1, int(round(1.0 / (frequency * (t[1] - t[0])))))


def split_response(t: np.ndarray, x: np.ndarray, frequency: float
                   ) -> tuple[float, np.ndarray]:
    """
    Split a record into its steady harmonic amplitude and the low-frequency rest.

    Least squares on [1, t, cos, sin of the first three harmonics of
    ``frequency``] over the whole record, the slow part being taken out first
    by a moving average over one load period.
    """
    n = load_period_samples(t, frequency)
    slow = np.convolve(x, np.ones(n) / n, mode='same')
    fast = x - slow
    late = t > t[-1] / 2
    basis = np.column_stack([np.cos(2 * math.pi * frequency * t[late]),
                             np.sin(2 * math.pi * frequency * t[late])])
    coef = np.linalg.lstsq(basis, fast[late], rcond=None)[0]
    return float(np.hypot(*coef)), slow


def desai_monotonic(n: int = 2001, gauss_point: Optional[int] = None
                    ) -> tuple[float, float, float]:
    """
    Shear a Desai Gauss point of the V14 model monotonically (V16).

    Returns
    -------
    (max tau / tau_f, max relative stress error, max relative tangent error
    before slip) against the capped Clough-Duncan hyperbola.

    """
    model = build(single_pile(h=0.886 / 2, growth=1.6, h_max=3.0, block=16.0))
    law = model.law
    assert law is not None and model.interface is not None
    k_n0, k_s0 = law.k_n0.ravel(), law.k_s0.ravel()
    z = np.einsum('ga,eai->egi', _face_n(), model.mesh.nodes[model.interface.faces_b])[..., 2]
    middle = np.flatnonzero((z.ravel() < -3.0) & (z.ravel() > -5.0)
                            & (np.abs(model.interface.frames[..., 0, 2].ravel()) < 0.5))
    g = int(middle[0]) if gauss_point is None else gauss_point
    tau_f = float(law.cohesion.ravel()[g] + law.sigma_n0.ravel()[g] * law.tan_delta.ravel()[g])
    rf = law.failure_ratio
    strain_f = tau_f / k_s0[g] / (1 - rf)
    gamma = np.linspace(0.0, 3 * strain_f, n)
    strain = np.zeros((n, 3))
    strain[:, 1] = gamma
    point = type(law)(np.full(n, k_n0[g]), np.full(n, k_s0[g]),
                      np.full(n, law.cohesion.ravel()[g]), np.full(n, law.tan_delta.ravel()[g]),
                      np.full(n, law.sigma_n0.ravel()[g]), rf, law.residual, law.max_closure)
    slip = np.zeros((n, 2))
    stress, tangent, _ = point.evaluate(strain, slip)
    tau = stress[:, 1]
    ref = hyperbola_stress(gamma, k_s0[g], tau_f, rf)
    ref_t = hyperbola_tangent(gamma, k_s0[g], tau_f, rf)
    before = gamma < strain_f * (1 - 1e-9)
    stress_error = float(np.max(np.abs(tau - ref)) / tau_f)
    tangent_error = float(np.max(np.abs(tangent[before, 1] - ref_t[before]) / ref_t[before]))
    return float(np.max(tau / tau_f)), stress_error, tangent_error


def _face_n() -> np.ndarray:
    from ttb_sim.fe.quad import FACE_N
    return FACE_N


def v16() -> list[Row]:
    """Desai interface under monotonic shear."""
    peak, stress_error, tangent_error = desai_monotonic()
    return [Row('V16', 'max tau / (c + sigma_n tan delta)', peak, 1.0, max(0.0, peak - 1.0),
                1e-6, peak <= 1.0 + 1e-6, '-', 'absolute'),
            Row('V16', 'stress vs capped hyperbola', stress_error, 0.0, stress_error, 1e-6,
                stress_error <= 1e-6, '-', 'absolute'),
            Row('V16', 'tangent vs hyperbola (rel.)', tangent_error, 0.0, tangent_error, 1e-6,
                tangent_error <= 1e-6, '-', 'absolute')]


def observed_rate(sizes: Sequence[float], values: Sequence[float]) -> float:
    """
    Return the observed order p of three solutions on meshes of sizes h1 > h2 > h3.

    With c(h) = c0 + C h^p, (c1 - c2) / (c2 - c3) = r23^p (r12^p - 1) / (r23^p - 1)
    for the refinement ratios r12 = h1 / h2, r23 = h2 / h3; p is found by
    bisection (NaN when the three values do not converge monotonically).
    """
    r12, r23 = sizes[0] / sizes[1], sizes[1] / sizes[2]
    target = (values[0] - values[1]) / (values[1] - values[2])

    def gap(p: float) -> float:
        return r23**p * (r12**p - 1) / (r23**p - 1) - target

    lo, hi = 0.05, 8.0
    if gap(lo) * gap(hi) > 0:
        return float('nan')
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if gap(lo) * gap(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def convergence(sizes: tuple[float, ...] = (0.886 / 2, 0.886 / 3, 0.886 / 4),
                force: float = 1e3) -> tuple[list[float], float]:
    """Return single-pile static head compliances on three meshes and the observed rate."""
    values = []
    for h in sizes:
        spec = single_pile(h=h, growth=1.3, h_max=2.5, block=30.0, max_aspect=16.0)
        values.append(1.0 / head_stiffness(spec, force))
    return values, observed_rate(sizes, values)


def harmonic_convergence(sizes: tuple[float, ...] = (0.886 / 2, 0.886 / 3, 0.886 / 4),
                         frequency: float = 5.0, duration: float = 2.0,
                         block: float = 30.0) -> tuple[list[float], float]:
    """
    Return the steady pile-head amplitude of ``single_pile`` under a harmonic load on three meshes.

    The built-in scenario with ``load.type: harmonic`` at ``frequency`` (1 kN),
    run through :class:`SubstructureRun`; the amplitude is the least-squares
    harmonic of the second half of the record (:func:`split_response`).
    """
    values = []
    for h in sizes:
        scenario = load_scenario('single_pile', values=[
            ('soil.mesh.h', h), ('soil.mesh.growth', 1.3), ('soil.mesh.h_max', 2.5),
            ('soil.mesh.max_aspect', 16.0), ('soil.block.lx', block), ('soil.block.ly', block),
            ('load.type', 'harmonic'), ('load.frequency', frequency),
            ('solver.duration', duration), ('output.rate_hz', 40.0 * frequency)])
        _, frames = scenario_frames(scenario)
        t = np.array([f.time for f in frames])
        z = np.array([f.pile_displacement[0, 2] for f in frames])
        amplitude, _ = split_response(t, z, frequency)
        LOG.info('harmonic convergence: h = %.4g m, amplitude %.6g m', h, amplitude)
        values.append(amplitude)
    return values, observed_rate(sizes, values)


PILE_SOIL_CASES = (
    Case('V11', 'homogeneous soil column on a rigid base: first resonance', v11),
    Case('V12', "[P]'s three-layer deposit: second shear-column mode", v12),
    Case('V13', 'viscous-spring boundary: energy reflected by the base', v13),
    Case('V14', 'single pile: static head stiffness vs Randolph-Wroth (about 1 min)', v14),
    Case('V16', 'Desai interface under monotonic shear', v16),
)
"""The pile-soil cases, registered with the validation suite."""
