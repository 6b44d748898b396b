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
The 8-node trilinear hexahedron for isotropic linear elasticity, vectorised.

Element matrices are integrated with 2 x 2 x 2 Gauss-Legendre points (full
integration) for all elements at once: arrays shaped (m, 24, 24), local DOFs
ordered (u_x, u_y, u_z) per node in the node order of :mod:`ttb_sim.fe.mesh`.
Each element has its own Young's modulus E (Pa), Poisson's ratio nu and
density rho (kg/m^3). Strains are in Voigt order (xx, yy, zz, yz, xz, xy) with
engineering shear strains.

Lumped masses are the row sums of the consistent mass (for a parallelepiped,
one eighth of the element mass at each node). The element matrices of a mesh
are assembled by :func:`ttb_sim.fe.assembly.assemble_chunked`.
"""

from __future__ import annotations

from typing import Optional

import numpy as np

from ttb_sim.errors import FEError

_G = 1.0 / np.sqrt(3.0)
#: Natural coordinates of the node corners.
CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
#: The 2 x 2 x 2 Gauss points (natural coordinates) and weights.
GAUSS_POINTS = CORNERS * _G
GAUSS_WEIGHTS = np.ones(8)


def shape_functions(xi: np.ndarray) -> np.ndarray:
    """Return the trilinear shape functions at natural points, shape (p, 8)."""
    xi = np.atleast_2d(xi)
    return np.prod(1.0 + xi[:, None, :] * CORNERS[None], axis=2) / 8.0


def shape_gradients(xi: np.ndarray) -> np.ndarray:
    """Return dN/dxi at natural points, shape (p, 8, 3)."""
    xi = np.atleast_2d(xi)
    f = 1.0 + xi[:, None, :] * CORNERS[None]
    g = np.empty(f.shape)
    g[..., 0] = CORNERS[:, 0] * f[..., 1] * f[..., 2]
    g[..., 1] = CORNERS[:, 1] * f[..., 0] * f[..., 2]
    g[..., 2] = CORNERS[:, 2] * f[..., 0] * f[..., 1]
    return g / 8.0


_DN = shape_gradients(GAUSS_POINTS)
_N = shape_functions(GAUSS_POINTS)


def elasticity(young: np.ndarray, poisson: np.ndarray) -> np.ndarray:
    """Return the isotropic elasticity matrices (Voigt, engineering shear), shape (m, 6, 6)."""
    young = np.atleast_1d(np.asarray(young, dtype=float))
    poisson = np.broadcast_to(np.asarray(poisson, dtype=float), young.shape)
    lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = young / (2 * (1 + poisson))
    d = np.zeros(young.shape + (6, 6))
    d[:, :3, :3] = lam[:, None, None]
    idx = np.arange(3)
    d[:, idx, idx] += 2 * mu[:, None]
    d[:, idx + 3, idx + 3] = mu[:, None]
    return d


def _jacobians(coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return (dN/dx at the Gauss points (m, 8g, 8, 3), det J (m, 8g))."""
    jac = np.einsum('gai,eaj->egij', _DN, coords)
    det = np.linalg.det(jac)
    if np.any(det <= 0):
        raise FEError('hexahedron with a non-positive Jacobian (inverted or '
                      'badly ordered nodes)')
    grad = np.einsum('egij,gaj->egai', np.linalg.inv(jac), _DN)
    return grad, det


def stretched(grad: np.ndarray, det: np.ndarray, stretch: Optional[np.ndarray]
              ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the gradients and volume factors in complex-stretched coordinates.

    A perfectly matched layer replaces x_i by x~_i with dx~_i = s_i dx_i
    (s_i complex, one per axis and Gauss point): d/dx~_i = (1 / s_i) d/dx_i and
    dV~ = s_x s_y s_z dV. Without a stretch the inputs are returned unchanged.
    Only the real-to-complex change of type is new; the integrals keep their
    form (transposes, not conjugates, so the matrices stay complex symmetric).
    """
    if stretch is None:
        return grad, det
    s = np.asarray(stretch)
    if s.shape != det.shape + (3,):
        raise FEError(f'stretch must have shape {det.shape + (3,)}, not {s.shape}')
    return grad / s[:, :, None, :], det * np.prod(s, axis=-1)


def strain_matrices(grad: np.ndarray) -> np.ndarray:
    """Return B (strain = B u_e) from n functions' gradients (..., n, 3): (..., 6, 3n)."""
    b = np.zeros(grad.shape[:-2] + (6, 3 * grad.shape[-2]), dtype=grad.dtype)
    gx, gy, gz = grad[..., 0], grad[..., 1], grad[..., 2]
    b[..., 0, 0::3] = gx
    b[..., 1, 1::3] = gy
    b[..., 2, 2::3] = gz
    b[..., 3, 1::3] = gz
    b[..., 3, 2::3] = gy
    b[..., 4, 0::3] = gz
    b[..., 4, 2::3] = gx
    b[..., 5, 0::3] = gy
    b[..., 5, 1::3] = gx
    return b


def incompatible_gradients(xi: np.ndarray) -> np.ndarray:
    """
    Return dP_k/dxi_j of Wilson's incompatible modes P_k = 1 - xi_k^2, shape (p, 3, 3).

    Three modes (k = x, y, z) per displacement component: the bending an 8-node
    brick cannot take, which it otherwise resists by spurious shear (locking).
    """
    xi = np.atleast_2d(xi)
    g = np.zeros((xi.shape[0], 3, 3))
    idx = np.arange(3)
    g[:, idx, idx] = -2.0 * xi
    return g


_DP = incompatible_gradients(GAUSS_POINTS)
_DN_CENTRE = shape_gradients(np.zeros(3))[0]


def _incompatible_physical(coords: np.ndarray, det: np.ndarray) -> np.ndarray:
    """
    Return the incompatible modes' gradients (m, 8g, 3, 3) at the Gauss points.

    Taylor, Beresford & Wilson (1976): from the Jacobian at the centre, scaled by
    det J_0 / det J_g, so that their integral over any element is zero and a
    constant strain is reproduced exactly (the patch test) on distorted bricks.
    """
    jac0 = np.einsum('ai,eaj->eij', _DN_CENTRE, coords)
    det0 = np.linalg.det(jac0)
    grad = np.einsum('eij,gkj->egki', np.linalg.inv(jac0), _DP)
    return grad * (det0[:, None] / det)[:, :, None, None]


def _gradients(coords: np.ndarray, stretch: Optional[np.ndarray], incompatible: bool
               ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the functions' gradients (m, 8g, n, 3) and volume factors (m, 8g) of the bricks.

    n = 8 nodal functions, 11 with the incompatible modes; stretched when given.
    """
    coords = np.asarray(coords, dtype=float)
    grad, det = _jacobians(coords)
    if incompatible:
        grad = np.concatenate([grad, _incompatible_physical(coords, det)], axis=2)
    return stretched(grad, det, stretch)


def _elastic_form(grad: np.ndarray, det: np.ndarray, young: np.ndarray,
                  poisson: np.ndarray) -> np.ndarray:
    """
    Return sum_g w det B^T D B for n scalar functions' gradients (m, 8g, n, 3): (m, 3n, 3n).

    DOFs ordered (u_x, u_y, u_z) per function.
    """
    m, _, n, _ = grad.shape
    young = np.asarray(young, dtype=float)
    poisson = np.broadcast_to(np.asarray(poisson, dtype=float), young.shape)
    lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = young / (2 * (1 + poisson))
    # A[a i, b j] = sum_g w det g_ai g_bj; K_aibj = lam A_aibj + mu A_ajbi + mu delta_ij A_akbk
    g = grad.reshape(m, grad.shape[1], 3 * n)
    a = np.matmul(np.swapaxes(g * (det * GAUSS_WEIGHTS)[:, :, None], 1, 2), g)
    a5 = a.reshape(m, n, 3, n, 3)
    trace = np.einsum('eaibi->eab', a5)
    k = lam[:, None, None, None, None] * a5 + mu[:, None, None, None, None] * \
        np.swapaxes(a5, 2, 4)
    idx = np.arange(3)
    k[:, :, idx, :, idx] += mu[None, :, None, None] * trace[None]
    return k.reshape(m, 3 * n, 3 * n)


def stiffness(coords: np.ndarray, young: np.ndarray, poisson: np.ndarray,
              stretch: Optional[np.ndarray] = None, incompatible: bool = False) -> np.ndarray:
    """
    Return element stiffness matrices K_e = sum_g w_g det J_g B_g^T D B_g.

    Parameters
    ----------
    coords : array, shape (m, 8, 3)
        Node coordinates (m).
    young, poisson : arrays, shape (m,)
        Young's modulus (Pa) and Poisson's ratio of each element.
    stretch : complex array, shape (m, 8, 3), optional
        Complex coordinate stretch (s_x, s_y, s_z) at each Gauss point, for a
        perfectly matched layer in the frequency domain (:func:`stretched`).
    incompatible : bool
        Enrich each brick with Wilson's nine incompatible modes
        (:func:`incompatible_gradients`, Taylor's patch-test form), condensed
        out element by element: the same DOFs, no shear locking in bending.

    Returns
    -------
    numpy.ndarray
        Shape (m, 24, 24), N/m; complex (and complex symmetric) with a stretch.

    """
    grad, det = _gradients(coords, stretch, incompatible)
    k = _elastic_form(grad, det, young, poisson)
    if not incompatible:
        return k
    k_uu, k_ua, k_aa = k[:, :24, :24], k[:, :24, 24:], k[:, 24:, 24:]
    condensed = k_uu - np.matmul(k_ua, np.linalg.solve(k_aa, np.swapaxes(k_ua, 1, 2)))
    return 0.5 * (condensed + np.swapaxes(condensed, 1, 2))   # symmetric to the last bit


def stiffness_reference(coords: np.ndarray, young: np.ndarray, poisson: np.ndarray,
                        stretch: Optional[np.ndarray] = None,
                        incompatible: bool = False) -> np.ndarray:
    """
    Return K_e = sum_g w_g det J_g B_g^T D B_g with explicit B matrices (slow; for tests).

    With ``incompatible``, B has the nine incompatible modes' columns too and
    they are condensed out by an explicit inverse of their block.
    """
    grad, det = _gradients(coords, stretch, incompatible)
    b = strain_matrices(grad)
    d = elasticity(young, poisson)
    db = np.matmul(d[:, None], b)
    k = np.matmul(np.swapaxes(b, 2, 3), db * (det * GAUSS_WEIGHTS)[:, :, None, None])
    k = k.sum(axis=1)
    if incompatible:
        k = k[:, :24, :24] - k[:, :24, 24:] @ np.linalg.inv(k[:, 24:, 24:]) @ k[:, 24:, :24]
    return k


def volumes(coords: np.ndarray) -> np.ndarray:
    """Return the volume of each element (m^3)."""
    _, det = _jacobians(np.asarray(coords, dtype=float))
    return det @ GAUSS_WEIGHTS


def consistent_mass(coords: np.ndarray, density: np.ndarray) -> np.ndarray:
    """Return consistent mass matrices rho int N^T N dV, shape (m, 24, 24), kg."""
    _, det = _jacobians(np.asarray(coords, dtype=float))
    scalar = np.einsum('ga,gb,eg->eab', _N, _N, det * GAUSS_WEIGHTS)
    scalar *= np.asarray(density, dtype=float)[:, None, None]
    m = np.zeros((len(scalar), 24, 24))
    for c in range(3):
        m[:, c::3, c::3] = scalar
    return m


def lumped_mass(coords: np.ndarray, density: np.ndarray,
                stretch: Optional[np.ndarray] = None) -> np.ndarray:
    """
    Return row-sum lumped nodal masses rho int N_a dV, shape (m, 8), kg.

    With a ``stretch`` (as in :func:`stiffness`) the volume element is the
    stretched one and the masses are complex.
    """
    _, det = stretched(*_jacobians(np.asarray(coords, dtype=float)), stretch)
    return np.einsum('ga,eg->ea', _N, det * GAUSS_WEIGHTS) * \
        np.asarray(density, dtype=float)[:, None]
