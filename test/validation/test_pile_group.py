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
V15's pieces on a small pile pair: the independent FE, the amplitude rows and the transient fit.

The independent FE (scikit-fem) assembles the block from the records and the
mesh geometry alone; the model's frequency response
(:func:`~ttb_sim.model.foundation.frequency_response.frequency_response`, the
operators the time stepping uses) must equal it to round-off for every
boundary option, and the time-domain run's steady amplitudes within V15's 5 %.
"""

import math

import numpy as np
import pytest
import scipy.sparse as sp

from ttb_sim.config import load_scenario
from ttb_sim.errors import ModelError
from ttb_sim.model.foundation.frequency_response import frequency_response
from ttb_sim.model.foundation.records import SoilLayer
from ttb_sim.model.foundation.substructure import build
from ttb_sim.validation.cases.pile_group import (amplitude_rows, AMPLITUDE_TOLERANCE,
                                                 HarmonicRecord, stratum_frequencies,
                                                 transient_frequency, transient_rows)
from ttb_sim.validation.references.independent_fe import (cell_materials, IndependentBlock,
                                                          skfem_cells)

PAIR = ('soil.block.lx=12', 'soil.block.ly=9', 'piles.rows=1', 'piles.cols=2', 'load.pile=2',
        'load.frequency=5', 'soil.mesh.h=0.6', 'soil.mesh.h_max=2.5', 'soil.mesh.h_shaft=2.0',
        'output.soil_points=[[0.0,0.0,0.0]]', 'solver.duration=1.5')
"""Two piles of ``pile_harmonic`` in a 12 x 9 m block (14 079 DOFs), 5 Hz on pile 2."""


def _pair(*extra):
    return load_scenario('pile_harmonic', [*PAIR, 'interface.model=bonded', *extra])


@pytest.mark.parametrize('boundary', ['viscoelastic', 'lysmer', 'fixed', 'rigid_base'])
def test_independent_fe_equals_the_model_for_every_boundary(boundary):
    """The model's K, M, C and boundary equal scikit-fem's to round-off (1e-8), at 5 Hz."""
    scenario = _pair(f'soil.boundary={boundary}', 'soil.boundary_lumping=lumped')
    model = build(scenario.substructure())
    ours = frequency_response(model, scenario.load, [5.0])
    block = IndependentBlock(scenario.substructure(), model.mesh.nodes, model.mesh.cells)
    head = block.head_weights(scenario.load.pile)
    theirs = block.response(5.0, head, head, np.array([[0.0, 0.0, 0.0]]))
    assert theirs.dofs <= int(model.free.sum())
    ours_head = ours.heads[0, scenario.load.pile - 1, 2]
    assert abs(theirs.head - ours_head) <= 1e-8 * abs(ours_head)
    ours_point = ours.points[0, -1]
    assert np.abs(theirs.points[0] - ours_point).max() <= 1e-8 * np.abs(ours_point).max()


def test_independent_fe_parities_sum_to_the_whole_solution(monkeypatch):
    """The four mirror-parity solves of an off-centre load equal one solve of the whole block."""
    scenario = _pair('soil.boundary=rigid_base')
    model = build(scenario.substructure())
    block = IndependentBlock(scenario.substructure(), model.mesh.nodes, model.mesh.cells)
    bases = block.parity_bases()
    assert len(bases) == 4 and sum(b.shape[1] for b in bases) == block.basis.N
    head = block.head_weights(2)
    points = np.array([[0.0, 0.0, 0.0], [-3.0, 2.0, 0.0]])
    parts = block.response(7.0, head, head, points)
    monkeypatch.setattr(block, 'parity_bases',
                        lambda: [sp.identity(block.basis.N, format='csr')])
    whole = block.response(7.0, head, head, points)
    assert parts.dofs < 0.6 * whole.dofs      # the y-antisymmetric parts are not loaded
    assert abs(parts.head - whole.head) <= 1e-9 * abs(whole.head)
    assert np.abs(parts.points - whole.points).max() <= 1e-9 * np.abs(whole.points).max()


def test_independent_fe_consistent_boundary_matrices():
    """With ``boundary_lumping: consistent`` both sides integrate N_a N_b: equal again."""
    scenario = _pair('soil.boundary_lumping=consistent')
    model = build(scenario.substructure())
    ours = frequency_response(model, scenario.load, [5.0]).heads[0, 1, 2]
    block = IndependentBlock(scenario.substructure(), model.mesh.nodes, model.mesh.cells)
    head = block.head_weights(2)
    theirs = block.response(5.0, head, head, np.zeros((0, 3))).head
    assert abs(theirs - ours) <= 1e-8 * abs(ours)


def test_time_domain_amplitudes_match_the_independent_fe():
    """V15's amplitude rows on the pair: the time-domain run users make within 5 %."""
    rows = amplitude_rows(PAIR)
    assert [r.passed for r in rows] == [True, True], rows
    assert all(r.tolerance == AMPLITUDE_TOLERANCE and r.reference > 0 for r in rows)


def test_cells_reordered_to_scikit_fem_whatever_their_corner_order():
    nodes = np.array([[x, y, z] for x in (0.0, 2.0) for y in (0.0, 1.0) for z in (-1.0, 0.0)])
    cells = np.arange(8)[None, :]
    shuffled = cells[:, [5, 2, 7, 0, 3, 6, 1, 4]]
    assert np.array_equal(skfem_cells(nodes, cells), skfem_cells(nodes, shuffled))
    flat = nodes.copy()
    flat[:, 2] = 0.0
    with pytest.raises(ModelError, match='box-like'):
        skfem_cells(flat, cells)


def test_cell_materials_from_centroids():
    scenario = _pair()
    spec = scenario.substructure()
    centroids = np.array([[1.5, 0.0, -0.1],     # inside pile 2, top layer depth
                          [1.5, 0.0, -12.5],    # below the pile tip: bottom layer
                          [0.0, 0.0, -1.0],     # soil, layer 1
                          [0.0, 0.0, -3.0],     # layer 2
                          [0.0, 0.0, -20.0]])   # layer 3
    assert cell_materials(spec, centroids).tolist() == [3, 2, 0, 1, 2]


def test_independent_fe_refuses_what_it_does_not_model():
    scenario = load_scenario('pile_harmonic', PAIR)   # Desai interface
    model = build(scenario.substructure())
    with pytest.raises(ModelError, match='bonded'):
        IndependentBlock(scenario.substructure(), model.mesh.nodes, model.mesh.cells)


def test_stratum_frequencies_of_one_layer_are_the_quarter_wavelength_ones():
    layer = SoilLayer(thickness=20.0, E=5e6, nu=0.25, rho=1900.0)
    g = layer.E / (2 * (1 + layer.nu))
    vs = math.sqrt(g / layer.rho)
    vp = vs * math.sqrt(2 * (1 - layer.nu) / (1 - 2 * layer.nu))
    out = stratum_frequencies([layer], 2)
    assert out['shear'] == pytest.approx([vs / 80, 3 * vs / 80], rel=1e-9)
    assert out['vertical'] == pytest.approx([vp / 80, 3 * vp / 80], rel=1e-9)


def test_transient_fit_recovers_a_damped_cosine():
    t = np.arange(0.0, 4.0, 1e-3)
    slow = 3e-6 * np.exp(-0.05 * 2 * math.pi * 0.73 * t) * np.cos(2 * math.pi * 0.73 * t + 0.4)
    assert transient_frequency(t, slow + 1e-6) == pytest.approx(0.73, rel=0.01)


def _record(pile_hz):
    return HarmonicRecord(1e-5, 1e-5, pile_hz, 2.0, 0, np.zeros((0, 3)), np.zeros((0, 8)))


def test_transient_rows_judge_only_the_rigid_base_options():
    layers = load_scenario('pile_harmonic').soil.layers
    first = stratum_frequencies(layers)['vertical'][0]
    runs = {'viscoelastic': _record(3.0), 'lysmer': _record(3.0), 'fixed': _record(first * 1.05),
            'rigid_base': _record(first * 1.2)}
    rows = {r.quantity: r for r in transient_rows(layers, runs)}
    assert rows['pile transient, fixed'].passed
    assert not rows['pile transient, rigid_base'].passed
    assert rows['pile transient, viscoelastic'].error_kind == 'report'
    assert rows['ground transient, fixed'].error_kind == 'report'
    assert rows['stratum vertical mode 1 (closed form)'].computed == pytest.approx(first)
