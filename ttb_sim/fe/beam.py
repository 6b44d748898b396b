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
Three-dimensional Euler-Bernoulli beam elements (12 DOF), vectorised over elements.

Each node carries (ux, uy, uz, rx, ry, rz). In the element's local axes the four
displacement fields along the axis are interpolated as

- axial displacement u and twist theta: linear,
- lateral deflection v (local y): cubic Hermite with rz = dv/dx,
- vertical deflection w (local z): cubic Hermite with ry = -dw/dx.

Element matrices are integrated from those fields with Gauss-Legendre quadrature
(exact for uniform sections), so the mass matrix, the stiffness matrix and the
moving-load vectors all follow from one definition of the shape functions.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import FEError

NODE_DOFS = 6
ELEMENT_DOFS = 12
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_XI = 0.5 * (_GAUSS_X + 1.0)
_WQ = 0.5 * _GAUSS_W


@dataclass(frozen=True)
class BeamSection:
    """
    Section properties of a set of beam elements (arrays of one value per element).

    Attributes
    ----------
    ea : axial stiffness (N)
    gj : torsional stiffness (N m^2)
    ei_y : bending stiffness for deflection along local z (N m^2)
    ei_z : bending stiffness for deflection along local y (N m^2)
    mass : mass per length (kg/m)
    inertia_x : mass moment of inertia about the axis per length (kg m^2/m)

    """

    ea: np.ndarray
    gj: np.ndarray
    ei_y: np.ndarray
    ei_z: np.ndarray
    mass: np.ndarray
    inertia_x: np.ndarray


def hermite(xi: ArrayLike, length: ArrayLike, derivative: int = 0) -> np.ndarray:
    """
    Evaluate cubic Hermite functions, or their x-derivatives, at local coordinates.

    Parameters
    ----------
    xi : array
        Local coordinate in [0, 1].
    length : array
        Element length (m), broadcast with ``xi``.
    derivative : int
        0, 1 or 2: order of the derivative with respect to x = xi * length.

    Returns
    -------
    numpy.ndarray
        Shape ``xi.shape + (4,)``: functions multiplying (w1, w1', w2, w2'),
        where ' is d/dx.

    """
    xi = np.asarray(xi, dtype=float)
    length = np.broadcast_to(np.asarray(length, dtype=float), xi.shape)
    if derivative == 0:
        h = [1 - 3 * xi**2 + 2 * xi**3, xi - 2 * xi**2 + xi**3,
             3 * xi**2 - 2 * xi**3, -xi**2 + xi**3]
    elif derivative == 1:
        h = [-6 * xi + 6 * xi**2, 1 - 4 * xi + 3 * xi**2,
             6 * xi - 6 * xi**2, -2 * xi + 3 * xi**2]
    elif derivative == 2:
        h = [-6 + 12 * xi, -4 + 6 * xi, 6 - 12 * xi, -2 + 6 * xi]
    else:
        raise FEError(f'derivative must be 0, 1 or 2, got {derivative}')
    scale = length ** (-derivative)
    return np.stack([h[0] * scale, h[1] * length * scale, h[2] * scale,
                     h[3] * length * scale], axis=-1)


def vertical_row(xi: ArrayLike, length: ArrayLike, derivative: int = 0) -> np.ndarray:
    """
    Map the local element DOFs (uz1, ry1, uz2, ry2) to w or its x-derivatives.

    Returns
    -------
    numpy.ndarray
        Shape ``xi.shape + (4,)``; the local DOF indices are :data:`W_DOFS`.

    """
    h = hermite(xi, length, derivative)
    return h * np.array([1.0, -1.0, 1.0, -1.0])


def lateral_row(xi: ArrayLike, length: ArrayLike, derivative: int = 0) -> np.ndarray:
    """Map the local element DOFs (uy1, rz1, uy2, rz2) to v or its x-derivatives."""
    return hermite(xi, length, derivative)


W_DOFS = np.array([2, 4, 8, 10])
"""Local DOFs that carry the vertical (local z) deflection."""
V_DOFS = np.array([1, 5, 7, 11])
"""Local DOFs that carry the lateral (local y) deflection."""


def _field_matrices(xi: float, length: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return N (fields u, v, w, theta) and B (u', theta', v'', w'') at one xi, per element."""
    nel = length.shape[0]
    n = np.zeros((nel, 4, ELEMENT_DOFS))
    b = np.zeros((nel, 4, ELEMENT_DOFS))
    xi_e = np.full(nel, xi)
    n[:, 0, 0], n[:, 0, 6] = 1 - xi, xi
    n[:, 3, 3], n[:, 3, 9] = 1 - xi, xi
    n[:, 1, V_DOFS] = lateral_row(xi_e, length)
    n[:, 2, W_DOFS] = vertical_row(xi_e, length)
    b[:, 0, 0], b[:, 0, 6] = -1 / length, 1 / length
    b[:, 1, 3], b[:, 1, 9] = -1 / length, 1 / length
    b[:, 2, V_DOFS] = lateral_row(xi_e, length, 2)
    b[:, 3, W_DOFS] = vertical_row(xi_e, length, 2)
    return n, b


def local_matrices(length: np.ndarray, section: BeamSection) -> tuple[np.ndarray, np.ndarray]:
    """
    Integrate the local stiffness and consistent mass matrices of every element.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        K and M in local axes, each of shape (n_elements, 12, 12).

    """
    length = np.asarray(length, dtype=float)
    d = np.stack([section.ea, section.gj, section.ei_z, section.ei_y], axis=-1)
    rho = np.stack([section.mass, section.mass, section.mass, section.inertia_x], axis=-1)
    k = np.zeros((length.size, ELEMENT_DOFS, ELEMENT_DOFS))
    m = np.zeros_like(k)
    for xi, wq in zip(_XI, _WQ):
        n, b = _field_matrices(xi, length)
        jac = (wq * length)[:, None, None]
        k += jac * np.einsum('eai,ea,eaj->eij', b, d, b)
        m += jac * np.einsum('eai,ea,eaj->eij', n, rho, n)
    return k, m


def rotations(start: np.ndarray, end: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return element lengths and rotation matrices (rows = local axes in global axes).

    The local x axis runs from start to end; local y is ``cross(ref, x)`` with
    ``ref`` the global z axis (global x for vertical elements), so for a girder
    along global x the local axes coincide with the global ones.

    """
    axis = np.asarray(end, float) - np.asarray(start, float)
    length = np.linalg.norm(axis, axis=1)
    ex = axis / length[:, None]
    ref = np.tile([0.0, 0.0, 1.0], (len(ex), 1))
    vertical = np.abs(ex[:, 2]) > 0.999
    ref[vertical] = [1.0, 0.0, 0.0]
    ey = np.cross(ref, ex)
    ey /= np.linalg.norm(ey, axis=1)[:, None]
    ez = np.cross(ex, ey)
    return length, np.stack([ex, ey, ez], axis=1)


def global_matrices(start: np.ndarray, end: np.ndarray,
                    section: BeamSection) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return element stiffness and mass matrices in global axes.

    Returns
    -------
    (K, M, R)
        Arrays of shape (n, 12, 12), (n, 12, 12) and the (n, 3, 3) rotations.

    """
    length, rot = rotations(start, end)
    k, m = local_matrices(length, section)
    t = np.zeros((len(length), ELEMENT_DOFS, ELEMENT_DOFS))
    for block in range(4):
        s = slice(3 * block, 3 * block + 3)
        t[:, s, s] = rot
    kg = np.einsum('eji,ejk,ekl->eil', t, k, t)
    mg = np.einsum('eji,ejk,ekl->eil', t, m, t)
    return kg, mg, rot


def field_rows(xi: np.ndarray, length: np.ndarray, derivative: int = 0) -> np.ndarray:
    """
    Map the 12 DOFs of elements along global x to the six fields at points.

    The fields are (u, v, w, theta_x, theta_y, theta_z) with theta_y = -w' and
    theta_z = v' (the node rotations of the same element), or their first
    x-derivatives.

    Parameters
    ----------
    xi : array
        Local coordinate in [0, 1], shape (n,).
    length : array
        Element length (m), broadcast with ``xi``.
    derivative : int
        0 or 1.

    Returns
    -------
    numpy.ndarray
        Shape (n, 6, 12).

    """
    if derivative not in (0, 1):
        raise FEError(f'derivative must be 0 or 1, got {derivative}')
    xi = np.asarray(xi, dtype=float)
    length = np.broadcast_to(np.asarray(length, dtype=float), xi.shape)
    out = np.zeros(xi.shape + (6, ELEMENT_DOFS))
    if derivative == 0:
        lin = np.stack([1.0 - xi, xi], axis=-1)
    else:
        lin = np.stack([-1.0 / length, 1.0 / length], axis=-1)
    out[..., 0, [0, 6]] = lin
    out[..., 3, [3, 9]] = lin
    out[..., 1, V_DOFS] = lateral_row(xi, length, derivative)
    out[..., 2, W_DOFS] = vertical_row(xi, length, derivative)
    out[..., 4, W_DOFS] = -vertical_row(xi, length, derivative + 1)
    out[..., 5, V_DOFS] = lateral_row(xi, length, derivative + 1)
    return out


def point_rows(xi: np.ndarray, length: np.ndarray, arm: np.ndarray,
               derivative: int = 0) -> np.ndarray:
    """
    Map the 12 DOFs of elements along global x to the motion of offset points.

    A point at ``arm`` = (0, r_y, r_z) from the axis moves by u + theta x r.

    Parameters
    ----------
    xi, length : array
        Local coordinate and element length, shape (n,).
    arm : array
        Offset of each point from the axis, shape (n, 3) or (3,) (m).
    derivative : int
        0 for the displacement, 1 for its x-derivative.

    Returns
    -------
    numpy.ndarray
        Shape (n, 3, 12): rows of the x, y, z displacement of each point.

    """
    return offset_rows(field_rows(xi, length, derivative), arm)


def offset_rows(fields: np.ndarray, arm: np.ndarray) -> np.ndarray:
    """
    Turn field rows (..., 6, n) into rows of the motion u + theta x r of offset points.

    Parameters
    ----------
    fields : array
        Rows of (u, v, w, theta_x, theta_y, theta_z), shape (..., 6, n).
    arm : array
        Offset r of the points from the axis, shape (..., 3) or (3,) (m).

    Returns
    -------
    numpy.ndarray
        Shape (..., 3, n).

    """
    r = np.broadcast_to(np.asarray(arm, dtype=float), fields.shape[:-2] + (3,))
    t, q = fields[..., :3, :], fields[..., 3:, :]
    out = t.copy()
    # theta x r = (ty rz - tz ry, tz rx - tx rz, tx ry - ty rx)
    out[..., 0, :] += q[..., 1, :] * r[..., 2, None] - q[..., 2, :] * r[..., 1, None]
    out[..., 1, :] += q[..., 2, :] * r[..., 0, None] - q[..., 0, :] * r[..., 2, None]
    out[..., 2, :] += q[..., 0, :] * r[..., 1, None] - q[..., 1, :] * r[..., 0, None]
    return out


def interior_compliance(xi: np.ndarray, length: np.ndarray, ea: np.ndarray, gj: np.ndarray,
                        ei_y: np.ndarray, ei_z: np.ndarray, height: float) -> np.ndarray:
    """
    Return the flexibility of an element's interior under a point load at a head point.

    The element interpolates its nodes' motion with the shape functions above,
    which are exact for a beam loaded only at its nodes. Under a point load
    inside the element the beam also deflects as the element clamped at both
    nodes would (the particular solution, zero at the nodes): with the load at
    a = xi L from the first node and b = L - a from the second,

    - deflection under a transverse force: a^3 b^3 / (3 EI L^3),
    - rotation under a moment: a b (a^2 - a b + b^2) / (EI L^3),
    - rotation under a force (and deflection under a moment): (a - b) a^2 b^2 / (2 EI L^3)
      (the slope of the deflection, in the sign of theta_y = -w'),
    - axial displacement and twist: a b / (EA L), a b / (GJ L).

    Nodal displacements of Euler beam elements are exact, so the static
    motion of a point load's own point is the interpolation plus this, on any
    mesh. For a point at ``height`` above the axis (the rail head; force
    (Fx, Fy, Fz) there is a force and a moment (-h Fy, h Fx, 0) at the axis) the
    flexibility is A G A^T with A the map of the axis motion to the point's.

    Parameters
    ----------
    xi, length : numpy.ndarray
        Local coordinate of the load and element length (m), shape (n,).
    ea, gj, ei_y, ei_z : numpy.ndarray
        The element's section (:class:`BeamSection`), shape (n,).
    height : float
        Height of the loaded point above the axis (m).

    Returns
    -------
    numpy.ndarray
        (n, 3, 3): x, y, z motion of the point per unit force along x, y, z (m/N).

    """
    xi = np.asarray(xi, dtype=float)
    length = np.asarray(length, dtype=float)
    xx, xz, yy, zz = interior_terms(xi, length, ea, gj, ei_y, ei_z, height)
    out = np.zeros(xi.shape + (3, 3))
    out[..., 0, 0] = xx
    out[..., 0, 2] = out[..., 2, 0] = xz
    out[..., 1, 1] = yy
    out[..., 2, 2] = zz
    return out


def interior_terms(xi: Any, length: Any, ea: Any, gj: Any, ei_y: Any, ei_z: Any,
                   height: float) -> tuple[Any, Any, Any, Any]:
    """
    Return the non-zero entries xx, xz (= zx), yy, zz of :func:`interior_compliance`.

    Elementwise arithmetic only, so the same function serves numpy arrays and,
    compiled, the scalars of the contact kernels
    (:func:`ttb_sim.sim.coupling.train_track.rail_kernels.rail_rows`).
    """
    a = xi * length
    b = (1.0 - xi) * length
    ab = a * b
    cube = length**3
    deflection = ab**3 / (3.0 * cube)
    rotation = ab * (a * a - ab + b * b) / cube
    coupling = (a - b) * ab * ab / (2.0 * cube)
    return (ab / (length * ea) + height**2 * rotation / ei_y, height * coupling / ei_y,
            deflection / ei_z + height**2 * ab / (length * gj), deflection / ei_y)
