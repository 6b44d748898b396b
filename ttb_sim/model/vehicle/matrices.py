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
The matrices of the 42-DOF multibody car of [P] (Table 1) and of a train of such cars.

Bodies and degrees of freedom
-----------------------------
Seven rigid bodies, six DOF each, body-major ordering
``index = 6 * body + component``:

======  ================  ==========================================
body    name              longitudinal position of the centre (m)
======  ================  ==========================================
0       ``car_body``      0
1       ``bogie_1``       +l_c (front bogie)
2       ``bogie_2``       -l_c (rear bogie)
3..6    ``wheelset_1..4``  +l_c + l_t, +l_c - l_t, -l_c + l_t, -l_c - l_t
======  ================  ==========================================

Components: 0 ``x`` (longitudinal), 1 ``y`` (lateral), 2 ``z`` (vertical),
3 ``roll`` (about x), 4 ``pitch`` (about y), 5 ``yaw`` (about z).

Axes follow REP 103 in the track frame: x forward along the track (direction of
travel), y to the LEFT, z UP; rotations are right-handed about those axes, so
a positive pitch lowers the front of a body and a positive roll raises its
left side.  [P] and Zhai write the vertical equations with z DOWNWARD positive
(PHYSICS.md section 3); here a vertical displacement is positive upward and
gravity acts in -z.  All displacements are perturbations about the prescribed
forward running at speed V; ``x`` is the longitudinal perturbation.

Wheelset spin
-------------
The nominal spin of every wheelset is the prescribed rolling rate
Omega = V / r0 (positive about +y for forward running).  The wheelset
``pitch`` DOF carries the spin perturbation (rotation angle about the axle on
top of Omega t), with inertia I_wy.  The axle boxes sit on the axle axis, so
no suspension element acts on it: it is driven only by the longitudinal creep
forces at the contacts (through ``-r0 * pitch`` in the contact-point motion,
see :func:`contact_map`).  The gyroscopic coupling of roll and yaw caused by
the nominal spin is speed dependent and is provided separately by
:func:`gyroscopic_matrix` (add it to C for a given speed).

Suspension
----------
The primary and secondary suspension, their element counts and the
stiffness and damping matrices are in :mod:`.suspension`.

Documented assumptions (not given in [P])
-----------------------------------------
Heights above the rail top: car-body centre of gravity 1.70 m, secondary
suspension force plane 0.90 m, bogie frame centre of gravity at axle height
(0.46 m), wheelset centre at r0.  Lateral semi-spacings: primary springs
1.00 m, secondary springs 1.00 m.  These are typical high-speed-car values;
they set the lateral-roll coupling.  By default the longitudinal suspension
forces have no pitch moment arm (``longitudinal_pitch_coupling=False``), as
in Zhai's model, whose pitch equations contain vertical forces only; this
keeps the vertical in-plane modes those of PHYSICS.md 3.1.  The price is that
a rigid pitch of the whole car is force-free only as the vertical-plane
rotation (z = -theta x, no x = theta z shift), the small-angle kinematics of
Zhai's model.  With the physical arms (``True``) every rigid motion is
force-free and car-body and bogie pitch rise by about 0.8 % and 0.7 %.

Zero-stiffness modes of the free car (wheelsets not in contact): 6 rigid-body
motions, 4 wheelset spins and 2 mechanisms in which each bogie rocks in
pitch, together with its two wheelsets, about the lateral line through its
two air springs (the secondary suspension sits at the bogie centre).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
import scipy.linalg
import scipy.sparse

from ttb_sim.errors import ModelError
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.vehicle.car import body_positions, CarParameters
from ttb_sim.model.vehicle.dofs import dof, DOF_PER_BODY, dofs, N_BODIES, N_DOF, SIDES, WHEELSETS
from ttb_sim.model.vehicle.suspension import damping_matrix, point_motion_matrix, stiffness_matrix


def mass_matrix(params: CarParameters | None = None) -> np.ndarray:
    """
    Return the constant 42 x 42 diagonal mass matrix (kg, kg m^2).

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    numpy.ndarray
        Diagonal matrix with [m, m, m, I_xx, I_yy, I_zz] per body.

    """
    p = params or CarParameters()
    diag = np.array([
        [p.car_body_mass] * 3 + [p.car_body_roll_inertia, p.car_body_pitch_inertia,
                                 p.car_body_yaw_inertia],
        *([[p.bogie_mass] * 3 + [p.bogie_roll_inertia, p.bogie_pitch_inertia,
                                 p.bogie_yaw_inertia]] * 2),
        *([[p.wheelset_mass] * 3 + [p.wheelset_roll_inertia, p.wheelset_spin_inertia,
                                    p.wheelset_yaw_inertia]] * 4),
    ])
    return np.diag(diag.ravel())


def gyroscopic_matrix(params: CarParameters | None, speed: float) -> np.ndarray:
    """
    Return the skew-symmetric gyroscopic matrix of the spinning wheelsets.

    With the nominal spin Omega = V / r0 about +y, the roll and yaw equations
    of each wheelset gain I_wy Omega (-yaw', +roll') terms.

    Parameters
    ----------
    params : CarParameters or None
        Car parameters; Table 1 defaults if None.
    speed : float
        Train speed V (m/s), >= 0.

    Returns
    -------
    numpy.ndarray
        42 x 42 matrix G to be added to the damping matrix (G = -G^T).

    """
    p = params or CarParameters()
    if not (math.isfinite(speed) and speed >= 0.0):
        raise ModelError(f'speed = {speed!r} m/s is invalid; allowed: finite and >= 0')
    h = p.wheelset_spin_inertia * speed / p.wheel_radius
    g = np.zeros((N_DOF, N_DOF))
    for w in WHEELSETS:
        roll, yaw = dof(w, 'roll'), dof(w, 'yaw')
        g[roll, yaw] = -h
        g[yaw, roll] = h
    return g


def gravity_vector(params: CarParameters | None = None) -> np.ndarray:
    """
    Return the gravity load vector (N), -m g on each vertical DOF (z up).

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    numpy.ndarray
        Shape (42,).

    """
    m = np.diag(mass_matrix(params))
    f = np.zeros(N_DOF)
    z = dofs(range(N_BODIES), ['z'])
    f[z] = -m[z] * GRAVITY
    return f


@dataclass(frozen=True)
class ContactMap:
    """
    Kinematics of the 8 wheel-rail contact points of a car.

    Contact k belongs to wheelset ``wheelset[k]`` (0..3) and side ``side[k]``
    (+1 left, -1 right); order: wheelset 0 left, wheelset 0 right, wheelset 1
    left, ...  The contact point sits at (0, s b, -r0) from the wheelset centre.
    Its rigid-body displacement (of the wheel material) is

    * longitudinal: x_w - r0 pitch_w - s b yaw_w  (rows of ``hx``),
    * lateral:      y_w + r0 roll_w               (rows of ``hy``),
    * vertical:     z_w + s b roll_w              (rows of ``hz``),

    and ``hyaw`` selects yaw_w (the DOF on which the spin moment M_z acts).
    The generalised car force from contact forces (Fx, Fy, Fz, Mz) acting on
    the wheels is ``hx.T @ Fx + hy.T @ Fy + hz.T @ Fz + hyaw.T @ Mz``.  The
    velocity form of the same rows gives the creepage terms of
    :func:`ttb_sim.model.wheel_rail.geometry.creepages`.  The simplified map of PHYSICS.md
    (lateral motion y_w only) is ``hy`` without the r0 roll term.

    Attributes
    ----------
    wheelset, side : numpy.ndarray
        Shape (8,) integer arrays.
    x_offset : numpy.ndarray
        Shape (8,), longitudinal position of the contact relative to the car
        centre (m, forward positive).
    hx, hy, hz, hyaw : numpy.ndarray
        Shape (8, 42) maps (m per unit DOF).
    semi_distance, wheel_radius : float
        b and r0 used (m).

    """

    wheelset: np.ndarray
    side: np.ndarray
    x_offset: np.ndarray
    hx: np.ndarray
    hy: np.ndarray
    hz: np.ndarray
    hyaw: np.ndarray
    semi_distance: float
    wheel_radius: float


def contact_map(params: CarParameters | None = None) -> ContactMap:
    """
    Return the wheelset-to-contact kinematics of a car (see :class:`ContactMap`).

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    ContactMap
        The 8 contacts, ordered wheelset-major, left before right.

    """
    p = params or CarParameters()
    b, r0 = p.contact_semi_distance, p.wheel_radius
    wheelset = np.repeat(np.arange(4), 2)
    side = np.tile(np.array(SIDES), 4)
    bodies = np.array(WHEELSETS)[wheelset]
    offsets = np.column_stack([np.zeros(8), side * b, np.full(8, -r0)])
    t = point_motion_matrix(bodies, offsets)
    hyaw = np.zeros((8, N_DOF))
    hyaw[np.arange(8), DOF_PER_BODY * bodies + 5] = 1.0
    x_offset = body_positions(p)[bodies, 0]
    return ContactMap(wheelset, side, x_offset, t[:, 0], t[:, 1], t[:, 2], hyaw, b, r0)


def contact_spring_stiffness(cmap: ContactMap, vertical: float, lateral: float = 0.0,
                             longitudinal: float = 0.0) -> np.ndarray:
    """
    Return the stiffness of linear springs from each contact point to a rigid rail.

    This is the linearised rigid-track idealisation used for static and modal
    checks (e.g. ``vertical`` = the linearised Hertz stiffness k_H).

    Parameters
    ----------
    cmap : ContactMap
        Contact kinematics from :func:`contact_map`.
    vertical, lateral, longitudinal : float
        Spring stiffness per contact along z, y, x (N/m), >= 0.

    Returns
    -------
    numpy.ndarray
        42 x 42 symmetric stiffness matrix.

    """
    for name, value in (('vertical', vertical), ('lateral', lateral),
                        ('longitudinal', longitudinal)):
        if not (math.isfinite(value) and value >= 0.0):
            raise ModelError(f'contact spring {name} = {value!r} N/m is invalid; '
                             'allowed: finite and >= 0')
    return (vertical * cmap.hz.T @ cmap.hz + lateral * cmap.hy.T @ cmap.hy
            + longitudinal * cmap.hx.T @ cmap.hx)


@dataclass(frozen=True)
class CarMatrices:
    """
    Constant matrices of one car.

    Attributes
    ----------
    mass, damping, stiffness : numpy.ndarray
        42 x 42 matrices (SI).
    gravity : numpy.ndarray
        Gravity load vector (N), shape (42,).
    contacts : ContactMap
        Wheelset-to-contact kinematics.
    params : CarParameters
        The parameters used.

    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    gravity: np.ndarray
    contacts: ContactMap
    params: CarParameters


def car_matrices(params: CarParameters | None = None) -> CarMatrices:
    """
    Build M, C, K, the gravity vector and the contact map of one car.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    CarMatrices
        Everything the coupled solver needs from the car.

    """
    p = params or CarParameters()
    return CarMatrices(mass_matrix(p), damping_matrix(p), stiffness_matrix(p),
                       gravity_vector(p), contact_map(p), p)


@dataclass(frozen=True)
class TrainMatrices:
    """
    Block-diagonal matrices of a train of identical, uncoupled cars.

    Cars are not connected (no couplers are modelled); car k (0 = leading car)
    occupies DOFs 42 k .. 42 k + 41 in the per-car order of this module.

    Attributes
    ----------
    mass, damping, stiffness : scipy.sparse.csr_matrix
        Shape (42 n, 42 n).
    gravity : numpy.ndarray
        Shape (42 n,), N.
    hx, hy, hz, hyaw : scipy.sparse.csr_matrix
        Shape (8 n, 42 n): contact maps of all cars stacked (contact 8 k + i is
        contact i of car k, see :class:`ContactMap`).
    wheelset_x : numpy.ndarray
        Shape (4 n,): longitudinal position of every wheelset relative to the
        head of the train (front end of car 0), m, negative behind the head,
        in DOF order.
    contact_x : numpy.ndarray
        Shape (8 n,): the same for every contact.
    contact_side : numpy.ndarray
        Shape (8 n,): +1 left, -1 right.
    n_cars : int
        Number of cars.
    car_length : float
        Length over couplers of each car (m).

    """

    mass: scipy.sparse.csr_matrix
    damping: scipy.sparse.csr_matrix
    stiffness: scipy.sparse.csr_matrix
    gravity: np.ndarray
    hx: scipy.sparse.csr_matrix
    hy: scipy.sparse.csr_matrix
    hz: scipy.sparse.csr_matrix
    hyaw: scipy.sparse.csr_matrix
    wheelset_x: np.ndarray
    contact_x: np.ndarray
    contact_side: np.ndarray
    n_cars: int
    car_length: float


def train_matrices(params: CarParameters | None = None, n_cars: int = 8,
                   car_length: float = 25.0) -> TrainMatrices:
    """
    Build the stacked matrices of ``n_cars`` identical cars in a row.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.
    n_cars : int
        Number of cars, 1..64 (default 8).
    car_length : float
        Length of each car (m), at least 2 (l_c + l_t + r0) so that wheels of
        neighbouring cars do not overlap (default 25 m).

    Returns
    -------
    TrainMatrices
        Sparse block-diagonal M, C, K, stacked contact maps and positions.

    Raises
    ------
    ModelError
        If ``n_cars`` or ``car_length`` is out of range.

    """
    p = params or CarParameters()
    if isinstance(n_cars, bool) or not isinstance(n_cars, (int, np.integer)) \
            or not 1 <= n_cars <= 64:
        raise ModelError(f'train n_cars = {n_cars!r} is invalid; allowed: integer 1..64')
    min_length = 2.0 * (p.bogie_semi_spacing + p.wheelbase_semi + p.wheel_radius)
    if not (math.isfinite(car_length) and min_length <= car_length <= 100.0):
        msg = (f'train car_length = {car_length!r} m is invalid; '
               f'allowed: {min_length:.3f}..100 m')
        raise ModelError(msg)
    car = car_matrices(p)
    cm = car.contacts
    eye = scipy.sparse.identity(n_cars, format='csr')

    def stack(a: np.ndarray) -> scipy.sparse.csr_matrix:
        return scipy.sparse.kron(eye, scipy.sparse.csr_matrix(a), format='csr')

    centres = -(np.arange(n_cars) + 0.5) * car_length
    ws_x = body_positions(p)[list(WHEELSETS), 0]
    return TrainMatrices(
        mass=stack(car.mass), damping=stack(car.damping), stiffness=stack(car.stiffness),
        gravity=np.tile(car.gravity, n_cars),
        hx=stack(cm.hx), hy=stack(cm.hy), hz=stack(cm.hz), hyaw=stack(cm.hyaw),
        wheelset_x=(centres[:, None] + ws_x[None, :]).ravel(),
        contact_x=(centres[:, None] + cm.x_offset[None, :]).ravel(),
        contact_side=np.tile(cm.side, n_cars),
        n_cars=int(n_cars), car_length=float(car_length))
