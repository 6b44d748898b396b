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
Foundation records, the Desai law and the assembled substructure.

Refusals name the key, the value and the allowed range; physics checks state
their reference and tolerance.
"""

from typing import Any

import numpy as np
import pytest

from ttb_sim.model.foundation.consistency import check_substructure
from ttb_sim.model.foundation.desai import DesaiLaw, initial_moduli
from ttb_sim.model.foundation.records import (BlockSize, FoundationError, MeshSize, Observation,
                                              PAPER_LAYERS, PileGroup, PileLoad, SoilLayer,
                                              SoilParameters, Substructure)
from ttb_sim.model.foundation.substructure import build
from ttb_sim.validation.cases.pile_soil import desai_monotonic

BAD_DIRECTION: Any = 'w'


@pytest.mark.parametrize('make, match', [
    (lambda: SoilLayer(2.0, 4e6, 0.5, 1800.0), r'soil\.layers\.nu = 0\.5 .*\[0, 0\.5\)'),
    (lambda: SoilLayer(0.0, 4e6, 0.3, 1800.0), r'soil\.layers\.thickness = 0\.0'),
    (lambda: PileGroup(spacing=0.8), r'piles\.spacing = 0\.8 .*overlap'),
    (lambda: PileGroup(nu=0.5), r'piles\.nu = 0\.5'),
    (lambda: MeshSize(h=1.0, h_max=0.5), r'soil\.mesh\.h_max = 0\.5'),
    (lambda: PileLoad(direction=BAD_DIRECTION),
     r"load\.direction = 'w' is invalid; allowed: one of 'x', 'y', 'z'"),
])
def test_bad_records_are_refused(make, match):
    with pytest.raises(FoundationError, match=match):
        make()


def test_bad_combinations_are_refused():
    """Piles outside the block, too long, a missing pile, a mesh too coarse for the load."""
    with pytest.raises(FoundationError, match=r'outside the soil block'):
        check_substructure(Substructure(soil=SoilParameters(block=BlockSize(10.0, 30.0))))
    with pytest.raises(FoundationError, match=r'piles\.length = 25\.0 .*< 22 m'):
        check_substructure(Substructure(piles=PileGroup(length=25.0)))
    with pytest.raises(FoundationError, match=r'load\.pile = 16'):
        check_substructure(Substructure(), PileLoad('harmonic', pile=16))
    with pytest.raises(FoundationError,
                       match=r'load\.frequency = 20 Hz .*soil\.mesh\.h <= 0\.178'):
        check_substructure(Substructure(soil=SoilParameters(mesh=MeshSize(h=0.5))),
                           PileLoad('harmonic', frequency=20.0))


def test_desai_monotonic_shear_v16():
    """V16: tau <= c + sigma_n tan(delta) and the hyperbola, stress and tangent, to 1e-6."""
    peak, stress_error, tangent_error = desai_monotonic(n=501)
    assert peak <= 1.0 + 1e-12
    assert stress_error < 1e-6 and tangent_error < 1e-6


def test_desai_normal_tangent_and_separation():
    """Bandis tangent = d sigma / d eps (central differences, 1e-6); separation frees the layer."""
    k_n0, k_s0 = initial_moduli(np.array([5e6]), np.array([0.25]))
    assert k_n0[0] == pytest.approx(6e6) and k_s0[0] == pytest.approx(2e6)
    assert initial_moduli(np.array([4e6]), np.array([0.35]), 'lame')[1][0] == \
        pytest.approx(0.7 / 0.3 * 4e6 / 2.7, rel=1e-12)
    law = DesaiLaw(k_n0, k_s0, np.array([1e4]), np.array([0.5]), np.array([3e4]))
    eps = np.array([-0.2, -0.01, 0.002])
    h = 1e-7
    for e in eps:
        s = [law.evaluate(np.array([[x, 0.0, 0.0]]), np.zeros((1, 2)))[0][0, 0]
             for x in (e - h, e + h)]
        t = law.evaluate(np.array([[e, 0.0, 0.0]]), np.zeros((1, 2)))[1][0, 0]
        assert (s[1] - s[0]) / (2 * h) == pytest.approx(t, rel=1e-6)
    stress, tangent, _ = law.evaluate(np.array([[0.1, 0.01, 0.0]]), np.zeros((1, 2)))
    assert stress[0, 0] == pytest.approx(3e4)       # total normal stress zero
    assert stress[0, 1] == 0.0 and tangent[0, 1] == pytest.approx(1e-3 * 2e6)


def _small_group():
    mesh = MeshSize(h=0.8, growth=1.5, h_max=3.0)
    return Substructure(soil=SoilParameters(PAPER_LAYERS, BlockSize(14.0, 11.0), mesh),
                        piles=PileGroup(rows=2, cols=3, spacing=3.0, side=0.8, length=6.0),
                        observation=Observation(line_points=5, points=((0.5, 0.2, -1.0),)))


def test_substructure_numbering_operators_and_mass():
    """Pile numbering, head operators (weights sum to 1, rigid rotation), load and mass totals."""
    model = build(_small_group())
    assert model.n_piles == 6
    nodes = model.mesh.nodes
    head = model.head_displacement
    # pile 3 (1-based) is the last of the first row: largest x, smallest y
    u = np.zeros(model.n_dofs)
    u[0::3], u[1::3], u[2::3] = nodes[:, 0], nodes[:, 1], 0.0
    centres = (head @ u).reshape(6, 3)
    assert np.allclose(centres[2, :2], [3.0, -1.5]) and np.allclose(centres[0, :2], [-3, -1.5])
    assert np.allclose(np.asarray(head.sum(axis=1)).ravel(), 1.0)
    # a rigid rotation theta about the pile-3 head centre is recovered
    theta = np.array([1e-3, -2e-3, 3e-3])
    r = nodes - [3.0, -1.5, 0.0]
    u = np.cross(theta, r).ravel()
    assert np.allclose((model.head_rotation @ u).reshape(6, 3)[2], theta, rtol=1e-9)
    f = model.load_vector(PileLoad('static', 1e4, pile=3, direction='y'))
    assert f.sum() == pytest.approx(1e4) and f[1::3].sum() == pytest.approx(1e4)
    layer_mass = sum(la.rho * la.thickness for la in PAPER_LAYERS) * 14 * 11
    pile_extra = 6 * 0.64 * 6.0 * (PileGroup().rho - np.mean([1835, 1937]))
    assert model.mass.sum() / 3 == pytest.approx(layer_mass + pile_extra, rel=0.02)
    # soil points: exact for a linear field
    u = (nodes @ np.array([[1e-3, 2e-3, 3e-3], [0, 1e-3, 0], [0, 0, 2e-3]]).T).ravel()
    pts = model.soil_points
    assert np.allclose(pts.operator @ u, (pts.positions @ np.array(
        [[1e-3, 2e-3, 3e-3], [0, 1e-3, 0], [0, 0, 2e-3]]).T).ravel())
    assert model.summary['interface_elements'] > 0 and model.summary['f_max'] > 0
