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
Mindlin plate element (MITC4) checks against closed forms.

References
----------
(a) Thin simply supported square plate (h/a = 0.01): Kirchhoff frequencies
    omega = pi^2 (m^2 + n^2) / a^2 sqrt(D / (rho h)); 24 x 24 elements, first
    four modes within 1 % (the mesh gives at most 0.6 %).
(b) Thick simply supported square plate (h/a = 0.1, nu = 0.3, kappa = 5/6):
    Navier solution of Mindlin's equations (w = W sin(m pi x/a) sin(n pi y/a),
    rotations in cosine-sine, the 2 x 2 determinant below); 24 x 24 elements
    within 1 %. The (1, 1) value in the usual parameter omega h sqrt(rho/G) is
    0.0930, the value tabulated for Mindlin's theory (e.g. Srinivas, Joga Rao
    and Rao 1970); Kirchhoff is 3.5 % (mode 1) to 13 % (mode 4) higher, so the
    shear terms matter and the element captures them.
(c) Free plate on a Winkler foundation k: uniform bounce at sqrt(k / (rho h))
    exactly (1e-9), since the consistent mass and foundation matrices share the
    shape functions; without foundation exactly three zero-frequency modes (no
    spurious mechanisms, which 1-point shear integration would have).
"""

import math

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse.linalg as sla
from ttb_sim.fe.mindlin import (element_matrices, MindlinPlate, plate_matrices, rectangular_mesh,
                                simply_supported_dofs)

STEEL = {'young': 2.1e11, 'poisson': 0.3, 'density': 7800.0}
MODES = ((1, 1), (1, 2), (2, 1), (2, 2))


def _ss_frequencies(a: float, h: float, n_el: int, n_modes: int = 4) -> np.ndarray:
    plate = MindlinPlate(thickness=h, **STEEL)
    grid = np.linspace(0.0, a, n_el + 1)
    mesh = rectangular_mesh(grid, grid)
    k, m = plate_matrices(mesh, plate)
    free = np.setdiff1d(np.arange(mesh.n_dofs), simply_supported_dofs(mesh))
    w2 = sla.eigsh(k[free][:, free].tocsc(), n_modes, m[free][:, free].tocsc(), sigma=0.0,
                   return_eigenvectors=False)
    return np.sqrt(np.sort(w2))


def _kirchhoff(a: float, plate: MindlinPlate, m: int, n: int) -> float:
    return math.pi**2 * (m**2 + n**2) / a**2 * math.sqrt(
        plate.bending_stiffness / plate.mass_per_area)


def _mindlin(a: float, plate: MindlinPlate, m: int, n: int) -> float:
    """Lowest root of the Navier determinant of Mindlin's simply supported plate."""
    k2 = (math.pi / a) ** 2 * (m**2 + n**2)
    s, d = plate.shear_stiffness, plate.bending_stiffness
    rh = plate.mass_per_area
    ri = rh * plate.thickness**2 / 12.0
    # (s k2 - rh x)(d k2 + s - ri x) - s^2 k2 = 0, x = omega^2.
    coeffs = [rh * ri, -(s * k2 * ri + (d * k2 + s) * rh), s * k2 * (d * k2 + s) - s**2 * k2]
    return math.sqrt(min(np.roots(coeffs).real))


def test_thin_simply_supported_plate_matches_kirchhoff():
    a, h = 1.0, 0.01
    plate = MindlinPlate(thickness=h, **STEEL)
    reference = np.sort([_kirchhoff(a, plate, m, n) for m, n in MODES])
    computed = _ss_frequencies(a, h, 24)
    assert np.max(np.abs(computed / reference - 1.0)) < 0.01


def test_thick_simply_supported_plate_matches_mindlin_closed_form():
    a, h = 1.0, 0.1
    plate = MindlinPlate(thickness=h, **STEEL)
    reference = np.sort([_mindlin(a, plate, m, n) for m, n in MODES])
    kirchhoff = np.sort([_kirchhoff(a, plate, m, n) for m, n in MODES])
    computed = _ss_frequencies(a, h, 24)
    assert np.max(np.abs(computed / reference - 1.0)) < 0.01
    # The tabulated Mindlin value of the fundamental, omega h sqrt(rho / G).
    shear_modulus = plate.young / (2 * (1 + plate.poisson))
    assert reference[0] * h * math.sqrt(plate.density / shear_modulus) == pytest.approx(
        0.0930, rel=0.002)
    # Shear deformation matters: Kirchhoff is off by more than the tolerance.
    assert kirchhoff[0] / reference[0] - 1.0 > 0.03
    assert kirchhoff[3] / reference[3] - 1.0 > 0.10
    assert computed[0] / kirchhoff[0] - 1.0 < -0.025


def _free_plate(foundation: float):
    plate = MindlinPlate(thickness=0.2, young=3e10, poisson=0.2, density=2500.0)
    mesh = rectangular_mesh(np.linspace(0.0, 4.0, 9), np.linspace(-1.0, 1.0, 5))
    k, m = plate_matrices(mesh, plate, foundation)
    w2 = la.eigh(k.toarray(), m.toarray(), eigvals_only=True)
    return plate, mesh, k, m, w2


def test_free_plate_has_three_rigid_modes_only():
    _, _, _, _, w2 = _free_plate(0.0)
    scale = w2[-1]
    assert np.sum(np.abs(w2) < 1e-10 * scale) == 3
    # The first elastic mode (about 46 Hz here) is far from zero.
    assert w2[3] > 1e-6 * scale


def test_free_plate_on_winkler_foundation_bounces_at_sqrt_k_over_m():
    k_found = 6e8
    plate, mesh, k, m, w2 = _free_plate(k_found)
    bounce = k_found / plate.mass_per_area
    uniform = np.zeros(mesh.n_dofs)
    uniform[0::3] = 1.0
    residual = k @ uniform - bounce * (m @ uniform)
    assert np.linalg.norm(residual) < 1e-9 * np.linalg.norm(k @ uniform)
    assert np.min(np.abs(w2 / bounce - 1.0)) < 1e-9


def test_element_matrices_are_symmetric_and_scale_with_size():
    plate = MindlinPlate(thickness=0.2, young=3e10, poisson=0.2, density=2500.0)
    mesh = rectangular_mesh(np.array([0.0, 0.3, 1.0]), np.array([0.0, 0.5]))
    k, m = element_matrices(mesh, plate, 1e8)
    assert np.allclose(k, np.swapaxes(k, 1, 2), rtol=0, atol=1e-6 * np.abs(k).max())
    assert np.allclose(m, np.swapaxes(m, 1, 2))
    # Total translational mass of each element.
    w = np.zeros(12)
    w[0::3] = 1.0
    assert np.einsum('i,eij,j->e', w, m, w) == pytest.approx(
        plate.mass_per_area * np.array([0.15, 0.35]))
