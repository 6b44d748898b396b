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

"""The compiled contact step against its numpy oracle, and its single track solve."""

from __future__ import annotations

import numpy as np
import pytest

from contact_oracle import use_numpy_step  # noqa: I100 - the oracle in test/sim
from ttb_sim.config import load_scenario
import ttb_sim.model.wheel_rail as ct
from ttb_sim.sim import Simulation
from ttb_sim.sim.coupling.train_track import contact_step, multibody
from ttb_sim.sim.coupling.train_track.equilibrium import rail_under_wheels

pytest.importorskip('numba')

SMALL = [('train.vehicle', 'car'), ('track.model', 'slab'), ('train.n_cars', 1),
         ('bridge.n_spans', 1), ('bearings.model', 'elastic'), ('train.start_position', 0.0),
         ('irregularity.spectrum', 'paper'), ('irregularity.seed', 7),
         ('solver.variant', 'qdldl')]


Run = tuple[Simulation, np.ndarray, np.ndarray, list[int]]


def passage(duration: float, extra: list | None = None, *, numpy: bool = False) -> Run:
    """
    One car onto a one-span bridge: wheel-rail forces, mid-span and solves per step.

    ``numpy`` takes the oracle's numpy step (``contact_oracle.py``) instead of the
    compiled one.
    """
    sim = Simulation(load_scenario('moving_force_beam', values=SMALL + [
        ('solver.duration', duration)] + (extra or [])))
    if numpy:
        use_numpy_step(sim.coupling)
    forces, midspan, solves = [], [], []
    for frame in sim.frames():
        forces.append(frame.wheel_rail.copy())
        midspan.append(frame.midspan.copy())
        solves.append(sim.coupling.solves)
    return sim, np.array(forces), np.array(midspan), solves[1:]


def relative(a: np.ndarray, b: np.ndarray) -> float:
    """Largest difference relative to the largest magnitude of b."""
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize('geometry', ['profiles', 'conicity'])
def test_compiled_two_solve_step_is_the_numpy_step_to_round_off(monkeypatch, geometry):
    """Kernels with the numpy step's two solves: the same passage within 1e-9 (round-off)."""
    extra = [('contact.geometry', geometry)]
    monkeypatch.setattr(multibody, 'INFLUENCE_HOPS', None)
    fast, f_fast, m_fast, _ = passage(0.06, extra)
    slow, f_slow, m_slow, _ = passage(0.06, extra, numpy=True)
    assert 'step' in vars(slow.coupling) and 'step' not in vars(fast.coupling)
    assert not fast.coupling.compliance.influence
    # The compression moves 10 um and more over the run: the comparison is not idle.
    assert np.ptp(f_slow[..., 2]) > 1e3
    assert relative(f_fast, f_slow) < 1e-9
    assert relative(m_fast[..., 2], m_slow[..., 2]) < 1e-9


def test_local_columns_give_the_rail_motion_of_the_predictor_solve():
    """
    The single-solve predictor: rows K^-1 rhs from local columns, against the solve.

    The right-hand side is the Newmark history of the running passage (rail
    and girder moving, the train on the bridge), as in the step.
    """
    sim = Simulation(load_scenario('moving_force_beam', values=SMALL + [
        ('solver.duration', 0.06)]))
    tt = sim.coupling
    assert tt.compliance.influence
    k = tt.contact_step.kernels
    n = tt.n_cars
    checked = 0
    for i, _ in enumerate(sim.frames()):
        if i % 20 != 5:
            continue
        head = sim.scenario.train.start_position + sim.speed * i * sim.output_every * sim.dt
        x = head + tt.contact_x
        rows, slope = np.zeros((n, 8, 3, 12)), np.zeros((n, 8, 3, 12))
        dofs, element = np.zeros((n, 8, 12), dtype=np.intp), np.zeros((n, 8), dtype=np.intp)
        dr, ds = np.zeros((n, 8, 3, 3)), np.zeros((n, 8, 3, 3))
        interior = np.zeros((n, 8, 3, 3))
        left, right = tt.rails
        sec_l, sec_r = tt.rail_sections
        assert k.rail_rows(x, tt.side, left.start, left.length, tt.rail_dofs[0],
                           tt.compliance.blocks[0], sec_l, right.start, right.length,
                           tt.rail_dofs[1], tt.compliance.blocks[1], sec_r,
                           float(tt.head_arm[2]), rows, slope, dofs, dr, ds, interior,
                           element) == -1
        # The numpy rows of the same wheels.
        rows_np, slope_np, dofs_np, _, interior_np = rail_under_wheels(tt, x)
        np.testing.assert_allclose(rows, rows_np, rtol=0, atol=1e-12)
        np.testing.assert_allclose(slope, slope_np, rtol=0, atol=1e-12)
        assert np.array_equal(dofs, dofs_np)
        assert np.max(interior[..., 1, 1]) > 0.0          # wheels inside their elements
        np.testing.assert_allclose(interior, interior_np, rtol=1e-13, atol=0)
        nm = tt.nm
        h_v, h_a = nm.history(tt.u, tt.v, tt.a)
        rhs = nm.effective_load(np.zeros(tt.n_free), h_v, h_a)
        exact = nm.solve(rhs)
        r_exact, s_exact = np.zeros((n, 8, 3)), np.zeros((n, 8, 3))
        k.rail_values(rows, exact, dofs, r_exact)
        k.rail_values(slope, exact, dofs, s_exact)
        r_local, s_local = np.zeros((n, 8, 3)), np.zeros((n, 8, 3))
        infl_l, infl_r = tt.compliance.influence
        k.rail_predictor(element, tt.side, *infl_l, *infl_r, rows, slope, rhs, r_local,
                         s_local)
        assert np.max(np.abs(r_exact)) > 1e-4       # the rail is loaded
        assert relative(r_local, r_exact) < 1e-8
        assert relative(s_local, s_exact) < 1e-7
        checked += 1
    assert checked >= 3


def test_single_solve_step_solves_once_and_meets_the_contact_tolerance():
    """
    One track solve per step; the passage equals the numpy step's to the contact tolerance.

    Both steps stop when the rail under the wheels agrees with the local model to
    contact.tolerance, so their forces differ by at most about what that
    tolerance is worth through the contact stiffness, k_H tol (measured 6.1e-6
    of the largest force, the bound 1.9e-5); a hundred times tighter they agree
    better (1.4e-6: what remains is the rail slope of the predictor, which the
    single-solve step takes from the local K^-1 columns and does not iterate).
    """
    sim, f_single, m_single, solves = passage(0.06)
    assert np.mean(solves) < 1.05
    tight = [('contact.tolerance', 1e-11)]
    _, f_tight, m_tight, _ = passage(0.06, tight)
    _, f_numpy, m_numpy, solves_numpy = passage(0.06, tight, numpy=True)
    assert min(solves_numpy) == 2
    tt = sim.coupling
    worth = ct.linearised_stiffness(tt.p0, tt.g_hertz) * tt.tol / np.max(np.abs(f_numpy))
    assert relative(f_single, f_numpy) < worth
    assert relative(f_tight, f_numpy) < 0.5 * relative(f_single, f_numpy)
    assert relative(m_tight[..., 2], m_numpy[..., 2]) < 1e-6


def test_step_setup_and_rail_check_are_the_numpy_formulas():
    """
    The step's set-up and mismatch kernels against the numpy step's formulas.

    Random values of every array; the mismatch's largest entry counts every
    component for the single-solve step, only the vertical otherwise, and a NaN
    is never below the tolerance.
    """
    rng = np.random.default_rng(3)
    n = 2
    force = rng.normal(size=(n, 8, 4)) * 1e5
    creep0 = rng.uniform(1e6, 1e7, size=4)
    r_star, rs_star, r_hist, interior_r, interior_v = (
        rng.normal(size=(n, 8, 3)) for _ in range(5))
    dr, ds = rng.normal(size=(n, 8, 3, 3)), rng.normal(size=(n, 8, 3, 3))
    q_star = rng.normal(size=(n, 42))
    wheelset_y = 6 * np.repeat(np.arange(3, 7), 2) + 1
    a1, speed, p0 = 2e4, 80.0, 7e4
    creep, r0p, rv0 = np.empty((4, n, 8)), np.empty((n, 8, 4)), np.empty((n, 8, 4))
    rvel, y_star = np.empty((n, 8, 3, 3)), np.empty((n, 8))
    setup = contact_step.KERNELS.compiled('contact_setup')
    setup(force, creep0, p0, r_star, rs_star, r_hist, interior_r, interior_v, dr, ds, a1, speed,
          q_star, wheelset_y, creep, r0p, rv0, rvel, y_star)
    expected = ct.scaled_creep_coefficients(tuple(creep0), p0, force[..., 2])
    np.testing.assert_allclose(creep, np.array(expected), rtol=1e-15, atol=0)
    np.testing.assert_array_equal(r0p[..., :3], r_star)
    np.testing.assert_allclose(rv0[..., :3], a1 * r_star + r_hist + speed * rs_star
                               - a1 * interior_r - interior_v, rtol=1e-15, atol=1e-14 * a1)
    assert not np.any(r0p[..., 3]) and not np.any(rv0[..., 3])
    np.testing.assert_allclose(rvel, a1 * dr + speed * ds, rtol=1e-15, atol=1e-15 * a1)
    np.testing.assert_array_equal(y_star, q_star[:, wheelset_y])

    size = 50
    rows, slope = rng.normal(size=(n, 8, 3, 12)), rng.normal(size=(n, 8, 3, 12))
    dofs = rng.integers(0, size + 1, size=(n, 8, 12))     # size: the ground slot
    u = rng.normal(size=size)
    offset = rng.normal(size=(n, 8, 4)) * 1e-3
    slope_offset = rng.normal(size=(n, 8, 3)) * 1e-3
    g = rng.normal(size=(n, 32))
    ue = np.append(u, 0.0)
    exact = np.einsum('cwij,cwj->cwi', rows, ue[dofs])
    exact_slope = np.einsum('cwij,cwj->cwi', slope, ue[dofs])
    gx = g.reshape(n, 8, 4)[..., :3]
    miss = exact - ((r0p + offset)[..., :3] - np.einsum('cwij,cwj->cwi', dr, gx))
    miss_slope = exact_slope - (rs_star + slope_offset - np.einsum('cwij,cwj->cwi', ds, gx))
    check = contact_step.KERNELS.compiled('rail_check')
    for single in (True, False):
        r_exact, mismatch, slope_mismatch = (np.empty((n, 8, 3)) for _ in range(3))
        worst = check(rows, slope, u, dofs, r0p, offset, dr, ds, g, rs_star, slope_offset,
                      single, r_exact, mismatch, slope_mismatch)
        np.testing.assert_allclose(r_exact, exact, rtol=0, atol=1e-13)
        np.testing.assert_allclose(mismatch, miss, rtol=0, atol=1e-13)
        np.testing.assert_allclose(slope_mismatch, miss_slope if single else 0.0, rtol=0,
                                   atol=1e-13)
        counted = np.abs(miss if single else miss[..., 2])
        assert worst == pytest.approx(counted.max(), rel=1e-13)
    offset[1, 5, 2] = np.nan
    assert check(rows, slope, u, dofs, r0p, offset, dr, ds, g, rs_star, slope_offset, False,
                 r_exact, mismatch, slope_mismatch) == np.inf
