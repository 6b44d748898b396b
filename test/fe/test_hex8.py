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
Hexahedron, mesh, interface and boundary elements against closed forms.

References and tolerances are stated per test; exact ones are to round-off.
"""

import numpy as np
import pytest

from ttb_sim.errors import FEError
from ttb_sim.fe import hex8
from ttb_sim.fe.assembly import assemble_chunked
from ttb_sim.fe.boundary import boundary_matrix, face_matrices
from ttb_sim.fe.interface import interface_set
from ttb_sim.fe.mesh import graded_planes, Grid, HEX_FACES, structured_hex
from ttb_sim.fe.quad import face_area_normals


def _distorted_mesh():
    grid = Grid(np.array([0.0, 0.7, 2.0]), np.array([0.0, 1.1, 2.0]),
                np.array([-3.0, -1.2, 0.0]))
    mesh = structured_hex(grid)
    centre = grid.node_id(1, 1, 1)
    mesh.nodes[centre] += [0.13, -0.08, 0.11]
    return mesh, centre


def test_fast_stiffness_equals_b_matrix_form():
    """The gradient form of K equals sum B^T D B on distorted bricks (round-off)."""
    rng = np.random.default_rng(1)
    x = hex8.CORNERS[None] * [0.4, 0.9, 1.3] + 0.08 * rng.standard_normal((20, 8, 3))
    e, nu = rng.uniform(1e6, 1e8, 20), rng.uniform(0.0, 0.45, 20)
    k, ref = hex8.stiffness(x, e, nu), hex8.stiffness_reference(x, e, nu)
    assert np.abs(k - ref).max() <= 1e-12 * np.abs(ref).max()


@pytest.mark.parametrize('incompatible', [False, True], ids=['plain', 'incompatible'])
def test_patch_test_linear_field_is_exact(incompatible: bool) -> None:
    """
    Patch test: a linear displacement on the boundary is reproduced inside (1e-10).

    With the incompatible modes this holds on the distorted patch through Taylor's form.
    """
    mesh, centre = _distorted_mesh()
    n = 3 * mesh.n_nodes
    k = assemble_chunked(n, mesh.cell_dofs(), lambda ids: hex8.stiffness(
        mesh.cell_coordinates(ids), np.full(len(ids), 3e7), np.full(len(ids), 0.3),
        incompatible=incompatible))
    grad = np.array([[1e-3, 2e-4, -5e-4], [3e-4, -2e-3, 1e-4], [-1e-4, 4e-4, 7e-4]])
    exact = (mesh.nodes @ grad.T).ravel()
    inner = np.arange(3 * centre, 3 * centre + 3)
    outer = np.setdiff1d(np.arange(n), inner)
    kd = k.toarray()
    u_in = np.linalg.solve(kd[np.ix_(inner, inner)], -kd[np.ix_(inner, outer)] @ exact[outer])
    assert np.allclose(u_in, exact[inner], rtol=0, atol=1e-10 * np.abs(exact).max())


def test_bar_under_end_load_matches_fl_over_ea():
    """Bar (nu = 0) under an end traction: tip displacement F L / (E A) (1e-10)."""
    grid = Grid(np.linspace(0, 5, 6), np.array([0.0, 0.5]), np.array([0.0, 0.4]))
    mesh = structured_hex(grid)
    n = 3 * mesh.n_nodes
    k = assemble_chunked(n, mesh.cell_dofs(), lambda ids: hex8.stiffness(
        mesh.cell_coordinates(ids), np.full(len(ids), 2e9), np.zeros(len(ids))))
    fixed = np.concatenate([3 * mesh.node_sets['xmin'][:, None] + np.arange(3)]).ravel()
    tip = mesh.node_sets['xmax']
    f = np.zeros(n)
    f[3 * tip] = 1e4 / len(tip)
    free = np.setdiff1d(np.arange(n), fixed)
    u = np.zeros(n)
    u[free] = np.linalg.solve(k.toarray()[np.ix_(free, free)], f[free])
    assert u[3 * tip] == pytest.approx(np.full(len(tip), 1e4 * 5 / (2e9 * 0.2)), rel=1e-10)


def test_lumped_and_consistent_mass_total_rho_v():
    """Lumped and consistent masses both total rho V on a distorted brick (1e-12)."""
    mesh, _ = _distorted_mesh()
    x = mesh.cell_coordinates()
    rho = np.full(mesh.n_cells, 1900.0)
    total = 1900.0 * hex8.volumes(x).sum()
    assert total == pytest.approx(1900.0 * 2 * 2 * 3, rel=1e-12)
    assert hex8.lumped_mass(x, rho).sum() == pytest.approx(total, rel=1e-12)
    assert hex8.consistent_mass(x, rho).sum() / 3 == pytest.approx(total, rel=1e-12)


def test_structured_faces_point_outward():
    """Each outer face set's normal points out of the block (exact)."""
    mesh = structured_hex(Grid(np.array([0.0, 1, 3]), np.array([0.0, 2]), np.array([0.0, 1])))
    expect = {'xmin': [-1, 0, 0], 'xmax': [1, 0, 0], 'ymin': [0, -1, 0], 'ymax': [0, 1, 0],
              'zmin': [0, 0, -1], 'zmax': [0, 0, 1]}
    for name, normal in expect.items():
        _, n = face_area_normals(mesh.nodes[mesh.face_sets[name]])
        assert np.allclose(n, normal)
    assert HEX_FACES.shape == (6, 4)


def test_graded_planes_keep_keys_and_growth():
    """Keys are planes; sizes are <= h in the zone and grow by about growth away from it."""
    p = graded_planes(-20, 20, [-0.443, 0.443, 3.0], [(-0.443, 0.443)], 0.3, 1.3, 3.0)
    for key in (-20, -0.443, 0.443, 3.0, 20):
        assert np.min(np.abs(p - key)) < 1e-12
    sizes = np.diff(p)
    assert sizes.max() <= 3.0 + 1e-9
    inside = (p[:-1] >= -0.443 - 1e-9) & (p[1:] <= 0.443 + 1e-9)
    assert np.all(sizes[inside] <= 0.3 + 1e-9)
    far = p[1:] < -1.0
    assert np.all(sizes[far][:-1] / sizes[far][1:] < 1.35)


def test_interface_spring_per_area_is_d_over_t():
    """A uniform relative displacement d gives traction D d / t: force D d A / t (1e-12)."""
    nodes = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0.0]] * 2)
    s = interface_set(nodes, [[4, 5, 6, 7]], [[0, 1, 2, 3]], 0.05, 24)
    d = np.array([30e6, 4e6, 5e6])
    u = np.zeros(24)
    u[12:24] = np.tile([1e-4, 2e-4, 3e-4], 4)
    f = s.stiffness(np.tile(d, (1, 4, 1))) @ u
    # frame rows n = z, s1 = x, s2 = y
    expect = np.array([d[1] * 1e-4, d[2] * 2e-4, d[0] * 3e-4]) / 0.05 * 6.0
    assert np.allclose(f[12:].reshape(4, 3).sum(0), expect, rtol=1e-12)
    assert np.allclose(f[:12].reshape(4, 3).sum(0), -expect, rtol=1e-12)
    assert np.allclose(s.strain(u)[0], [3e-4 / 0.05, 1e-4 / 0.05, 2e-4 / 0.05])
    stress = np.tile(d * s.strain(u)[0, 0], (1, 4, 1))
    assert np.allclose(s.force(stress), f, rtol=1e-12)


def test_interface_element_matrix_matches_sparse():
    """The dense element matrix and the sparse global matrix agree (round-off)."""
    nodes = np.array([[0, 0, 0], [1, 0, 0.2], [1, 1, 0.1], [0, 1, 0.0]] * 2)
    s = interface_set(nodes, [[4, 5, 6, 7]], [[0, 1, 2, 3]], 0.02, 24)
    tangent = np.random.default_rng(3).uniform(1, 2, (1, 4, 3))
    order = list(range(12, 24)) + list(range(12))
    k = s.stiffness(tangent).toarray()[np.ix_(order, order)]
    assert np.allclose(s.element_stiffness(tangent)[0], k, rtol=1e-12, atol=0)


def test_boundary_lumped_and_consistent_totals():
    """Both lumpings carry (k_N + 2 k_T) A in total; K = (k_N - k_T) nn + k_T I per node."""
    nodes = np.array([[0, 0, 0], [0, 2, 0], [0, 2, 3], [0, 0, 3.0]])
    for lumping in ('lumped', 'consistent'):
        k = boundary_matrix(12, nodes, np.array([[0, 1, 2, 3]]), np.array([5.0]),
                            np.array([1.0]), lumping).toarray()
        assert k.sum() == pytest.approx(6 * 7.0, rel=1e-12)
    m = face_matrices(nodes[None], np.array([5.0]), np.array([1.0]), 'lumped')[0]
    assert np.allclose(m[:3, :3], 1.5 * np.diag([5.0, 1.0, 1.0]))


def test_a_unit_stretch_changes_nothing_and_a_complex_one_keeps_symmetry() -> None:
    rng = np.random.default_rng(7)
    coords = np.repeat(hex8.CORNERS[None] * np.array([0.5, 0.7, 0.3]), 3, axis=0) \
        + rng.normal(0.0, 0.02, (3, 8, 3))
    young, poisson = np.array([1e6, 2e6, 3e6]), np.array([0.25, 0.3, 0.35])
    plain = hex8.stiffness(coords, young, poisson)
    assert np.array_equal(hex8.stiffness(coords, young, poisson, np.ones((3, 8, 3))), plain)
    s = 1.0 + rng.normal(0.0, 0.3, (3, 8, 3)) - 1j * rng.uniform(0.0, 2.0, (3, 8, 3))
    k = hex8.stiffness(coords, young, poisson, s)
    # the fast kernel against the explicit-B one; transposes, not conjugates: Z = Z^T
    np.testing.assert_allclose(k, hex8.stiffness_reference(coords, young, poisson, s),
                               rtol=0, atol=1e-12 * np.abs(k).max())
    np.testing.assert_allclose(k, np.swapaxes(k, 1, 2), rtol=0, atol=1e-12 * np.abs(k).max())
    # a stretch constant over the element scales a box's mass by s_x s_y s_z
    box = hex8.CORNERS[None] * 0.5
    const = np.broadcast_to(np.array([1 - 2j, 1.0, 3 - 1j]), (1, 8, 3))
    np.testing.assert_allclose(hex8.lumped_mass(box, np.array([2.0]), const),
                               hex8.lumped_mass(box, np.array([2.0])) * (1 - 2j) * (3 - 1j))
    with pytest.raises(FEError, match='stretch must have shape'):
        hex8.stiffness(coords, young, poisson, np.ones((3, 8)))


def _cantilever_tip(elements: int, incompatible: bool) -> float:
    """Return the tip deflection of a 10 x 1 x 1 m cantilever (nu = 0) under an end moment."""
    grid = Grid(np.linspace(0.0, 10.0, elements + 1), np.array([0.0, 1.0]),
                np.array([-0.5, 0.5]))
    mesh = structured_hex(grid)
    n = 3 * mesh.n_nodes
    k = assemble_chunked(n, mesh.cell_dofs(), lambda ids: hex8.stiffness(
        mesh.cell_coordinates(ids), np.full(len(ids), 1e9), np.zeros(len(ids)),
        incompatible=incompatible))
    fixed = (3 * mesh.node_sets['xmin'][:, None] + np.arange(3)).ravel()
    tip = mesh.node_sets['xmax']
    f = np.zeros(n)
    moment = 1e6
    # the end moment as the consistent nodal forces of sigma = M z / I over the 1 x 1 end
    # face: +-M / 2 at z = +-0.5 (four nodes: a couple of M)
    f[3 * tip] = moment * mesh.nodes[tip, 2]
    free = np.setdiff1d(np.arange(n), fixed)
    u = np.zeros(n)
    u[free] = np.linalg.solve(k.toarray()[np.ix_(free, free)], f[free])
    return float(-u[3 * tip + 2].mean())


def test_incompatible_modes_take_pure_bending_exactly() -> None:
    exact = 1e6 * 10.0**2 / (2 * 1e9 / 12.0)   # M L^2 / (2 E I)
    plain = _cantilever_tip(5, incompatible=False)
    enriched = _cantilever_tip(5, incompatible=True)
    # Wilson's modes represent the bending field of a rectangular brick exactly (nu = 0);
    # the plain brick locks: one brick through the depth at aspect 2 bends a third as far
    assert enriched == pytest.approx(exact, rel=1e-9)
    assert plain < 0.5 * exact


def test_incompatible_kernel_equals_its_explicit_twin() -> None:
    rng = np.random.default_rng(3)
    x = hex8.CORNERS[None] * [0.4, 0.9, 1.3] + 0.08 * rng.standard_normal((6, 8, 3))
    e, nu = rng.uniform(1e6, 1e8, 6), rng.uniform(0.0, 0.45, 6)
    s = 1.0 + rng.normal(0.0, 0.3, (6, 8, 3)) - 1j * rng.uniform(0.0, 2.0, (6, 8, 3))
    for stretch in (None, s):
        k = hex8.stiffness(x, e, nu, stretch, incompatible=True)
        ref = hex8.stiffness_reference(x, e, nu, stretch, incompatible=True)
        np.testing.assert_allclose(k, ref, rtol=0, atol=1e-10 * np.abs(ref).max())
        # symmetric to the last bit (transposes, not conjugates, with a stretch)
        assert np.array_equal(k, np.swapaxes(k, 1, 2))
    # six rigid-body modes, no more: the enrichment adds no spurious zero-energy mode
    eig = np.linalg.eigvalsh(hex8.stiffness(x[:1], e[:1], nu[:1], incompatible=True)[0])
    assert np.sum(np.abs(eig) < 1e-9 * eig.max()) == 6
    # the condensed element is softer than the plain one (it has more freedom inside)
    plain = np.linalg.eigvalsh(hex8.stiffness(x[:1], e[:1], nu[:1])[0])
    assert np.all(eig <= plain * (1 + 1e-9) + 1e-9 * plain.max())
