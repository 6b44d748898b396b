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
                                                 averaged_part, domain_modes, fit_transient,
                                                 HarmonicRecord, restrained_stratum,
                                                 stratum_frequencies, Transient,
                                                 transient_rows)
from ttb_sim.validation.cases.pile_soil import split_response
from ttb_sim.validation.references.independent_fe import (cell_materials, IndependentBlock,
                                                          skfem_cells)
from ttb_sim.validation.references.pile_soil import (restrained_column_root,
                                                     shear_column_frequencies)

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
    fitted = fit_transient(t, slow + 1e-6)
    assert fitted.frequency == pytest.approx(0.73, rel=0.01)
    assert fitted.damping == pytest.approx(0.05, abs=0.005)


def _v15_like_record(f=0.84, zeta=0.24):
    """Return a 20 Hz head response from rest over a near-field hump and a ringing mode."""
    t = np.arange(0.0, 4.0, 1e-3)
    w = 2 * math.pi * f * math.sqrt(1 - zeta**2)
    ring = -8e-7 * np.exp(-zeta * 2 * math.pi * f * t) * np.sin(w * t)
    hump = 3e-6 * np.exp(-t / 0.05) - 3e-6 * np.exp(-t / 0.002)
    return t, 2.2e-5 * np.sin(2 * math.pi * 20.0 * t) + ring + hump


def test_transient_fit_of_a_harmonic_start_needs_the_moving_average_inside_the_record():
    """
    The V15 record: the load-period average's half-windows at the ends hold humps of 2/pi.

    Fitted where the average lies inside the record, the ringing mode comes back within
    2 % in frequency and 0.03 in damping ratio (the hump's exponential beside it).
    """
    t, x = _v15_like_record()
    _, slow = split_response(t, x, 20.0)
    kept_t, kept = averaged_part(t, slow, 20.0)
    assert kept.size == t.size - 2 * 26        # 50 samples a load period: 26 cut each end
    fitted = fit_transient(kept_t, kept)
    assert fitted.frequency == pytest.approx(0.84 * math.sqrt(1 - 0.24**2), rel=0.02)
    assert fitted.damping == pytest.approx(0.24, abs=0.03)
    assert fitted.natural == pytest.approx(0.84, rel=0.02)


def test_transient_fit_of_a_hump_without_ringing_has_no_damping():
    """One decaying hump is no ringing: the spectral peak, damping unknown (NaN)."""
    t = np.arange(0.0, 2.0, 1e-3)
    hump = 2e-6 * np.exp(-t / 0.05) + 1e-8 * np.sin(2 * math.pi * 3.1 * t)
    fitted = fit_transient(t, hump)
    assert math.isnan(fitted.damping)
    assert fitted.natural == fitted.frequency


def test_restrained_column_root_is_the_undamped_stratum_without_restraint():
    thickness, modulus, rho = [2.0, 4.0, 16.0], [6.0e6, 6.0e6, 7.2e6], [1835.0, 1937.0, 1529.0]
    f0 = shear_column_frequencies(thickness, modulus, rho, 1)[0]
    root = restrained_column_root(thickness, modulus, rho, lambda z: 0.0, lambda z: 0.0, f0)
    assert root.real == pytest.approx(0.0, abs=1e-9)
    assert root.imag / (2 * math.pi) == pytest.approx(f0, rel=1e-9)


def test_restrained_column_root_of_a_uniform_restraint_is_the_damped_oscillator():
    """
    Uniform k and c along one layer keep the quarter-wave shape.

    So rho s^2 + c s + k + E beta^2 = 0, beta = pi / 2 h.
    """
    h, e, rho, k, c = 20.0, 7.2e6, 1900.0, 3.0e4, 5.0e3
    beta = math.pi / (2 * h)
    exact = (-c + np.sqrt(complex(c * c - 4 * rho * (k + e * beta**2)))) / (2 * rho)
    root = restrained_column_root([h], [e], [rho], lambda z: k, lambda z: c,
                                  math.sqrt(e / rho) / (4 * h))
    assert root == pytest.approx(exact, rel=1e-9)


def test_restrained_stratum_tends_to_the_stratum_as_the_block_widens():
    """Sides 100 km away restrain nothing: the stratum's mode, undamped (to 1e-3)."""
    layers = load_scenario('pile_harmonic').soil.layers
    first = stratum_frequencies(layers, 1)['vertical'][0]
    wide = restrained_stratum(layers, 1e5, 1e5)
    assert wide.natural == pytest.approx(first, rel=1e-3)
    assert wide.damping == pytest.approx(0.0, abs=1e-3)
    narrow = restrained_stratum(layers, 36.0, 30.0)   # pile_harmonic's block
    assert narrow.natural > first * 1.05               # the side springs stiffen the column
    assert 0.1 < narrow.damping < 1.0                  # and their dashpots damp it


def _record(pile_hz, damping=math.nan):
    return HarmonicRecord(1e-5, 1e-5, Transient(pile_hz, damping), Transient(2.0), 0,
                          np.zeros((0, 3)), np.zeros((0, 8)))


def test_transient_rows_judge_only_the_rigid_base_options():
    scenario = load_scenario('pile_harmonic')
    layers = scenario.soil.layers
    domains = domain_modes(scenario)
    first = stratum_frequencies(layers)['vertical'][0]
    assert domains['fixed'].natural == pytest.approx(first)
    spring = domains['rigid_base']
    runs = {'viscoelastic': _record(3.0), 'lysmer': _record(3.0), 'fixed': _record(first * 1.05),
            'rigid_base': _record(spring.natural * 1.2)}
    rows = {r.quantity: r for r in transient_rows(layers, runs, domains)}
    assert rows['pile transient, fixed: natural frequency'].passed
    assert not rows['pile transient, rigid_base: natural frequency'].passed
    assert rows['pile transient, viscoelastic'].error_kind == 'report'
    assert rows['ground transient, fixed'].error_kind == 'report'
    assert rows['stratum vertical mode 1 (closed form)'].computed == pytest.approx(first)
    # the natural frequency, not the damped one, is judged: a ringing at the domain's
    # damped frequency with its damping ratio passes
    damped = spring.frequency
    runs['rigid_base'] = _record(damped, spring.damping)
    rows = {r.quantity: r for r in transient_rows(layers, runs, domains)}
    assert rows['pile transient, rigid_base: natural frequency'].passed
    assert rows['pile transient, rigid_base: damping ratio'].error_kind == 'report'
