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
Stepping of the pile-soil substructure: schemes against each other and closed forms.

References and tolerances are stated per test.
"""

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.model.foundation.records import (BlockSize, Interface, MeshSize, Observation,
                                              PAPER_LAYERS, PileGroup, PileLoad, SoilParameters,
                                              Substructure)
from ttb_sim.model.foundation.substructure import build
from ttb_sim.sim.substructure import observe, PartitionedNewmark, states, SubstructureRun
from ttb_sim.sim.substructure.stable_step import stable_time_step
from ttb_sim.sim.substructure.state import initial_state
from ttb_sim.validation.cases.pile_soil import (boundary_reflection, harmonic_convergence,
                                                head_stiffness, randolph_wroth_reference,
                                                single_pile)


PILE_SETS = ['soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
             'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6', 'load.type=static',
             'load.amplitude=1000']
"""The built-in single_pile with the mesh and pile of :func:`_pile`."""


def _pile(interface='desai'):
    mesh = MeshSize(h=0.8, growth=1.5, h_max=2.5)
    return Substructure(soil=SoilParameters(PAPER_LAYERS, BlockSize(12.0, 12.0), mesh),
                        piles=PileGroup(rows=1, cols=1, side=0.8, length=6.0),
                        interface=Interface(model=interface),
                        observation=Observation(line_points=0, points=((2.0, 0.0, 0.0),)))


def test_stable_step_undamped_is_two_over_omega():
    """Explicit predictor-corrector: omega dt = 2 without damping (1e-9), less with beta."""
    assert stable_time_step(100.0, 0.0, 0.0, safety=1.0) == pytest.approx(0.02, rel=1e-9)
    assert stable_time_step(100.0, 0.0, 1e-3, safety=1.0) < 0.02


def test_mixed_and_implicit_schemes_agree():
    """Mixed (explicit soil) and implicit runs of a 10 Hz head load: 2 % RMS difference."""
    model = build(_pile())
    load = PileLoad('harmonic', 1e4, 5.0, pile=1)
    force = model.load_vector(load)
    out = {}
    for scheme in ('mixed', 'implicit'):
        out[scheme] = np.array([observe(model, s).pile_displacement[0, 2] for s in states(
            model, force, load.history, 0.6, 0.005, scheme=scheme)])
    diff = np.sqrt(np.mean((out['mixed'] - out['implicit'])**2))
    assert diff <= 0.02 * np.sqrt(np.mean(out['implicit']**2))


def test_modified_and_full_newton_agree_under_slip():
    """A 600 kN head load drives the interface into slip; both Newton variants agree (1e-6)."""
    model = build(_pile())
    force = model.load_vector(PileLoad('static', 6e5, pile=1))
    results = []
    for newton in ('modified', 'full'):
        integ = PartitionedNewmark(model, 0.005, 'mixed', newton)
        state = initial_state(model)
        for k in range(5):
            state = integ.step(state, force * min(1.0, (k + 1) / 3))
        results.append(state.u)
        assert state.slip is not None
    assert np.abs(results[0] - results[1]).max() <= 1e-6 * np.abs(results[1]).max()
    assert np.any(np.abs(state.slip) > 0)


def test_static_frame_and_bonded_vs_desai():
    """Static load gives one frame at t = 0; bonded and Desai stiffness within 10 %."""
    frames = {}
    for interface in ('desai', 'bonded'):
        scenario = load_scenario('single_pile', PILE_SETS + [f'interface.model={interface}'])
        frames[interface] = list(SubstructureRun(scenario).frames())
    assert len(frames['desai']) == 1 and frames['desai'][0].time == 0.0
    w = [f[0].pile_displacement[0, 2] for f in frames.values()]
    assert w[0] > 0 and abs(w[0] / w[1] - 1) < 0.1


@pytest.mark.slow
def test_single_pile_head_stiffness_v14_coarse():
    """V14 on a coarse mesh (h = d/2, 30 m block): within 15 % of Randolph-Wroth."""
    spec = single_pile(h=0.443, growth=1.4, h_max=3.0, block=30.0)
    assert head_stiffness(spec) == pytest.approx(randolph_wroth_reference(spec), rel=0.15)


def test_viscoelastic_and_dashpot_bases_absorb_v13():
    """V13: reflected energy < 5 % (viscous-spring) and < 1 % (dashpots, plane wave)."""
    assert boundary_reflection(depth=20.0, h=0.4) < 0.05
    assert boundary_reflection(depth=20.0, h=0.4, boundary='lysmer') < 0.01


def test_pile_head_harmonic_amplitude_converges_at_second_order():
    """
    Three meshes (h = d/2, d/3, d/4 near the pile, 0.886 m square): observed order 1.5 to 2.5.

    Trilinear bricks converge at second order in displacement; measured 1.78 in this
    16 m block (5 Hz, 1.6 s; 8.66, 8.82, 8.89 um) and 2.05 in a 30 m block (9.54, 11.20,
    11.77 um). The steady amplitude comes from the built-in single_pile scenario run as
    ``ttb-sim run`` steps it.
    """
    values, rate = harmonic_convergence(frequency=5.0, duration=1.6, block=16.0)
    assert values[0] < values[1] < values[2]
    assert 1.5 <= rate <= 2.5
