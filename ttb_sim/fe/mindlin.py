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
Mindlin-Reissner bending plate: bilinear MITC4 quadrilaterals on a rectangular grid.

The plate lies in the x-y plane; every node carries (w, theta_x, theta_y): the
deflection along z and right-handed rotations about x and y, the same
convention as the beam nodes of :mod:`ttb_sim.fe.beam` (so theta_x = dw/dy and
theta_y = -dw/dx in the thin limit). A point at height z above the mid-plane
moves in-plane by (u, v) = z (theta_y, -theta_x), so with phi = (theta_y,
-theta_x)

- curvatures kappa = (phi_x,x, phi_y,y, phi_x,y + phi_y,x),
- transverse shear strains gamma = (w,x + phi_x, w,y + phi_y),
- energy 1/2 int kappa^T D_b kappa + kappa_s G h gamma^T gamma + k w^2 dA,
  with D_b = D [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu)/2]] and
  D = E h^3 / (12 (1 - nu^2)),
- kinetic energy 1/2 int rho h w'^2 + rho h^3/12 (theta_x'^2 + theta_y'^2) dA
  (consistent mass with rotary inertia).

Shear locking is avoided with the MITC4 assumed shear strain (Bathe & Dvorkin
1985): gamma_xz is sampled at the mid-points of the element edges parallel to
x and interpolated linearly in y, gamma_yz likewise with x and y exchanged. On
the rectangular (axis-aligned) elements used here the covariant tying reduces
to Cartesian components. All integrals use 2 x 2 Gauss points (exact for the
mass and foundation terms) and are evaluated for all elements at once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe.assembly import assemble

NODE_DOFS = 3
"""Per node: w (m), theta_x, theta_y (rad)."""
ELEMENT_DOFS = 12
SHEAR_FACTOR = 5.0 / 6.0

# Element corners in (xi, eta), counter-clockwise from (-1, -1).
_CORNERS = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
_G = 1.0 / np.sqrt(3.0)
_GAUSS = np.array([[-_G, -_G], [_G, -_G], [_G, _G], [-_G, _G]])
_GAUSS_W = np.ones(4)


@dataclass(frozen=True)
class MindlinPlate:
    """
    Material and thickness of a homogeneous plate.

    Attributes
    ----------
    young : float
        Elastic modulus E (Pa).
    poisson : float
        Poisson's ratio nu.
    thickness : float
        Thickness h (m).
    density : float
        Mass density rho (kg/m^3); the mass per area is rho h.
    shear_factor : float
        Shear correction factor kappa_s (5/6 by default).

    """

    young: float
    poisson: float
    thickness: float
    density: float
    shear_factor: float = SHEAR_FACTOR

    @property
    def bending_stiffness(self) -> float:
        """Return D = E h^3 / (12 (1 - nu^2)) (N m)."""
        return self.young * self.thickness**3 / (12.0 * (1.0 - self.poisson**2))

    @property
    def shear_stiffness(self) -> float:
        """Return kappa_s G h (N/m)."""
        shear = self.young / (2.0 * (1.0 + self.poisson))
        return self.shear_factor * shear * self.thickness

    @property
    def mass_per_area(self) -> float:
        """Return rho h (kg/m^2)."""
        return self.density * self.thickness


@dataclass(frozen=True)
class PlateMesh:
    """
    Structured mesh of rectangles on the grid lines x (ascending) by y (ascending).

    Node (i, j) at (x[i], y[j]) has number ``j * x.size + i``.

    Attributes
    ----------
    x, y : numpy.ndarray
        Grid lines (m).
    nodes : numpy.ndarray
        (n_nodes, 2) node coordinates.
    elements : numpy.ndarray
        (n_el, 4) node numbers, counter-clockwise from the (min x, min y) corner.

    """

    x: np.ndarray
    y: np.ndarray
    nodes: np.ndarray
    elements: np.ndarray

    @property
    def n_dofs(self) -> int:
        """Return the number of DOFs (3 per node)."""
        return NODE_DOFS * self.nodes.shape[0]

    @property
    def dofs(self) -> np.ndarray:
        """Return the (n_el, 12) DOFs of every element."""
        return (self.elements[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)

    def node(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Return the numbers of the nodes at grid indices (i along x, j along y)."""
        return np.asarray(j) * self.x.size + np.asarray(i)

    def nearest(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """Return the numbers of the grid nodes nearest to points (x, y)."""
        i = np.abs(self.x[:, None] - np.atleast_1d(x)[None, :]).argmin(axis=0)
        j = np.abs(self.y[:, None] - np.atleast_1d(y)[None, :]).argmin(axis=0)
        return self.node(i, j)


def rectangular_mesh(x: np.ndarray, y: np.ndarray) -> PlateMesh:
    """
    Build the structured mesh on grid lines x by y.

    Parameters
    ----------
    x, y : array
        Strictly ascending grid lines (m).

    Returns
    -------
    PlateMesh

    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if np.any(np.diff(x) <= 0) or np.any(np.diff(y) <= 0):
        raise FEError('grid lines must be strictly ascending')
    nx = x.size
    xx, yy = np.meshgrid(x, y)
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(y.size - 1))
    first = (j * nx + i).ravel()
    elements = np.stack([first, first + 1, first + nx + 1, first + nx], axis=1)
    return PlateMesh(x, y, np.column_stack([xx.ravel(), yy.ravel()]), elements)


def _shape(xi: np.ndarray, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return bilinear N and its xi, eta derivatives at points, each (n_points, 4)."""
    xi = np.asarray(xi, dtype=float)[:, None]
    eta = np.asarray(eta, dtype=float)[:, None]
    cx, cy = _CORNERS[:, 0], _CORNERS[:, 1]
    n = 0.25 * (1 + cx * xi) * (1 + cy * eta)
    return n, 0.25 * cx * (1 + cy * eta), 0.25 * cy * (1 + cx * xi)


def _shear_rows(xi: np.ndarray, eta: np.ndarray, hx: np.ndarray,
                hy: np.ndarray) -> np.ndarray:
    """
    Return the displacement-based shear strain rows at points, per element.

    Returns
    -------
    numpy.ndarray
        (n_el, n_points, 2, 12): rows of gamma_xz and gamma_yz.

    """
    n, dxi, deta = _shape(xi, eta)
    dx = dxi[None] * (2.0 / hx)[:, None, None]
    dy = deta[None] * (2.0 / hy)[:, None, None]
    out = np.zeros((hx.size, n.shape[0], 2, ELEMENT_DOFS))
    out[..., 0, 0::3] = dx
    out[..., 0, 2::3] = n[None]
    out[..., 1, 0::3] = dy
    out[..., 1, 1::3] = -n[None]
    return out


def element_matrices(mesh: PlateMesh, plate: MindlinPlate,
                     foundation: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """
    Integrate the MITC4 stiffness and the consistent mass of every element.

    Parameters
    ----------
    mesh : PlateMesh
        The rectangular mesh.
    plate : MindlinPlate
        Material and thickness.
    foundation : float
        Winkler foundation modulus k under the whole plate (N/m^3): adds the
        consistent int k w^2 dA / 2 to the stiffness.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        K and M, each of shape (n_el, 12, 12), DOFs (w, theta_x, theta_y) per
        node in the element's node order.

    """
    corner = mesh.nodes[mesh.elements]
    hx = corner[:, 1, 0] - corner[:, 0, 0]
    hy = corner[:, 3, 1] - corner[:, 0, 1]
    n_el = hx.size
    gx, gy = _GAUSS[:, 0], _GAUSS[:, 1]
    n, dxi, deta = _shape(gx, gy)
    dx = dxi[None] * (2.0 / hx)[:, None, None]
    dy = deta[None] * (2.0 / hy)[:, None, None]
    jac = (0.25 * hx * hy)[:, None] * _GAUSS_W[None, :]

    # Curvatures from phi = (theta_y, -theta_x).
    bb = np.zeros((n_el, gx.size, 3, ELEMENT_DOFS))
    bb[..., 0, 2::3] = dx
    bb[..., 1, 1::3] = -dy
    bb[..., 2, 2::3] = dy
    bb[..., 2, 1::3] = -dx

    # MITC4 assumed shear: tying points A (0, -1), C (0, 1) for gamma_xz,
    # D (-1, 0), B (1, 0) for gamma_yz.
    tie = _shear_rows(np.array([0.0, 0.0, -1.0, 1.0]), np.array([-1.0, 1.0, 0.0, 0.0]),
                      hx, hy)
    bs = np.zeros((n_el, gx.size, 2, ELEMENT_DOFS))
    bs[..., 0, :] = (0.5 * (1 - gy)[None, :, None] * tie[:, 0:1, 0, :]
                     + 0.5 * (1 + gy)[None, :, None] * tie[:, 1:2, 0, :])
    bs[..., 1, :] = (0.5 * (1 - gx)[None, :, None] * tie[:, 2:3, 1, :]
                     + 0.5 * (1 + gx)[None, :, None] * tie[:, 3:4, 1, :])

    nu = plate.poisson
    db = plate.bending_stiffness * np.array([[1.0, nu, 0.0], [nu, 1.0, 0.0],
                                             [0.0, 0.0, 0.5 * (1.0 - nu)]])
    k = (np.einsum('eq,eqai,ab,eqbj->eij', jac, bb, db, bb)
         + plate.shear_stiffness * np.einsum('eq,eqai,eqaj->eij', jac, bs, bs))

    # Fields (w, theta_x, theta_y) for mass and foundation.
    nf = np.zeros((gx.size, 3, ELEMENT_DOFS))
    for c in range(NODE_DOFS):
        nf[:, c, c::3] = n
    rh = plate.mass_per_area
    inertia = np.array([rh, rh * plate.thickness**2 / 12.0, rh * plate.thickness**2 / 12.0])
    m = np.einsum('eq,qai,a,qaj->eij', jac, nf, inertia, nf)
    if foundation:
        k = k + foundation * np.einsum('eq,qi,qj->eij', jac, nf[:, 0, :], nf[:, 0, :])
    return k, m


def plate_matrices(mesh: PlateMesh, plate: MindlinPlate,
                   foundation: float = 0.0) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """
    Assemble the global stiffness and mass matrices of the plate.

    Parameters
    ----------
    mesh, plate, foundation
        As for :func:`element_matrices`.

    Returns
    -------
    (scipy.sparse.csr_matrix, scipy.sparse.csr_matrix)
        K and M over ``mesh.n_dofs`` DOFs; DOF 3 n + c is component c of node n.

    """
    k, m = element_matrices(mesh, plate, foundation)
    return assemble(mesh.n_dofs, mesh.dofs, k), assemble(mesh.n_dofs, mesh.dofs, m)


def simply_supported_dofs(mesh: PlateMesh) -> np.ndarray:
    """
    Return the DOFs fixed by hard simple supports on all four edges.

    On the edges x = const, w and theta_x (the rotation about the edge) are
    fixed; on the edges y = const, w and theta_y. These are the conditions of
    Navier's solution of Mindlin's plate equations.
    """
    nx, ny = mesh.x.size, mesh.y.size
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    on_x = ((i == 0) | (i == nx - 1)).ravel()
    on_y = ((j == 0) | (j == ny - 1)).ravel()
    nodes = np.arange(nx * ny)
    fixed = np.concatenate([NODE_DOFS * nodes[on_x | on_y],
                            NODE_DOFS * nodes[on_x] + 1, NODE_DOFS * nodes[on_y] + 2])
    return np.unique(fixed)
