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
Beam element checks against closed forms.

References: simply supported beam frequencies f_j = j^2 pi/(2 L^2) sqrt(EI/m)
(tolerance 1e-4 with 16 elements); tip deflection of a cantilever P L^3/(3 EI)
(exact for cubic Hermite elements, 1e-10); rotation invariance of the element; the
interior flexibility of an element under a point load at a head point against the same
element clamped and split at the load (nodal values exact, 1e-9) and against the closed
form of a clamped beam P a^3 b^3 / (3 EI L^3).
"""

import math

import numpy as np
import pytest
import scipy.linalg as la
from ttb_sim.fe.assembly import assemble, link_kinematics
from ttb_sim.fe.beam import (BeamSection, global_matrices, interior_compliance, local_matrices,
                             offset_rows, vertical_row)


def _section(n, ea=2e9, gj=3e8, ei_y=5e8, ei_z=7e8, m=100.0, ix=20.0):
    return BeamSection(*(np.full(n, v) for v in (ea, gj, ei_y, ei_z, m, ix)))


def _line(n, length, direction=(1.0, 0.0, 0.0)):
    d = np.asarray(direction) / np.linalg.norm(direction)
    x = np.linspace(0, length, n + 1)[:, None] * d
    return x[:-1], x[1:]


def _assemble_line(n, length, direction=(1.0, 0.0, 0.0), **kw):
    start, end = _line(n, length, direction)
    k, m, _ = global_matrices(start, end, _section(n, **kw))
    nodes = np.arange(n)
    dofs = np.concatenate([nodes[:, None] * 6 + np.arange(6),
                           (nodes[:, None] + 1) * 6 + np.arange(6)], axis=1)
    return assemble((n + 1) * 6, dofs, k).toarray(), assemble((n + 1) * 6, dofs, m).toarray()


def test_cantilever_tip_deflection_exact():
    length, p, ei = 3.0, 1e3, 5e8
    k, _ = _assemble_line(4, length)
    free = np.arange(6, k.shape[0])
    f = np.zeros(k.shape[0])
    f[-4] = -p  # uz at the tip
    u = np.zeros_like(f)
    u[free] = np.linalg.solve(k[np.ix_(free, free)], f[free])
    assert u[-4] == pytest.approx(-p * length**3 / (3 * ei), rel=1e-10)
    # ry = -dw/dx: the tip rotates positively when it deflects downward.
    assert u[-2] == pytest.approx(p * length**2 / (2 * ei), rel=1e-10)


@pytest.mark.parametrize('direction', [(1, 0, 0), (0, 0, 1), (1, 2, 3)])
def test_simply_supported_frequencies(direction):
    length, n = 10.0, 16
    # Axial and torsion made stiff so that the lowest modes are the bending ones.
    k, m = _assemble_line(n, length, direction, ea=2e13, gj=3e12, ei_y=5e8, ei_z=5e8)
    # Pin both ends (translations only), whatever the beam's direction.
    fixed = [0, 1, 2, 6 * n, 6 * n + 1, 6 * n + 2]
    free = np.setdiff1d(np.arange(k.shape[0]), fixed)
    w2 = la.eigh(k[np.ix_(free, free)], m[np.ix_(free, free)], eigvals_only=True)
    f = np.sqrt(np.abs(w2)) / (2 * math.pi)
    f1 = math.pi / (2 * length**2) * math.sqrt(5e8 / 100.0)
    # The twist about the beam axis is then free: that rigid mode has zero
    # frequency and is not a bending mode.
    f = f[f > 0.1 * f1]
    # Two bending planes with equal EI give each frequency twice.
    assert f[0] == pytest.approx(f1, rel=1e-4) and f[1] == pytest.approx(f1, rel=1e-4)
    bending = np.sort(f)[:8]
    assert bending[2] == pytest.approx(4 * f1, rel=1e-4)
    assert bending[4] == pytest.approx(9 * f1, rel=1e-4)


def test_element_matrices_symmetric_and_rigid_modes():
    k, m = local_matrices(np.array([2.0]), _section(1))
    assert np.allclose(k, k.transpose(0, 2, 1)) and np.allclose(m, m.transpose(0, 2, 1))
    eig = np.linalg.eigvalsh(k[0])
    assert np.sum(np.abs(eig) < 1e-6 * eig.max()) == 6  # six rigid-body modes
    assert np.all(np.linalg.eigvalsh(m[0]) > 0)
    # Total translational mass is m L in each direction.
    assert m[0][np.ix_([2, 8], [2, 8])].sum() == pytest.approx(200.0)


def test_vertical_row_interpolates_and_differentiates():
    xi = np.linspace(0, 1, 7)
    length = 2.0
    # Nodal values of w = x^3 - x on [0, 2]: w, and ry = -w'.
    nodal = np.array([0.0, 1.0, 6.0, -11.0])
    w = vertical_row(xi, length) @ nodal
    x = xi * length
    assert np.allclose(w, x**3 - x)
    assert np.allclose(vertical_row(xi, length, 1) @ nodal, 3 * x**2 - 1)
    assert np.allclose(vertical_row(xi, length, 2) @ nodal, 6 * x)


def test_link_kinematics_rigid_arm():
    g = link_kinematics(np.array([[0.0, 2.0, 0.0]]), np.zeros((1, 3)))[0]
    q = np.zeros(12)
    q[3] = 0.01  # twist of node a about x
    # A point 2 m to the left rises by 2 * 0.01 when the section twists by +0.01.
    assert np.allclose(g @ q, [0.0, 0.0, 0.02])


@pytest.mark.parametrize('xi', [0.0, 0.13, 0.5, 0.71, 1.0])
def test_interior_compliance_is_the_clamped_element_split_at_the_load(xi):
    # The element clamped at both nodes and cut at the load point into two exact
    # elements: the cut node's motion under the head forces is the interior flexibility.
    length, height = 0.315, 0.088
    sec = {'ea': 1.6e9, 'gj': 1.958e5, 'ei_y': 6.6e6, 'ei_z': 1.08e6}
    got = interior_compliance(np.array([xi]), np.array([length]), *(
        np.array([v]) for v in sec.values()), height)[0]
    head = offset_rows(np.eye(6)[None], np.array([0.0, 0.0, height]))[0]     # (3, 6)
    if xi in (0.0, 1.0):
        np.testing.assert_array_equal(got, 0.0)
        return
    a = xi * length
    ends = np.array([[0.0, 0.0, 0.0], [a, 0.0, 0.0], [length, 0.0, 0.0]])
    section = BeamSection(*(np.full(2, v) for v in (*sec.values(), 60.0, 1.0)))
    k, _, _ = global_matrices(ends[:2], ends[1:], section)
    stiffness = k[0, 6:, 6:] + k[1, :6, :6]           # the cut node, both ends fixed
    want = head @ np.linalg.solve(stiffness, head.T)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
    b = length - a
    assert got[2, 2] == pytest.approx(a**3 * b**3 / (3 * sec['ei_y'] * length**3), rel=1e-12)
