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
Substructure interiors condensed out of the Newmark step (ttb_sim.sim.integrators.condensed).

The oracle is Newmark's step on the whole system: the condensed step is the same
equations in modal coordinates, so the two agree to round-off (the tolerances below
are a few hundred times machine precision times the modal matrix's condition, and
each says so).
"""

import numpy as np
import pytest
import scipy.sparse as sp

from ttb_sim.config import load_scenario
from ttb_sim.sim import Simulation
from ttb_sim.sim.integrators import interior_kernels
from ttb_sim.sim.integrators.condensed import condense_interiors, interior_modes
from ttb_sim.sim.integrators.newmark import Newmark


def chain(n_boundary: int, n_interior: int, seed: int) -> tuple[sp.csr_matrix, ...]:
    """Return (M, C, K, interior): a spring chain with a dense interior block at its end.

    The interior has a full mass, a full stiffness and a damping far from proportional
    (as the reduced substructures' boundary dashpots make it); it meets the chain only
    through its last DOF.
    """
    rng = np.random.default_rng(seed)
    n = n_boundary + n_interior
    k = np.zeros((n, n))
    for i in range(n_boundary - 1):
        k[i:i + 2, i:i + 2] += 1e6 * np.array([[1.0, -1.0], [-1.0, 1.0]])
    k[0, 0] += 1e6
    block = slice(n_boundary - 1, n)
    g = rng.standard_normal((n_interior + 1, n_interior + 1))
    k[block, block] += 1e5 * (g @ g.T + np.eye(n_interior + 1))
    m = np.diag(rng.uniform(1.0, 10.0, n))
    h = rng.standard_normal((n_interior + 1, n_interior + 1))
    m[block, block] += 0.5 * h @ h.T
    c = 1e-3 * k
    c[n_boundary:, n_boundary:] += np.diag(rng.uniform(10.0, 300.0, n_interior))
    interior = np.arange(n_boundary, n)
    return sp.csr_matrix(m), sp.csr_matrix(c), sp.csr_matrix(k), interior


def step_both(mass, damping, stiffness, blocks, dt, loads):
    """Step the whole system and its condensed form under the same loads; return both."""
    n = mass.shape[0]
    whole = Newmark(mass, damping, stiffness, dt, method='qdldl', lean=True)
    ci = condense_interiors(mass, damping, stiffness, blocks, dt)
    assert ci is not None
    kept = Newmark(*ci.kept_matrices(mass, damping, stiffness), dt, method='qdldl', lean=True)
    start, boundary, rho, sigma, p_hat, e_hat, d_m, d_c = ci.packed()
    u, v, a = np.zeros(n), np.zeros(n), np.zeros(n)
    eta, e = ci.amplitudes(u, v, a)
    pre = np.zeros_like(eta)
    uk, vk, ak = np.zeros(ci.keep.size), np.zeros(ci.keep.size), np.zeros(ci.keep.size)
    for f in loads:
        h_v, h_a = whole.history(u, v, a)
        u = np.array(whole.solve(whole.effective_load(f, h_v, h_a)))
        v, a = (np.array(x) for x in whole.finish(u, h_v, h_a))
        h_v, h_a = kept.history(uk, vk, ak)
        rhs = kept.effective_load(f[ci.keep], h_v, h_a)
        interior_kernels.interior_load(start, boundary, rho, sigma, p_hat, d_m, d_c,
                                       eta, e, pre, h_a, h_v, rhs)
        uk = np.array(kept.solve(rhs))
        vk, ak = (np.array(x) for x in kept.finish(uk, h_v, h_a))
        interior_kernels.interior_finish(start, boundary, sigma, e_hat, eta, e, pre, uk, vk, ak)
    full = (np.zeros(n), np.zeros(n), np.zeros(n))
    ci.expand((uk, vk, ak), eta, full)
    return (u, v, a), full, ci


def test_the_condensed_step_is_newmarks_step_on_the_whole_system():
    m, c, k, interior = chain(4, 6, seed=1)
    dt = 1e-3
    t = dt * np.arange(1, 301)
    loads = np.zeros((t.size, m.shape[0]))
    loads[:, 0] = 1e3 * np.sin(2 * np.pi * 7.0 * t) + 5e2 * np.sin(2 * np.pi * 61.0 * t)
    whole, condensed, ci = step_both(m, c, k, [np.arange(3, 10)], dt, loads)
    assert ci.modes[0].interior.tolist() == interior.tolist()
    assert ci.modes[0].boundary.tolist() == [3]
    for name, x, y in zip('uva', condensed, whole):
        scale = np.max(np.abs(y))
        assert scale > 0.0
        # round-off: 1e-15 x (steps 300) x (modal condition, below 1e3 here) with margin
        assert np.max(np.abs(x - y)) <= 1e-9 * scale, name


def test_the_schur_complement_is_the_modal_forms_feedthrough():
    # D S_ib (the boundary force per unit boundary displacement through the modes) must
    # equal -S_bi S_ii^-1 S_ib (the exact elimination): two derivations of one matrix.
    m, c, k, interior = chain(3, 5, seed=2)
    dt = 2e-3
    boundary = np.array([2])
    modes = interior_modes(m, c, k, interior, boundary, dt)
    a0, a1 = 4.0 / dt**2, 2.0 / dt
    s = (k + a1 * c + a0 * m).toarray()
    s_ib = s[np.ix_(interior, boundary)]
    from_modes = np.einsum('kj,kl->jl', modes.p_hat,   # p_hat carries the pairs' weight 2
                           modes.sigma[:, None] * np.einsum('kqj,q->kj', modes.e_hat,
                                                            np.array([a0, a1, 1.0])))
    mass_part = (m.toarray()[np.ix_(boundary, interior)]
                 @ np.linalg.solve(m.toarray()[np.ix_(interior, interior)], s_ib))
    assert np.allclose(from_modes.real - mass_part, modes.schur, rtol=1e-8, atol=0.0)


def test_a_defective_interior_is_not_condensed():
    # A critically damped single coordinate has a double eigenvalue and one eigenvector:
    # no modal form, so the interiors must stay in the global system.
    mass = sp.csr_matrix(np.diag([1.0, 1.0]))
    stiffness = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 1.0]]) * 1e4)
    damping = sp.csr_matrix(np.array([[0.0, 0.0], [0.0, 2.0 * np.sqrt(1e4)]]))
    assert condense_interiors(mass, damping, stiffness, [np.array([1])], 1e-3) is None


def test_live_coupled_realtime_condenses_its_piers_and_matches_qdldl():
    values = [('solver.duration', 0.2), ('irregularity.seed', 4)]
    runs = {}
    for variant in ('realtime', 'qdldl'):
        sim = Simulation(load_scenario('live_coupled',
                                       values=[('solver.variant', variant), *values]))
        runs[variant] = (sim, list(sim.frames()))
    sim = runs['realtime'][0]
    assert sim.compiled_loop
    condensed = sim.coupling._condensed
    assert condensed is not None and len(condensed.interiors.modes) == 2
    for field in ('midspan', 'bearings', 'body_acceleration', 'wheel_rail', 'pier_tops',
                  'pile_displacement', 'pile_acceleration', 'pile_rotation_rate',
                  'soil_points'):
        x = np.array([getattr(f, field) for f in runs['realtime'][1]])
        y = np.array([getattr(f, field) for f in runs['qdldl'][1]])
        scale = np.max(np.abs(y))
        assert scale > 0.0, field
        # the realtime-vs-reference bound of test_realtime.py (the two LDL^T orders
        # already differ by 4e-10 in the interiors' accelerations)
        assert np.max(np.abs(x - y)) <= 1e-9 * scale, field


@pytest.mark.parametrize('seed', [3, 4, 5])
def test_condensed_reruns_are_identical(seed):
    values = [('solver.variant', 'realtime'), ('solver.duration', 0.05),
              ('irregularity.seed', seed)]
    frames = [list(Simulation(load_scenario('live_coupled', values=values)).frames())
              for _ in range(2)]
    for a, b in zip(*frames):
        np.testing.assert_array_equal(a.pile_acceleration, b.pile_acceleration)
        np.testing.assert_array_equal(a.soil_points, b.soil_points)
