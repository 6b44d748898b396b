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
The 8-node thin-layer interface element (Desai et al., IJNAMG 8, 1984), vectorised.

An element joins two coincident 4-node faces: face ``a`` (nodes 1-4 of [P]
Eq. 4) and face ``b`` (nodes 5-8), listed in the same node order. At each of
the 2 x 2 Gauss points the relative displacement u_a - u_b is interpolated with
the bilinear shape functions and turned into the local frame (n, s1, s2) of
face ``b`` (n = (x1 - x0) x (x3 - x0) side, so build face ``b`` with n pointing
towards face ``a``). The layer strain is that relative displacement over the
notional thickness t ([P] Eq. 5, B = N / t), so with a diagonal modulus
D = diag(D_n, D_s1, D_s2) per Gauss point

    K_e = int_V B^T D B dV = (1 / t) int_A N^T D N dA

(the 1/t that [P] Eq. 10 omits; PHYSICS.md 6.3): the layer acts as springs of
D / t per unit area. The geometry is of zero thickness; t only enters the
strain. Stress (D strain) is a traction, so the internal force vector is
int_A N^T sigma dA.

All Gauss points of a set of elements are handled by one sparse operator
(relative displacement, local axes, per Gauss point = ``relative @ u``), so the
strain, the internal force and the tangent matrix are each one sparse product.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe.quad import face_frames, FACE_N


@dataclass(frozen=True)
class InterfaceSet:
    """
    A set of thin-layer interface elements.

    Attributes
    ----------
    faces_a, faces_b : arrays of int, shape (k, 4)
        Node ids of the two faces, in corresponding order.
    frames : array, shape (k, 4, 3, 3)
        Local frame (rows n, s1, s2) at each Gauss point.
    weights : array, shape (k, 4)
        Gauss weight times area Jacobian (m^2).
    thickness : array, shape (k,)
        Notional layer thickness t (m).
    relative : scipy.sparse.csr_matrix, shape (12 k, n_dofs)
        Maps the global displacement to the local relative displacement
        (n, s1, s2) at each Gauss point, ordered (element, Gauss point, axis).

    """

    faces_a: np.ndarray
    faces_b: np.ndarray
    frames: np.ndarray
    weights: np.ndarray
    thickness: np.ndarray
    relative: sp.csr_matrix

    @property
    def n_elements(self) -> int:
        """Number of elements."""
        return int(len(self.faces_a))

    @property
    def n_points(self) -> int:
        """Number of Gauss points (4 per element)."""
        return 4 * self.n_elements

    def strain(self, u: np.ndarray) -> np.ndarray:
        """Return the layer strain, relative displacement over t, shape (k, 4, 3), axes n s1 s2."""
        rel = (self.relative @ u).reshape(self.n_elements, 4, 3)
        return rel / self.thickness[:, None, None]

    def force(self, stress: np.ndarray) -> np.ndarray:
        """Return the global internal force int_A N^T sigma dA of stresses (k, 4, 3) (Pa)."""
        return self.relative.T @ (stress * self.weights[:, :, None]).ravel()

    def stiffness(self, tangent: np.ndarray) -> sp.csr_matrix:
        """Return the global tangent (1/t) int N^T D N dA of diagonal moduli (k, 4, 3) (Pa)."""
        scale = (tangent * (self.weights / self.thickness[:, None])[:, :, None]).ravel()
        return (self.relative.T @ sp.diags(scale) @ self.relative).tocsr()

    def element_stiffness(self, tangent: np.ndarray) -> np.ndarray:
        """Return element matrices (k, 24, 24), DOFs of face a then face b."""
        g = element_operators(self.frames)
        scale = tangent * (self.weights / self.thickness[:, None])[:, :, None]
        return np.einsum('egri,egr,egrj->eij', g, scale, g)


def element_operators(frames: np.ndarray) -> np.ndarray:
    """Return the local relative-displacement operators, shape (k, 4, 3, 24)."""
    k = len(frames)
    g = np.zeros((k, 4, 3, 24))
    for a in range(4):
        block = frames * FACE_N[None, :, a, None, None]
        g[:, :, :, 3 * a:3 * a + 3] = block
        g[:, :, :, 12 + 3 * a:12 + 3 * a + 3] = -block
    return g


def interface_set(nodes: np.ndarray, faces_a: np.ndarray, faces_b: np.ndarray,
                  thickness: np.ndarray | float, n_dofs: int) -> InterfaceSet:
    """
    Build an :class:`InterfaceSet` from coincident face pairs.

    Parameters
    ----------
    nodes : array, shape (n, 3)
        Node coordinates (m).
    faces_a, faces_b : arrays of int, shape (k, 4)
        Node ids of the two faces; the frame is taken on face b.
    thickness : float or array (k,)
        Notional thickness t (m), > 0.
    n_dofs : int
        Global number of DOFs (3 per node).

    """
    faces_a = np.asarray(faces_a, dtype=int).reshape(-1, 4)
    faces_b = np.asarray(faces_b, dtype=int).reshape(-1, 4)
    k = len(faces_a)
    t = np.broadcast_to(np.asarray(thickness, dtype=float), (k,)).copy()
    if np.any(t <= 0):
        raise FEError(f'interface thickness must be > 0 m, got min {t.min() if k else 0:g}')
    if k == 0:
        return InterfaceSet(faces_a, faces_b, np.zeros((0, 4, 3, 3)), np.zeros((0, 4)), t,
                            sp.csr_matrix((0, n_dofs)))
    frames, weights = face_frames(nodes[faces_b])
    g = element_operators(frames)
    dofs = np.concatenate([(3 * faces_a[:, :, None] + np.arange(3)).reshape(k, 12),
                           (3 * faces_b[:, :, None] + np.arange(3)).reshape(k, 12)], axis=1)
    rows = np.broadcast_to(np.arange(12 * k).reshape(k, 4, 3, 1), g.shape)
    cols = np.broadcast_to(dofs[:, None, None, :], g.shape)
    keep = g != 0
    relative = sp.csr_matrix((g[keep], (rows[keep], cols[keep])), shape=(12 * k, n_dofs))
    return InterfaceSet(faces_a, faces_b, frames, weights, t, relative)
