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
The slab track mesh (`build_track`): layout counts and the rail on its fasteners.

Defaults ([P] Tables 2 and 4, PHYSICS.md 4): fasteners every s = 0.63 m, nine per
5.6 m slab unit with 0.07 m gaps, k_v = 5e7 N/m, rail EI = 2.059e11 * 3.217e-5.
"""

import math

import numpy as np
import pytest
import scipy.sparse.linalg as sla
from ttb_sim.fe.assembly import assemble, assemble_links
from ttb_sim.fe.beam import global_matrices, NODE_DOFS
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.track import approach_length, build_track, TrackParameters

TRACK = TrackParameters(model='slab')
BRIDGE_LENGTH = 32.0
GIRDER_ELEMENTS = 16
FIRST_NODE = GIRDER_ELEMENTS + 1
P0 = 64000.0 * GRAVITY / 8.0
"""Static wheel load of the [P] Table 1 car: (48 + 2 x 3.2 + 4 x 2.4) t on 8 wheels (N)."""


def _girder() -> BeamLine:
    x = np.linspace(0.0, BRIDGE_LENGTH, GIRDER_ELEMENTS + 1)
    pairs = np.column_stack([np.arange(GIRDER_ELEMENTS), np.arange(1, GIRDER_ELEMENTS + 1)])
    dofs = (pairs[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    return BeamLine(start=x[:-1], length=np.diff(x), dofs=dofs, z=0.0)


@pytest.fixture(scope='module')
def mesh():
    return build_track(TRACK, BRIDGE_LENGTH, 0.0, FIRST_NODE, _girder())


def test_layout_counts(mesh):
    """
    Units, fasteners, nodes and elements follow from the pitch 9 x 0.63 = 5.67 m.

    Automatic approach: train length (0) + 20 m on each side, so the track must
    cover 72 m: ceil(72 / 5.67) = 13 units, 117 fasteners per rail, rails of
    116 bays x 2 elements, slab and base of 13 units x 10 elements (11 nodes).
    """
    assert approach_length(TRACK, 0.0) == 20.0
    assert approach_length(TrackParameters(approach_length=35.0), 100.0) == 35.0
    units = math.ceil((BRIDGE_LENGTH + 40.0) / 5.67)
    assert units == 13
    assert mesh.n_fasteners == units * 9
    assert mesh.x_start == pytest.approx(-20.0)
    assert mesh.x_end == pytest.approx(-20.0 + units * 5.67)
    rail_nodes = (units * 9 - 1) * 2 + 1
    assert mesh.coords.shape == (2 * rail_nodes + 2 * units * 11, 3)
    assert mesh.elements.shape == (2 * (rail_nodes - 1) + 2 * units * 10, 2)
    assert mesh.elements.min() == FIRST_NODE
    assert mesh.elements.max() == FIRST_NODE + mesh.coords.shape[0] - 1
    assert mesh.sections.ea.size == mesh.elements.shape[0]
    assert mesh.links[0].dofs.shape == (2 * mesh.n_fasteners, 12)


def test_rails_run_between_the_outer_fasteners(mesh):
    """The rails start and end at the first and last fastener, 0.28 m inside the units."""
    margin = 0.5 * (0.63 - 0.07)
    for side, rail in zip((1.0, -1.0), mesh.rails):
        assert rail.start[0] == pytest.approx(-20.0 + margin)
        assert rail.end == pytest.approx(-20.0 + margin + (mesh.n_fasteners - 1) * 0.63)
        assert rail.length == pytest.approx(np.full(rail.length.size, 0.315))
        assert rail.y == side * TRACK.rail_semi_spacing
    assert mesh.rail_head == pytest.approx(0.5 * TRACK.rail_height)


@pytest.mark.parametrize('line', ['slab', 'base'])
def test_slab_units_have_gaps(mesh, line):
    """Slab and base units are 5.6 m long with 0.07 m gaps; nothing spans a gap."""
    beam = getattr(mesh, line)
    ends = beam.start + beam.length
    gaps = beam.start[1:] - ends[:-1]
    is_gap = gaps > 1e-9
    assert np.count_nonzero(is_gap) == 12
    assert gaps[is_gap] == pytest.approx(np.full(12, 0.07))
    unit_ends = np.append(ends[:-1][is_gap], ends[-1])
    unit_starts = np.insert(beam.start[1:][is_gap], 0, beam.start[0])
    assert unit_ends - unit_starts == pytest.approx(np.full(13, 5.6))
    _, _, inside = beam.locate(unit_ends[:-1] + 0.035)
    assert not inside.any()


def _rail_on_rigid_slab(mesh):
    """Return the stiffness of the left rail on its fasteners with the slab held, and DOFs."""
    girder_xyz = np.column_stack([np.linspace(0.0, BRIDGE_LENGTH, FIRST_NODE),
                                  np.zeros((FIRST_NODE, 2))])
    xyz = np.concatenate([girder_xyz, mesh.coords])
    n_full = xyz.shape[0] * NODE_DOFS
    el = mesh.elements
    dofs = (el[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    ke, _, _ = global_matrices(xyz[el[:, 0]], xyz[el[:, 1]], mesh.sections)
    fasteners = mesh.links[0]
    k = (assemble(n_full, dofs, ke)
         + assemble_links(n_full, fasteners.dofs, fasteners.kinematics, fasteners.stiffness))
    rail_dofs = np.unique(mesh.rails[0].dofs)
    return k[rail_dofs][:, rail_dofs].tocsc(), rail_dofs, xyz


@pytest.mark.parametrize('where', ['on a fastener', 'mid-bay'])
def test_static_rail_deflection_vs_winkler(mesh, where):
    """
    Rail deflection under P0 on a rigid slab vs the Winkler beam, PHYSICS.md 4.

    Continuous support k = k_v / s = 7.94e7 N/m^2, beta = (k / 4 EI)^(1/4)
    = 1.316 1/m, w = P0 beta / (2 k) = 0.650 mm. The discrete fasteners
    (s beta = 0.83) make the rail 0.7 % stiffer over a fastener and 0.5 % softer
    mid-bay; tolerance 1.5 %.
    """
    k = TRACK.fastener_vertical_stiffness / TRACK.fastener_spacing
    beta = (k / (4.0 * TRACK.rail_young_modulus * TRACK.rail_inertia_y)) ** 0.25
    reference = P0 * beta / (2.0 * k)
    assert reference == pytest.approx(0.65e-3, rel=0.01)

    stiffness, rail_dofs, xyz = _rail_on_rigid_slab(mesh)
    nodes = rail_dofs[::NODE_DOFS] // NODE_DOFS
    x_fasteners = xyz[mesh.links[0].dofs[:mesh.n_fasteners, 0] // NODE_DOFS, 0]
    x_load = x_fasteners[np.argmin(np.abs(x_fasteners - 0.5 * BRIDGE_LENGTH))]
    if where == 'mid-bay':
        x_load += 0.5 * TRACK.fastener_spacing
    node = nodes[np.argmin(np.abs(xyz[nodes, 0] - x_load))]
    assert xyz[node, 0] == pytest.approx(x_load)
    row = np.searchsorted(rail_dofs, node * NODE_DOFS + 2)
    force = np.zeros(rail_dofs.size)
    force[row] = -P0
    w = -sla.spsolve(stiffness, force)[row]
    assert w == pytest.approx(reference, rel=0.015)
