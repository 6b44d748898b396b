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
Bearing-force coupling of piled piers, checked on a pier whose substructure is known exactly.

A pier column on foundation springs is what ``foundation.model: springs`` builds
inside the bridge; written as a :class:`FoundationOperator` (``spring_pier``)
and attached as a piled pier, the monolithic coupling must reproduce the
spring-founded bridge to round-off, the partitioned one with n = 1 to the
staggering error and with n = 3 to the first-order extrapolation error.
"""

import logging

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.bridge import pier_section, rayleigh_coefficients, span_frequency
from ttb_sim.model.foundation.operator import spring_pier, TOP
import ttb_sim.sim.build as build
from ttb_sim.sim.simulation import Simulation

BRIDGE = ['bridge.n_spans=4', 'solver.dt=2e-4', 'solver.duration=3.0', 'output.rate_hz=1000']
PILED = ['foundation.model=piled', 'foundation.piled_piers=[3]', 'cap.enabled=true']


def springs_operator(scenario, spec=None):
    """Return the spring-founded pier of ``scenario`` as a substructure (``spec`` unused)."""
    fd, pr, b = scenario.foundation, scenario.piers, scenario.bridge
    f1 = span_frequency(b.span_length, b.bending_stiffness, b.mass_per_length)
    k = np.array([fd.lateral_stiffness] * 2 + [fd.vertical_stiffness]
                 + [fd.rotational_stiffness] * 3)
    c = np.array([fd.damping] * 3 + [0.0] * 3)
    return spring_pier(pr.height, pr.elements, pier_section(pr), k, c,
                       rayleigh_coefficients(b.damping_ratio, f1, 4 * f1))


@pytest.fixture
def spring_piles(monkeypatch):
    """Make piled piers stand on the spring-founded pier column."""
    monkeypatch.setattr(build, 'build_foundation', springs_operator)


def passage(overrides, capture=None):
    """Run ten_span_train with ``overrides``; return bearing forces (frames, supports, 2, 3)."""
    sim = Simulation(load_scenario('ten_span_train', BRIDGE + overrides))
    frames = []
    for frame in sim.frames():
        frames.append(frame.bearings)
        if capture is not None:
            capture(sim, frame)
    return np.array(frames)


def relative_rms(x, reference):
    return float(np.sqrt(np.mean((x - reference) ** 2) / np.mean(reference ** 2)))


def test_monolithic_piled_pier_is_the_spring_founded_pier(spring_piles):
    springs = passage([])
    monolithic = passage(PILED + ['solver.coupling=monolithic', 'solver.substructure_steps=1'])
    assert np.abs(springs[:, 2]).max() > 1e5, 'the train must load the piled pier'
    np.testing.assert_allclose(monolithic, springs, rtol=0, atol=1e-9 * np.abs(springs).max())


def test_partitioned_coupling_converges_to_the_monolithic_one(spring_piles):
    monolithic = passage(PILED + ['solver.coupling=monolithic', 'solver.substructure_steps=1'])
    errors = {n: relative_rms(passage(PILED + [f'solver.substructure_steps={n}'])[:, 2],
                              monolithic[:, 2]) for n in (1, 3)}
    # n = 1: one step of staggering, the pier top extrapolated over dt only (O(dt^3))
    assert errors[1] < 1e-5
    # n = 3: the pier top extrapolated over 3 dt; V17's criterion is 1 %
    assert errors[3] < 2e-3
    assert errors[3] > errors[1]


def test_bearing_forces_on_girders_and_pier_are_equal_and_opposite(spring_piles):
    """At every frame the pier top receives minus the force the bearings take from the girders."""
    checked = []

    def capture(sim, frame):
        fd = sim.foundations
        coupling, pier = fd.couplings[0], fd.piers[0]
        state = fd.current()[0]
        # load on the pier top: the girder part plus the pier part of every link
        on_pier = coupling.on_pier(*sim.coupling.bridge_state(coupling.girder_dofs))
        k_b, c_b = coupling.pier_matrices()
        on_pier = on_pier - k_b @ state.u[TOP] - c_b @ state.v[TOP]
        # the bearing forces published for the support act on it (the pier top)
        published = frame.bearings[pier.support].sum(axis=0)
        checked.append((on_pier[:3], published))

    passage(PILED + ['solver.substructure_steps=1'], capture)
    on_pier = np.array([c[0] for c in checked])
    published = np.array([c[1] for c in checked])
    assert np.abs(published[:, 2]).max() > 1e5
    np.testing.assert_allclose(on_pier, published, rtol=0,
                               atol=1e-9 * np.abs(published).max())


def test_partitioned_scheme_decays_after_the_train_has_left(spring_piles):
    """At n dt = 1.5 ms, where the lagged-force scheme blew up, free vibration decays."""
    long = ['solver.dt=5e-4', 'solver.duration=8.0']
    monolithic = passage(PILED + long + ['solver.coupling=monolithic',
                                         'solver.substructure_steps=1'])
    forces = passage(PILED + long + ['solver.substructure_steps=3'])

    def envelope(f, seconds):
        return np.abs(f[:, 2]).max(axis=(1, 2))[1000 * seconds[0]:1000 * seconds[1]].max()

    assert np.isfinite(forces).all()
    # the train has left by 4 s: the free vibration decays as the monolithic one does
    assert envelope(forces, (7, 8)) < 0.5 * envelope(forces, (5, 6))
    assert envelope(forces, (7, 8)) < 1.05 * envelope(monolithic, (7, 8))


@pytest.mark.parametrize('override, message', [
    (['foundation.piled_piers=[1]'], 'foundation.piled_piers'),
    (['foundation.piled_piers=[5]'], 'is not a pier'),
    (['foundation.piled_piers=[3, 3]'], 'twice'),
    (['foundation.piled_piers=[]'], 'needs foundation.piled_piers'),
    (['cap.enabled=false'], 'cap.enabled'),
    (['solver.coupling=monolithic'], 'substructure_steps'),
    (['solver.variant=reduced', 'solver.coupling=monolithic', 'solver.substructure_steps=1'],
     "solver.variant = 'reduced' does not support solver.coupling = 'monolithic'"),
    (['bearings.model=rigid'], "bearings.model = 'elastic'"),
])
def test_piled_scenario_errors_name_the_key(override, message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario('ten_span_train', BRIDGE + PILED + override)


def test_loading_above_the_soil_mesh_resolution_is_warned(caplog):
    """The first car line V / 25 m (3.33 Hz at 300 km/h) against the mesh's f_max."""
    scenario = load_scenario('paper_ttbcpsi')
    with caplog.at_level(logging.WARNING, logger='ttb_sim.sim.build'):
        assert build.warn_unresolved_loading(scenario, 1.30)
    assert 'soil.mesh.h_max = 3 m' in caplog.text and '3.33 Hz' in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger='ttb_sim.sim.build'):
        assert not build.warn_unresolved_loading(scenario, 3.34)
    assert caplog.text == ''
