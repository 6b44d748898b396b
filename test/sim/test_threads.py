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
solver.threads: the automatic choice, one thread or two giving the same bits, the plan line.

On a busy machine two threads of a parallel kernel wait for each other (issue
#28: a step 3.5-11x slower than with one); ``solver.threads = 0`` takes two only
when the load leaves 1.5 cores free. One thread runs each parallel kernel's
serial compilation, two run numba's parallel one: the frames must not differ
by a bit.
"""

from __future__ import annotations

import os

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.fe import compiled
from ttb_sim.sim import Simulation
from ttb_sim.sim.cost import compile_time, estimate_cost
from ttb_sim.sim.variants import resolve_threads

SMALL_CARS = [('train.vehicle', 'car'), ('track.model', 'slab'), ('train.n_cars', 1),
              ('bridge.n_spans', 1), ('bearings.model', 'elastic'),
              ('train.start_position', 0.0), ('irregularity.spectrum', 'paper'),
              ('irregularity.seed', 5), ('solver.variant', 'qdldl'),
              ('solver.duration', 0.02)]


def machine(monkeypatch, cores: int, load: float) -> None:
    """Pretend the process may run on ``cores`` cores at 1-minute load ``load``."""
    monkeypatch.setattr(os, 'sched_getaffinity', lambda pid: set(range(cores)), raising=False)
    monkeypatch.setattr(os, 'getloadavg', lambda: (load, load, load))


@pytest.mark.parametrize(('cores', 'load', 'expected'), [
    (2, 0.0, 2), (2, 0.5, 2), (2, 0.6, 1), (2, 8.0, 1), (1, 0.0, 1), (8, 6.0, 2), (8, 6.6, 1)])
def test_auto_takes_two_threads_only_with_a_core_and_a_half_free(monkeypatch, cores, load,
                                                                 expected):
    machine(monkeypatch, cores, load)
    chosen = resolve_threads(0)
    assert chosen.count == expected
    assert f'load {load:.1f} on {cores} cores' in chosen.reason


def test_a_set_count_is_taken_as_it_is(monkeypatch):
    machine(monkeypatch, 2, 12.0)
    assert resolve_threads(2).count == 2
    assert resolve_threads(2).reason == 'solver.threads'
    assert resolve_threads(1).describe() == '1 thread (solver.threads)'


def test_auto_without_a_load_average_takes_one(monkeypatch):
    def unavailable():
        raise OSError('no load average here')
    monkeypatch.setattr(os, 'getloadavg', unavailable)
    assert resolve_threads(0).count == 1


def frames(threads: int) -> tuple[np.ndarray, np.ndarray]:
    """Wheel-rail forces and mid-span of a short one-car passage at ``threads``."""
    sim = Simulation(load_scenario('moving_force_beam', values=SMALL_CARS + [
        ('solver.threads', threads)]))
    assert sim.threads.count == threads
    out = [(f.wheel_rail.copy(), f.midspan.copy()) for f in sim.frames()]
    assert sim.coupling.compliance.influence       # the parallel rail predictor ran
    return np.array([w for w, _ in out]), np.array([m for _, m in out])


def test_one_thread_and_two_give_the_same_bits():
    pytest.importorskip('numba')
    wheel_1, mid_1 = frames(1)
    wheel_2, mid_2 = frames(2)
    assert np.ptp(wheel_1[..., 2]) > 1e3                # the forces move: not idle
    assert np.array_equal(wheel_1, wheel_2)
    assert np.array_equal(mid_1, mid_2)


def _twice(x: float) -> float:
    return 2.0 * x


def test_pending_names_a_kernel_until_it_is_compiled(monkeypatch):
    pytest.importorskip('numba')
    monkeypatch.setattr(compiled, '_in_disk_cache', lambda kernel: False)
    kernel = compiled.jit(_twice)
    assert kernel is not None
    assert '_twice' in compiled.pending()
    assert kernel(2.0) == 4.0
    assert '_twice' not in compiled.pending()


def test_the_plan_says_threads_and_what_it_compiles():
    plan = estimate_cost(steps=10, dt=1e-3, free_dofs=100, cars=0, frames=11,
                         messages_per_frame=3, variant='qdldl',
                         threads='1 thread (auto: load 3.0 on 2 cores)',
                         compiling=('contact_newton', 'history'))
    line = plan.describe()
    assert '1 thread (auto: load 3.0 on 2 cores)' in line
    assert 'compiling 2 kernels on first use' in line
    assert plan.compile_time == pytest.approx(compile_time(['contact_newton', 'history']))
    assert plan.wall_time > plan.compile_time
    quiet = estimate_cost(steps=10, dt=1e-3, free_dofs=100, cars=0, frames=11,
                          messages_per_frame=3, variant='qdldl')
    assert 'compiling' not in quiet.describe()
    assert plan.wall_time - quiet.wall_time == pytest.approx(plan.compile_time)


def test_realtime_takes_one_thread_unless_asked(monkeypatch):
    """Issue #27: single-threaded by default, even on an idle machine; a set count still holds."""
    from ttb_sim.sim.variants import solver_variant
    machine(monkeypatch, 2, 0.0)
    realtime = solver_variant('realtime')
    assert resolve_threads(0, realtime).count == 1
    assert 'realtime' in resolve_threads(0, realtime).reason
    assert resolve_threads(2, realtime).count == 2
    assert resolve_threads(0, solver_variant('qdldl')).count == 2
