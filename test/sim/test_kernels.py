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

"""Compiled kernels of the lean step equal their numpy twins bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.sim import kernel_registry as kernels, Newmark, Simulation
from ttb_sim.sim.coupling.girder_load import MovingLoad
from ttb_sim.sim.integrators.newmark_kernels import KERNELS

pytest.importorskip('numba')


@pytest.fixture
def numpy_twins(monkeypatch):
    """Switch the compiled kernels off (the numpy twins run) inside a test."""
    def off():
        monkeypatch.setattr(kernels, 'ENABLED', False)
    return off


def test_switch_off_gives_no_kernel(monkeypatch):
    assert KERNELS.compiled('history') is not None
    monkeypatch.setattr(kernels, 'ENABLED', False)
    assert KERNELS.compiled('history') is None


def test_compiled_moving_load_is_the_numpy_load_bit_for_bit(numpy_twins):
    sim = Simulation(load_scenario('ten_span_train', [], [('solver.variant', 'qdldl')]))
    st = sim.structure
    fast = MovingLoad(st.girder, sim.vehicle.loads, st.n_free, st.n_full)
    numpy_twins()
    slow = MovingLoad(st.girder, sim.vehicle.loads, st.n_free, st.n_full)
    assert fast._kernel is not None and slow._kernel is None
    rng = np.random.default_rng(5)
    # Axles before, on and after the bridge, on element ends and span joints.
    heads = np.concatenate([[0.0, 32.0, 64.0, st.girder.length], rng.uniform(-50, 600, 40)])
    for head in heads:
        positions = head - sim.vehicle.axles.offsets
        assert np.array_equal(fast(positions).copy(), slow(positions))
        assert np.array_equal(fast.full(positions), slow.full(positions))


def test_compiled_newmark_history_load_and_finish_are_numpy_bit_for_bit(numpy_twins):
    sim = Simulation(load_scenario('ten_span_train', [], [('solver.variant', 'qdldl')]))
    st = sim.structure

    def run():
        nm = Newmark(st.mass, st.damping, st.stiffness, sim.dt, method='qdldl', lean=True)
        rng = np.random.default_rng(3)
        u, v, a = (np.zeros(st.n_free) for _ in range(3))
        for _ in range(20):
            u, v, a = nm.step(u, v, a, rng.normal(size=st.n_free))
        return nm, u, v, a

    fast, *compiled = run()
    numpy_twins()
    slow, *twin = run()
    assert fast._history_kernel is not None and slow._history_kernel is None
    assert fast._load_kernel is not None and slow._load_kernel is None
    for x, y in zip(compiled, twin):
        assert np.array_equal(x, y)
    # The mat-vec alone, on values of every scale: scipy's sums, bit for bit.
    rng = np.random.default_rng(8)
    history = rng.normal(size=2 * st.n_free) * 10.0 ** rng.integers(-12, 6, 2 * st.n_free)
    force = rng.normal(size=st.n_free)
    fast._history[:] = history
    rhs = fast.effective_load(force, fast._h_v, fast._h_a)
    assert np.array_equal(rhs, force - fast._stacked @ history)
