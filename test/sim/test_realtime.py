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
solver.variant 'realtime': the steps between frames in one compiled loop, against qdldl.

For moving forces and quarter cars the loop (``advance`` of the couplings) takes
the lean Newmark step of ``qdldl`` with the same arithmetic: the moving load or
the quarter cars' kernels, the stacked mat-vec and QDLDL's own triangular loops
on the wheel's factors. The step-by-step ``qdldl`` path is therefore its oracle,
bit for bit, through the pipeline users run (Simulation.frames); the
``reference`` (SuperLU) agrees to round-off. Multibody cars are refused with
a message that names what is allowed.
"""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.errors import DivergenceError
from ttb_sim.sim import kernel_registry, Simulation

FIELDS = ('midspan', 'bearings', 'body_acceleration', 'wheel_rail', 'observers', 'speed',
          'head_position', 'pile_displacement', 'pile_acceleration', 'pile_rotation_rate',
          'soil_points', 'pier_tops')

CASES = {
    # Moving forces over ten spans (elastic bearings, pier springs), frames every 4 steps.
    'ten_span_train': [('solver.duration', 0.3)],
    # A single span with rigid supports (the reactions read the applied load).
    'moving_force_beam': [],
    # Quarter cars on an irregular track, a frame every step.
    'live_train': [('solver.duration', 0.3), ('irregularity.seed', 3)],
    # One quarter car on a smooth single span, frames at a rate the steps do not divide.
    'sprung_mass_beam': [('output.rate_hz', 300.0)],
    # The coupled default: quarter cars, two piled piers solved with the girders (monolithic).
    'live_coupled': [('solver.duration', 0.15), ('irregularity.seed', 4)],
}


def run(name: str, variant: str, values: list[tuple[str, object]]) -> tuple[Simulation, list]:
    """Return the simulation and its frames."""
    sim = Simulation(load_scenario(name, values=[('solver.variant', variant), *values]))
    return sim, list(sim.frames())


def same_frames(a: list, b: list) -> None:
    """Assert that two runs wrote the same frames, field by field, bit for bit."""
    assert len(a) == len(b)
    for fa, fb in zip(a, b):
        assert fa.step == fb.step
        for field in FIELDS:
            np.testing.assert_array_equal(getattr(fa, field), getattr(fb, field), err_msg=field)


BIT_FOR_BIT = sorted(set(CASES) - {'live_coupled'})
"""The built-ins whose realtime loop is qdldl's step in the same order of operations; the
piled piers of live_coupled are condensed (test_condensed.py: equal to round-off)."""


@pytest.mark.parametrize('name', BIT_FOR_BIT)
def test_realtime_writes_the_frames_of_qdldl_bit_for_bit(name):
    sim, fast = run(name, 'realtime', CASES[name])
    assert sim.coupling.fused() and sim.compiled_loop, 'the compiled loop must be under test'
    assert sim.describe()['compiled_loop'] is True
    _, slow = run(name, 'qdldl', CASES[name])
    same_frames(fast, slow)


@pytest.mark.parametrize('name', ['ten_span_train', 'live_train', 'live_coupled'])
def test_realtime_agrees_with_the_reference(name):
    # SuperLU (general LU) against QDLDL's LDL^T of the same matrix: round-off only.
    _, fast = run(name, 'realtime', CASES[name])
    _, ref = run(name, 'reference', CASES[name])
    fields = ('midspan', 'bearings') + (('body_acceleration',) if name != 'ten_span_train'
                                        else ()) + (
        ('pile_displacement', 'pile_acceleration', 'pier_tops') if name == 'live_coupled'
        else ())
    for field in fields:
        x = np.array([getattr(f, field) for f in fast])
        y = np.array([getattr(f, field) for f in ref])
        scale = np.max(np.abs(y))
        assert scale > 0.0
        assert np.max(np.abs(x - y)) <= 1e-9 * scale, field


def test_realtime_reruns_are_identical():
    _, first = run('live_train', 'realtime', CASES['live_train'])
    _, second = run('live_train', 'realtime', CASES['live_train'])
    same_frames(first, second)


def test_a_speed_change_between_frames_is_taken_as_the_step_by_step_path_takes_it():
    def changed(variant: str) -> list:
        sim = Simulation(load_scenario('ten_span_train', values=[
            ('solver.variant', variant), *CASES['ten_span_train']]))
        out = []
        for i, frame in enumerate(sim.frames()):
            out.append(frame)
            if i == 20:
                sim.set_speed(0.5 * sim.speed)   # as the node's speed parameter does
        return out
    same_frames(changed('realtime'), changed('qdldl'))


@pytest.mark.parametrize('name', ['ten_span_train', 'live_train'])
def test_divergence_stops_at_the_same_step_with_the_same_message(name):
    # A limit the static deflection already exceeds: the loop must stop inside a frame
    # interval, at the step the per-step check stops at, with nothing published after.
    values = [*CASES[name], ('solver.divergence_limit', 2e-4)]
    messages, counts = [], []
    for variant in ('realtime', 'qdldl'):
        sim = Simulation(load_scenario(name, values=[('solver.variant', variant), *values]))
        frames = []
        with pytest.raises(DivergenceError) as caught:
            for frame in sim.frames():
                frames.append(frame)
        messages.append(str(caught.value))
        counts.append(len(frames))
    assert messages[0] == messages[1]
    assert counts[0] == counts[1]
    assert 'solver.divergence_limit = 0.0002 m' in messages[0]


def test_without_numba_realtime_steps_one_by_one_with_the_same_results(monkeypatch):
    monkeypatch.setattr(kernel_registry, 'ENABLED', False)
    sim, plain = run('moving_force_beam', 'realtime', [])
    assert not sim.coupling.fused() and not sim.compiled_loop
    monkeypatch.setattr(kernel_registry, 'ENABLED', True)
    _, fast = run('moving_force_beam', 'realtime', [])
    for a, b in zip(plain, fast):
        # numpy twins against the compiled kernels: equal to round-off (test_kernels.py).
        np.testing.assert_allclose(a.midspan, b.midspan, rtol=1e-12, atol=1e-18)
