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
V1: moving constant force on a simply supported Euler-Bernoulli beam.

Reference: Fryba's modal series (PHYSICS.md 9.1), peak mid-span deflection over
the passage plus one fundamental period. Tolerance 1 % on the DAF, through the
user pipeline (built-in scenario -> Simulation -> frames), default time step.
"""

import numpy as np
import pytest
from ttb_sim.config import load_scenario
from ttb_sim.sim.simulation import Simulation
from ttb_sim.validation.cases.registry import moving_force_daf
from ttb_sim.validation.references.structural import Beam, fryba_peak


def test_reference_reproduces_published_daf():
    beam = Beam(32.0, 4.646e11, 35200.0)
    table = {0.1: 1.10, 0.3: 1.41, 0.5: 1.71, 1.0: 1.55, 1.2: 1.40, 1.5: 1.17, 2.0: 0.95}
    for alpha, daf in table.items():
        speed = alpha * 2 * beam.f1 * beam.length
        computed = fryba_peak(beam, 1.0, speed) / beam.static_midspan(1.0)
        assert computed == pytest.approx(daf, abs=0.006), alpha


@pytest.mark.parametrize('alpha', [0.1, 0.3, 0.5, 0.62, 1.0])
def test_v1_builtin(alpha):
    computed, reference = moving_force_daf(alpha)
    assert computed == pytest.approx(reference, rel=0.01)


# Arbitrary spans, stiffness, mass and speeds (seeded, so the test is repeatable).
_rng = np.random.default_rng(20261122)
_CASES = [(float(_rng.uniform(8, 60)), float(10 ** _rng.uniform(9, 12)),
           float(10 ** _rng.uniform(3, 4.7)), float(a))
          for a in (0.05, 0.2, 0.7, 1.5)]


@pytest.mark.parametrize('span, ei, mass, alpha', _CASES)
def test_v1_arbitrary_parameters(span, ei, mass, alpha):
    overrides = [f'bridge.span_length={span}', f'bridge.bending_stiffness={ei}',
                 f'bridge.mass_per_length={mass}', 'train.axle_load=2e5']
    computed, reference = moving_force_daf(alpha, overrides)
    assert computed == pytest.approx(reference, rel=0.01)


def test_supports_carry_the_force():
    """
    Check equilibrium: the supports receive the force, -P in z, on time average.

    The undamped span keeps vibrating, so inertia makes the instantaneous sum
    oscillate by about 1 %; its mean over the crossing is -P within 0.1 %, and
    each support carries P times the lever arm of the other (within 1 %).
    """
    s = load_scenario('moving_force_beam', ['train.speed_kmh=10'])
    frames = [f for f in Simulation(s).frames() if 0.0 < f.head_position < 32.0]
    total = np.array([f.bearings[:, :, 2].sum() for f in frames])
    assert total.mean() == pytest.approx(-s.train.axle_load, rel=1e-3)
    mid = min(frames, key=lambda f: abs(f.head_position - 8.0))
    assert mid.bearings[0, :, 2].sum() == pytest.approx(-0.75 * s.train.axle_load, rel=0.01)
    assert mid.bearings[0, 0, 2] == pytest.approx(mid.bearings[0, 1, 2])
