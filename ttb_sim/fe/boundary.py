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
Spring-dashpot boundary faces: the viscous-spring (viscoelastic) boundary.

Each boundary face carries, per unit area, a spring and a dashpot normal to it
and the same pair tangential to it, so that per unit area
K = (k_N - k_T) n n^T + k_T I and C = (c_N - c_T) n n^T + c_T I ([P] Eq. 3;
Liu et al., Earthq. Eng. Eng. Vib. 5(1) 2006). With ``lumping='lumped'`` each
node gets its tributary area int N_a dA (a quarter of a parallelogram face);
with ``'consistent'`` the face carries int N_a N_b dA.

:func:`viscoelastic_coefficients` gives the per-area values of the
viscous-spring boundary: springs alpha G / R, dashpots rho Vs and rho Vp.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe.assembly import assemble
from ttb_sim.fe.quad import face_frames, FACE_N

Lumping = Literal['lumped', 'consistent']


def viscoelastic_coefficients(shear_modulus: np.ndarray, density: np.ndarray,
                              vs: np.ndarray, vp: np.ndarray, distance: np.ndarray,
                              alpha_t: float = 0.67, alpha_n: float = 1.33
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Return per-area (k_N, k_T, c_N, c_T) of the viscous-spring boundary.

    k_N = alpha_n G / R, k_T = alpha_t G / R (N/m^3); c_N = rho Vp,
    c_T = rho Vs (N s/m^3). Defaults are the 3-D values recommended by Liu et al.
    """
    g = np.asarray(shear_modulus, dtype=float)
    r = np.asarray(distance, dtype=float)
    rho = np.asarray(density, dtype=float)
    return alpha_n * g / r, alpha_t * g / r, rho * np.asarray(vp), rho * np.asarray(vs)


def face_matrices(coords: np.ndarray, normal_value: np.ndarray,
                  tangential_value: np.ndarray, lumping: Lumping = 'lumped') -> np.ndarray:
    """
    Return 12 x 12 face matrices of oriented per-area springs (or dashpots).

    Parameters
    ----------
    coords : array, shape (k, 4, 3)
        Face node coordinates (m).
    normal_value, tangential_value : arrays, shape (k,)
        Per-area value normal and tangential to the face (N/m^3 or N s/m^3).
    lumping : {'lumped', 'consistent'}
        Tributary-area (diagonal blocks) or consistent area integration.

    Returns
    -------
    numpy.ndarray
        Shape (k, 12, 12), DOFs (x, y, z) per face node.

    """
    frames, weights = face_frames(coords)
    n = frames[:, :, 0]
    kn = np.asarray(normal_value, dtype=float)[:, None, None, None]
    kt = np.asarray(tangential_value, dtype=float)[:, None, None, None]
    block = (kn - kt) * n[..., :, None] * n[..., None, :] + kt * np.eye(3)
    if lumping == 'lumped':
        area = np.einsum('ga,eg->ea', FACE_N, weights)
        total = weights.sum(1)[:, None, None, None]
        nodal = np.einsum('ea,egij,eg->eaij', area, block, weights) / total
        out = np.zeros((len(coords), 12, 12))
        for a in range(4):
            out[:, 3 * a:3 * a + 3, 3 * a:3 * a + 3] = nodal[:, a]
        return out
    if lumping != 'consistent':
        raise FEError(f"lumping must be 'lumped' or 'consistent', not {lumping!r}")
    nn = np.einsum('ga,gb,eg,egij->eaibj', FACE_N, FACE_N, weights, block)
    return nn.reshape(len(coords), 12, 12)


def boundary_matrix(n_dofs: int, nodes: np.ndarray, faces: np.ndarray,
                    normal_value: np.ndarray, tangential_value: np.ndarray,
                    lumping: Lumping = 'lumped',
                    coords: np.ndarray | None = None) -> sp.csr_matrix:
    """
    Assemble oriented per-area springs (or dashpots) on faces into an n_dofs matrix.

    Parameters
    ----------
    n_dofs : int
        Size of the global matrix (3 DOFs per node).
    nodes : array, shape (n, 3)
        Node coordinates (m).
    faces : array of int, shape (k, 4)
        Node ids of the faces.
    normal_value, tangential_value : arrays, shape (k,)
        Per-area value normal and tangential to each face.
    lumping : {'lumped', 'consistent'}
        See :func:`face_matrices`.
    coords : array, shape (k, 4, 3), optional
        The faces' corner coordinates where they are not ``nodes[faces]`` (the
        faces of a periodic mesh, whose tied nodes do not move the corners).

    """
    faces = np.asarray(faces)
    if len(faces) == 0:
        return sp.csr_matrix((n_dofs, n_dofs))
    mats = face_matrices(nodes[faces] if coords is None else coords, normal_value,
                         tangential_value, lumping)
    dofs = (3 * faces[:, :, None] + np.arange(3)).reshape(len(faces), 12)
    return assemble(n_dofs, dofs, mats)
