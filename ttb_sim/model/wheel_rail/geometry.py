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
Wheelset contact geometry and the creepages of the wheels (PHYSICS.md 2.3).

Contents:

* :class:`WheelsetGeometry`, the rolling radii and contact angles of the two
  wheels (from the equivalent cone here, or from the profile table of
  :mod:`.profiles`).
* The simplified (equivalent-cone) contact geometry of PHYSICS.md section 2.3.
* Creepages from that geometry and the wheelset motion.

Sign conventions (REP 103 track frame: x forward, y left, z up)
---------------------------------------------------------------
Side s = +1 is the left wheel, s = -1 the right wheel.  Creepages are the
slip velocity of the wheel relative to the rail at the contact point divided
by V (spin: relative angular velocity about the contact normal divided by
V).  The contact angle gamma_s > 0 tilts the normal force on wheel s towards
the track centre (the usual coned-tread case, for both wheels).  PHYSICS.md
writes the creepages in Zhai's axes; with y to the left here, the
longitudinal creepage of the left wheel of a wheelset displaced to the left
is negative, so the creep forces of :mod:`.creep` steer the wheelset back to
the track centre.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail._checks import check_positive

__all__ = [
    'WheelsetGeometry',
    'creepages',
    'simplified_geometry',
]


@dataclass(frozen=True)
class WheelsetGeometry:
    """
    Rolling radii and contact angles of the two wheels of wheelsets.

    Attributes
    ----------
    rolling_radius : numpy.ndarray
        Shape (..., 2): rolling radius of the left and right wheel (m).
    contact_angle : numpy.ndarray
        Shape (..., 2): contact angle of the left and right wheel (rad), > 0
        when the normal on the wheel tilts towards the track centre.

    """

    rolling_radius: np.ndarray
    contact_angle: np.ndarray


def simplified_geometry(lateral: ArrayLike, conicity: float, nominal_radius: float = 0.46
                        ) -> WheelsetGeometry:
    """
    Return the equivalent-cone contact geometry of PHYSICS.md section 2.3.

    r_L = r0 + lambda_e y, r_R = r0 - lambda_e y (y to the left), and the contact
    angle of both wheels is the cone angle arctan(lambda_e).

    Parameters
    ----------
    lateral : array_like
        Wheelset lateral displacement relative to the track y (m).
    conicity : float
        Equivalent conicity lambda_e (-), 0 .. 1.
    nominal_radius : float
        Nominal rolling radius r0 (m).

    Returns
    -------
    WheelsetGeometry
        Arrays of shape ``lateral.shape + (2,)``.

    """
    if not (math.isfinite(conicity) and 0.0 <= conicity <= 1.0):
        raise ModelError(f'conicity = {conicity!r} is invalid; allowed: 0..1')
    check_positive('nominal rolling radius', nominal_radius)
    y = np.asarray(lateral, dtype=float)
    radius = np.stack([nominal_radius + conicity * y, nominal_radius - conicity * y], axis=-1)
    angle = np.full(radius.shape, math.atan(conicity))
    return WheelsetGeometry(rolling_radius=radius, contact_angle=angle)


def creepages(speed: float, geometry: WheelsetGeometry, *, longitudinal_velocity: ArrayLike = 0.0,
              lateral_velocity: ArrayLike = 0.0, yaw: ArrayLike = 0.0,
              yaw_rate: ArrayLike = 0.0, spin_rate: ArrayLike = 0.0,
              roll_rate: ArrayLike = 0.0, nominal_radius: float = 0.46,
              semi_distance: float = 0.7465) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the creepages of the left and right wheel of wheelsets.

    With side s = +1 (left) / -1 (right), rolling radius r_s, contact angle
    gamma_s and nominal spin Omega = V / r0 (PHYSICS.md 2.3, in REP-103 axes):

    * xi_x = (x' - r_s beta' - s b psi') / V + 1 - r_s / r0
    * xi_y = (y' + r0 phi') / V - psi
    * xi_sp = psi' cos(gamma_s) / V - s sin(gamma_s) / r0

    where beta' is the spin perturbation rate (wheelset pitch DOF) and phi'
    the roll rate.  With the equivalent cone (r_s = r0 + s lambda y,
    gamma = lambda) and beta' = phi' = 0 these are PHYSICS.md's
    xi_x = -s (lambda y / r0 + b psi' / V) (+ x'/V), xi_y = y'/V - psi and
    xi_sp = psi'/V - s lambda / r0 up to the sign change of y and psi between
    Zhai's axes and REP 103.

    Parameters
    ----------
    speed : float
        Train speed V (m/s), > 0.
    geometry : WheelsetGeometry
        Rolling radii and contact angles, shape (..., 2).
    longitudinal_velocity, lateral_velocity : array_like
        x' and y' of the wheelset (m/s).
    yaw, yaw_rate : array_like
        psi (rad) and psi' (rad/s) of the wheelset.
    spin_rate, roll_rate : array_like
        beta' and phi' of the wheelset (rad/s).
    nominal_radius : float
        r0 (m).
    semi_distance : float
        b, half the distance between the contact points (m).

    Returns
    -------
    xi_x, xi_y, xi_sp : numpy.ndarray
        Shape (..., 2) (left, right); xi_sp in 1/m.

    """
    if not (math.isfinite(speed) and speed > 0.0):
        raise ModelError(f'speed = {speed!r} m/s is invalid; allowed: finite and > 0')
    side = np.array([1.0, -1.0])
    r = geometry.rolling_radius
    gamma = geometry.contact_angle
    xd = np.asarray(longitudinal_velocity, dtype=float)[..., None]
    yd = np.asarray(lateral_velocity, dtype=float)[..., None]
    psi = np.asarray(yaw, dtype=float)[..., None]
    psid = np.asarray(yaw_rate, dtype=float)[..., None]
    betad = np.asarray(spin_rate, dtype=float)[..., None]
    phid = np.asarray(roll_rate, dtype=float)[..., None]
    xi_x = (xd - r * betad - side * semi_distance * psid) / speed + 1.0 - r / nominal_radius
    xi_y = (yd + nominal_radius * phid) / speed - psi
    xi_sp = psid * np.cos(gamma) / speed - side * np.sin(gamma) / nominal_radius
    xi_x, xi_y, xi_sp = np.broadcast_arrays(xi_x, xi_y, xi_sp)
    return np.array(xi_x), np.array(xi_y), np.array(xi_sp)
