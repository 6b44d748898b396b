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
Bilinear 4-node surface quadrature on faces in 3-D, shared by face elements.

Faces are four node ids ordered so that (x1 - x0) x (x3 - x0) is the chosen
normal (:mod:`ttb_sim.fe.mesh`). The 2 x 2 Gauss rule integrates the products
of two bilinear shape functions exactly on flat parallelograms.
"""

from __future__ import annotations

import numpy as np

from ttb_sim.errors import FEError

_G = 1.0 / np.sqrt(3.0)
#: Natural coordinates of the face corners.
FACE_CORNERS = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=float)
#: 2 x 2 Gauss points on the face (natural coordinates); weights are all 1.
FACE_GAUSS = FACE_CORNERS * _G


def face_shape_functions(xi: np.ndarray) -> np.ndarray:
    """Return bilinear shape functions at natural points, shape (p, 4)."""
    xi = np.atleast_2d(xi)
    return np.prod(1.0 + xi[:, None, :] * FACE_CORNERS[None], axis=2) / 4.0


def face_shape_gradients(xi: np.ndarray) -> np.ndarray:
    """Return dN/d(xi, eta) at natural points, shape (p, 4, 2)."""
    xi = np.atleast_2d(xi)
    f = 1.0 + xi[:, None, :] * FACE_CORNERS[None]
    g = np.empty(f.shape)
    g[..., 0] = FACE_CORNERS[:, 0] * f[..., 1]
    g[..., 1] = FACE_CORNERS[:, 1] * f[..., 0]
    return g / 4.0


FACE_N = face_shape_functions(FACE_GAUSS)
FACE_DN = face_shape_gradients(FACE_GAUSS)


def face_frames(coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the local frames and area weights at the four Gauss points of faces.

    Parameters
    ----------
    coords : array, shape (k, 4, 3)
        Face node coordinates (m).

    Returns
    -------
    frames : array, shape (k, 4, 3, 3)
        Rows n, s1, s2: unit normal ((x1 - x0) x (x3 - x0) side), the unit
        tangent along xi and n x s1.
    weights : array, shape (k, 4)
        Gauss weight times the area Jacobian (m^2); they sum to the face area.

    """
    coords = np.asarray(coords, dtype=float)
    t = np.einsum('gal,eai->egli', FACE_DN, coords)
    normal = np.cross(t[:, :, 0], t[:, :, 1])
    area = np.linalg.norm(normal, axis=2)
    if np.any(area <= 0):
        raise FEError('degenerate face (zero area)')
    n = normal / area[..., None]
    s1 = t[:, :, 0] / np.linalg.norm(t[:, :, 0], axis=2)[..., None]
    s2 = np.cross(n, s1)
    return np.stack([n, s1, s2], axis=2), area


def face_area_normals(coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return each face's area (m^2, shape (k,)) and mean unit normal (k, 3)."""
    frames, weights = face_frames(coords)
    area = weights.sum(axis=1)
    n = np.einsum('eg,egi->ei', weights, frames[:, :, 0])
    return area, n / np.linalg.norm(n, axis=1)[:, None]
