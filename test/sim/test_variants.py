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

"""Solver variants: the contract key, the lean Newmark step and bit-for-bit determinism."""

import numpy as np
import pytest
import scipy.sparse as sp
from ttb_sim.config import key_spec, load_scenario, Scenario
from ttb_sim.fe.beam import point_rows
from ttb_sim.sim import blas_threads, Newmark, Simulation, solver_variant, VARIANTS
from ttb_sim.sim.coupling.base import girder_wheel_load
from ttb_sim.sim.coupling.girder_load import MovingLoad, point_rows_and_slopes


def test_variants_are_the_choices_of_the_contract_key():
    _typ, default, spec = key_spec('solver.variant')
    assert set(spec.choices) == set(VARIANTS)
    assert default in VARIANTS and default != 'reference'
    assert Scenario().solver.variant == default
    assert VARIANTS['reference'].factorization == 'superlu'
    assert not VARIANTS['reference'].lean and VARIANTS['reference'].blas_threads is None
    with pytest.raises(ValueError, match="unknown solver variant 'x'; allowed: reference"):
        solver_variant('x')


def _system(n: int = 40):
    k = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n), format='csr') * 1e6
    m = sp.diags([1.0, 4.0, 1.0], [-1, 0, 1], shape=(n, n), format='csr') * 10.0
    return m, 1e-3 * k + 0.5 * m, k


def test_lean_newmark_matches_plain_to_round_off():
    m, c, k = _system()
    plain = Newmark(m, c, k, 1e-3)
    lean = Newmark(m, c, k, 1e-3, method='cholmod', lean=True)
    rng = np.random.default_rng(7)
    state_p = state_l = tuple(rng.standard_normal((3, 40)))
    for step in range(50):
        force = np.sin(0.1 * step) * np.ones(40)
        state_p = plain.step(*state_p, force)
        state_l = lean.step(*state_l, force)
    for xp, xl in zip(state_p, state_l):
        assert np.max(np.abs(xl - xp)) <= 1e-10 * np.max(np.abs(xp))


@pytest.mark.parametrize('variant', sorted(VARIANTS))
def test_every_variant_is_deterministic_and_agrees_with_reference(variant):
    """Two runs give the same bits; each agrees with reference to 1e-9 (relative)."""
    def midspans(name):
        sc = load_scenario('moving_force_beam', [], [('solver.variant', name),
                                                     ('solver.duration', 0.02)])
        return np.array([f.midspan for f in Simulation(sc).frames()])

    first, second = midspans(variant), midspans(variant)
    assert np.array_equal(first, second)
    reference = midspans('reference')
    assert np.max(np.abs(first - reference)) <= 1e-9 * np.max(np.abs(reference))


def test_blas_threads_limit_applies_inside_the_block():
    threadpoolctl = pytest.importorskip('threadpoolctl')
    with blas_threads(1):
        infos = [i for i in threadpoolctl.threadpool_info() if i['user_api'] == 'blas']
        assert all(i['num_threads'] == 1 for i in infos)
    with blas_threads(None):
        pass


def test_lean_moving_load_equals_the_general_assembly():
    sc = load_scenario('ten_span_train', [], [('solver.variant', 'reference')])
    sim = Simulation(sc)
    st = sim.structure
    lean = MovingLoad(st.girder, sim.vehicle.loads, st.n_free, st.n_full)
    for head in (0.0, 17.3, 160.0, 321.9, 500.0):
        positions = head - sim.vehicle.axles.offsets
        full = girder_wheel_load(st.girder, st.n_full, positions, sim.vehicle.loads)
        scale = np.max(np.abs(full)) or 1.0
        assert np.max(np.abs(lean.full(positions) - full)) <= 1e-14 * scale
        assert np.max(np.abs(lean(positions) - full[st.free])) <= 1e-14 * scale


def test_rail_rows_and_slopes_are_point_rows_bit_for_bit():
    rng = np.random.default_rng(11)
    xi, length = rng.random(64), 0.3 + 0.4 * rng.random(64)
    arm = np.array([0.0, 0.0, 0.176])
    rows, slopes = point_rows_and_slopes(xi, length, arm)
    assert np.array_equal(rows, point_rows(xi, length, arm))
    assert np.array_equal(slopes, point_rows(xi, length, arm, 1))
