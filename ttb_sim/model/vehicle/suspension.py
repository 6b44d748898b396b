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
The suspension of the 42-DOF multibody car: its elements and matrices.

Every suspension connection is a point-to-point 3-D spring-damper between two
bodies (:class:`SuspensionElements`); the constant stiffness and damping
matrices are sums of T^T diag(k) T over the elements, T the relative motion of
their two ends (:func:`point_motion_matrix`). Bodies, DOFs and axes are those
of :mod:`.matrices`.

Suspension layout and element counts (per car)
----------------------------------------------
* Primary: one spring at each of the 8 axle boxes (PHYSICS.md section 3.1),
  at lateral offset +/-``primary_semi_spacing`` on the axle axis, with Table 1
  per-spring stiffnesses K_px, K_py, K_pz.
* Secondary: one air spring at each of the 4 positions (2 per bogie), at
  +/-``secondary_semi_spacing`` and height ``secondary_height``, with per-spring
  stiffnesses K_sx, K_sy, K_sz.
* Dampers (Table 1 gives only C_pz, C_sy, C_sz, per damper, but not how
  many): the counts are record fields (``primary_vertical_dampers``,
  ``secondary_vertical_dampers``, ``secondary_lateral_dampers``), smeared
  evenly over the spring positions so that any count keeps the left/right and
  front/rear symmetry.  One damper per spring position (8 / 4 / 4, the literal
  reading of Zhai's 2 K (...) + 2 C (...)' per bogie side) gives projected
  damping ratios (phi^T C phi / 2 omega, :func:`~ttb_sim.model.vehicle.modal.
  modal_damping_ratios`) of 0.56 car-body bounce, 0.63 car-body pitch, 0.65
  bogie pitch and 1.52 bogie bounce, which PHYSICS.md 3.1 calls implausible;
  the record's defaults, one primary vertical damper per wheelset and one
  secondary vertical and lateral damper per bogie (4 / 2 / 2), halve them
  (0.28, 0.32, 0.33, 0.76; damped bounce 0.82 Hz).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.model.vehicle.car import body_positions, CarParameters
from ttb_sim.model.vehicle.dofs import (BOGIES, CAR_BODY, DOF_PER_BODY, dofs, N_BODIES, N_DOF,
                                        SIDES, WHEELSETS)


@dataclass(frozen=True)
class SuspensionElements:
    """
    Every suspension connection of a car as point-to-point 3-D spring-dampers.

    Attributes
    ----------
    body_a, body_b : numpy.ndarray
        Shape (n,), the two bodies each element connects.
    point : numpy.ndarray
        Shape (n, 3), attachment point (x, y, z) in the car frame (m); both
        bodies are attached there.
    stiffness : numpy.ndarray
        Shape (n, 3), stiffness along x, y, z (N/m).
    damping : numpy.ndarray
        Shape (n, 3), damping along x, y, z (N s/m), already multiplied by the
        number of dampers per position.
    group : tuple of str
        Name of the spring group of each element.

    """

    body_a: np.ndarray
    body_b: np.ndarray
    point: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    group: tuple[str, ...]


def suspension_elements(params: CarParameters | None = None) -> SuspensionElements:
    """
    Return the primary, secondary and anti-yaw suspension elements of a car.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    SuspensionElements
        Primary elements connect bogie i to its wheelsets at the axle boxes
        (on the axle axis, so wheelset spin is not restrained); secondary
        elements connect the car body to each bogie at the air springs;
        anti-yaw elements (dampers only, longitudinal) connect the car body to
        each bogie at +/- ``yaw_damper_semi_spacing``, omitted when there are none.

    """
    p = params or CarParameters()
    pos = body_positions(p)
    body_a, body_b, point, stiff, damp, group = [], [], [], [], [], []
    # Dampers smeared evenly over the spring positions (8 axle boxes, 4 air springs).
    c_pz = p.primary_damping_z * p.primary_vertical_dampers / 8.0
    c_sz = p.secondary_damping_z * p.secondary_vertical_dampers / 4.0
    c_sy = p.secondary_damping_y * p.secondary_lateral_dampers / 4.0
    c_yaw = p.yaw_damping * p.yaw_dampers / 4.0
    for i, bogie in enumerate(BOGIES):
        for side in SIDES if c_yaw > 0.0 else ():
            body_a.append(CAR_BODY)
            body_b.append(bogie)
            point.append((pos[bogie, 0], side * p.yaw_damper_semi_spacing, p.secondary_height))
            stiff.append((0.0, 0.0, 0.0))
            damp.append((c_yaw, 0.0, 0.0))
            group.append('yaw_damper')
        for side in SIDES:
            body_a.append(CAR_BODY)
            body_b.append(bogie)
            point.append((pos[bogie, 0], side * p.secondary_semi_spacing, p.secondary_height))
            stiff.append((p.secondary_stiffness_x, p.secondary_stiffness_y,
                          p.secondary_stiffness_z))
            damp.append((0.0, c_sy, c_sz))
            group.append('secondary')
        for wheelset in WHEELSETS[2 * i:2 * i + 2]:
            for side in SIDES:
                body_a.append(bogie)
                body_b.append(wheelset)
                point.append((pos[wheelset, 0], side * p.primary_semi_spacing, p.wheel_radius))
                stiff.append((p.primary_stiffness_x, p.primary_stiffness_y,
                              p.primary_stiffness_z))
                damp.append((0.0, 0.0, c_pz))
                group.append('primary')
    return SuspensionElements(np.array(body_a), np.array(body_b), np.array(point, dtype=float),
                              np.array(stiff, dtype=float), np.array(damp, dtype=float),
                              tuple(group))


def point_motion_matrix(bodies: np.ndarray, offsets: np.ndarray,
                        n_dof: int = N_DOF) -> np.ndarray:
    """
    Return the matrices mapping car DOFs to the motion of material points.

    For a point at offset r from the centre of gravity of its body, the small
    displacement is u + theta x r, i.e. ``[I | -skew(r)] [u; theta]``.

    Parameters
    ----------
    bodies : numpy.ndarray
        Shape (n,), body index of each point.
    offsets : numpy.ndarray
        Shape (n, 3), offset r of each point from its body's centre (m).
    n_dof : int
        Length of the DOF vector (42 for one car).

    Returns
    -------
    numpy.ndarray
        Shape (n, 3, n_dof); row k of block i gives the displacement of point i
        along axis k (x, y, z).

    """
    bodies = np.asarray(bodies, dtype=int)
    r = np.asarray(offsets, dtype=float)
    n = bodies.size
    block = np.zeros((n, 3, 6))
    block[:, :, :3] = np.eye(3)
    rx, ry, rz = r[:, 0], r[:, 1], r[:, 2]
    # -skew(r): rows x, y, z; columns roll, pitch, yaw.
    block[:, 0, 4], block[:, 0, 5] = rz, -ry
    block[:, 1, 3], block[:, 1, 5] = -rz, rx
    block[:, 2, 3], block[:, 2, 4] = ry, -rx
    out = np.zeros((n, 3, n_dof))
    cols = DOF_PER_BODY * bodies[:, None] + np.arange(6)[None, :]
    out[np.arange(n)[:, None, None], np.arange(3)[None, :, None], cols[:, None, :]] = block
    return out


def _relative_motion(params: CarParameters, elements: SuspensionElements) -> np.ndarray:
    pos = body_positions(params)
    ta = point_motion_matrix(elements.body_a, elements.point - pos[elements.body_a])
    tb = point_motion_matrix(elements.body_b, elements.point - pos[elements.body_b])
    t = ta - tb
    if not params.longitudinal_pitch_coupling:
        # Zhai-type model: longitudinal suspension forces have no pitch moment arm.
        t[:, 0, dofs(range(N_BODIES), ['pitch'])] = 0.0
    return t


def stiffness_matrix(params: CarParameters | None = None) -> np.ndarray:
    """
    Return the constant 42 x 42 suspension stiffness matrix (N/m, N m/rad).

    Assembled as sum over elements of T^T diag(k) T, where T maps the DOFs to
    the relative displacement of the element's two ends.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    numpy.ndarray
        Symmetric, positive semi-definite; its null space is the rigid motion of
        the whole car (6) plus the spin of each wheelset (4).

    """
    p = params or CarParameters()
    el = suspension_elements(p)
    t = _relative_motion(p, el)
    return np.einsum('nai,na,naj->ij', t, el.stiffness, t)


def damping_matrix(params: CarParameters | None = None) -> np.ndarray:
    """
    Return the constant 42 x 42 suspension damping matrix (N s/m, N m s/rad).

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    numpy.ndarray
        Symmetric, positive semi-definite; excludes the speed-dependent
        gyroscopic terms (see :func:`gyroscopic_matrix`) and all contact terms.

    """
    p = params or CarParameters()
    el = suspension_elements(p)
    t = _relative_motion(p, el)
    return np.einsum('nai,na,naj->ij', t, el.damping, t)
