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
The wheel-rail contact of one multibody car linearised on rigid, straight, smooth track.

Linearised at speed V about the centred static state (every wheelset at y = 0,
every wheel load P0), for the hunting analysis of :mod:`.stability`: the
contact geometry (:class:`LinearGeometry`, from the equivalent cone or the
profile table) and the contact damping and stiffness C_c, K_c
(:func:`contact_matrices`). The contact laws are those of the time-domain solver
(:meth:`ttb_sim.sim.coupling.train_track.TrainTrackCoupling.step`) with the rails held
fixed, so this is an independent check of that implementation:

* Hertz: Fz = ((rail_z - wheel_z + height(y)) / G)^(3/2), linearised to
  dFz = k_H (height'(0) y - hz q), k_H = 1.5 P0^(1/3) / G;
* lateral: Fy = -eps (f22 xi_y + f23 xi_sp) - s tan(gamma(y)) Fz;
* longitudinal: Fx = -eps f11 xi_x; spin moment Mz = eps (f23 xi_y - f33 xi_sp);
* creepages xi_x = hx q' / V + 1 - r(y) / r0, xi_y = hy q' / V - yaw,
  xi_sp = yaw' cos(gamma) / V - s sin(gamma(y)) / r0;
* creep coefficients of the Hertz ellipse at P0 (``ct.hertz_ellipse`` with the
  solver's default curvatures), scaled with the wheel load as
  (P / P0)^(2/3, 2/3, 1, 4/3) for f11, f22, f23, f33.

y is the wheelset lateral displacement (the geometry argument of the
solver), s = +1 for the left and -1 for the right wheel, and r(y), gamma(y),
height(y) come from the profile table or from the equivalent cone
(:class:`LinearGeometry`).  The saturation factor eps is 1 (linear Kalker)
unless ``creep_factor`` is given; the time-domain solver's Shen-Hedrick-Elkins
factor at the static state is 1 - beta0 / 3 with beta0 = |f23 sin(gamma0)| /
(r0 mu P0) (about 2 % below 1 for the LMA/CHN60 table).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from ttb_sim.errors import ModelError
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.vehicle.dofs import DOF_PER_BODY, N_DOF, WHEELSETS
from ttb_sim.model.vehicle.matrices import contact_map, ContactMap
import ttb_sim.model.wheel_rail as ct
from ttb_sim.model.wheel_rail.contact_table import contact_geometry_table, ContactGeometryTable

__all__ = ['GEOMETRY_STEP', 'LinearGeometry', 'conicity_geometry', 'contact_matrices',
           'table_geometry']

#: Half-width (m) of the central differences of the profile table at y = 0.
GEOMETRY_STEP = 1e-3


@dataclass(frozen=True)
class LinearGeometry:
    """
    Contact geometry of the two wheels of a wheelset, linearised at y = 0.

    Arrays have shape (2,): left wheel (s = +1), right wheel (s = -1); y is the
    wheelset lateral displacement (m, to the left).

    Attributes
    ----------
    radius : numpy.ndarray
        Rolling radius r_s(0) (m).
    radius_slope : numpy.ndarray
        dr_s/dy (-); +lambda, -lambda for an equivalent cone.
    angle : numpy.ndarray
        Contact angle gamma_s(0) (rad), > 0 towards the track centre.
    angle_slope : numpy.ndarray
        dgamma_s/dy (rad/m).
    height_slope : numpy.ndarray
        d height_s/dy (-) of the rigid-contact wheel height of the solver.
    nominal_radius : float
        r0 (m).

    """

    radius: np.ndarray
    radius_slope: np.ndarray
    angle: np.ndarray
    angle_slope: np.ndarray
    height_slope: np.ndarray
    nominal_radius: float


def conicity_geometry(conicity: float, nominal_radius: float = 0.46, *,
                      contact_angle: float | None = None,
                      knife_edge: bool = True) -> LinearGeometry:
    """
    Return the equivalent-cone geometry of the solver's ``geometry = 'conicity'``.

    r_s = r0 + s lambda y, gamma = arctan(lambda) on both wheels (constant) and
    height_s = r_s - r0 (knife-edge rails), as ``TrainTrackCoupling._geometry``.

    Parameters
    ----------
    conicity : float
        Equivalent conicity lambda (-), 0..1.
    nominal_radius : float
        r0 (m).
    contact_angle : float, optional
        Override of the (constant) contact angle (rad).  0 gives the pure
        kinematic wheelset of Klingel: no lateral component of the normal
        force and no static spin creepage.
    knife_edge : bool
        True (the solver): height_s = s lambda y, so the wheelset rolls by
        lambda y / b and the lateral creepage sees the contact-point velocity
        y' + r0 roll' = (1 + r0 lambda / b) y'.  False: height slope 0, the
        wheelset stays level, as in Klingel's derivation.

    Returns
    -------
    LinearGeometry
        The linearised geometry.

    """
    g = ct.simplified_geometry(0.0, conicity, nominal_radius)
    angle = float(g.contact_angle[0]) if contact_angle is None else float(contact_angle)
    if not (math.isfinite(angle) and abs(angle) < 0.5 * math.pi):
        raise ModelError(f'contact_angle = {contact_angle!r} rad is invalid; '
                         'allowed: |angle| < pi/2')
    side = np.array([1.0, -1.0])
    return LinearGeometry(radius=np.asarray(g.rolling_radius, dtype=float),
                          radius_slope=side * conicity, angle=np.full(2, angle),
                          angle_slope=np.zeros(2),
                          height_slope=side * conicity if knife_edge else np.zeros(2),
                          nominal_radius=float(nominal_radius))


def table_geometry(table: ContactGeometryTable | None = None, semi_distance: float = 0.7465,
                   step: float = GEOMETRY_STEP) -> LinearGeometry:
    """
    Return the profile-table geometry linearised by central differences at y = 0.

    Uses the same lookups as the solver (``wheelset_geometry`` and
    ``wheel_height(y, b)``); the table is piecewise linear, so the slope is a
    secant over +-``step``, which for the LMA/CHN60 table changes by < 0.1 %
    between 0.1 and 3 mm.

    Parameters
    ----------
    table : ContactGeometryTable, optional
        The table; the default LMA/CHN60 table if omitted.
    semi_distance : float
        Arm b of the wheel heights (m), the car's contact semi-distance.
    step : float
        Half-width of the central differences (m), > 0.

    Returns
    -------
    LinearGeometry
        The linearised geometry.

    """
    if not (math.isfinite(step) and step > 0.0):
        raise ModelError(f'geometry step = {step!r} m is invalid; allowed: finite and > 0')
    tb = table if table is not None else contact_geometry_table()
    y = np.array([-step, 0.0, step])
    g = tb.wheelset_geometry(y)
    h = tb.wheel_height(y, semi_distance)

    def slope(a: np.ndarray) -> np.ndarray:
        return (a[2] - a[0]) / (2.0 * step)

    return LinearGeometry(radius=g.rolling_radius[1], radius_slope=slope(g.rolling_radius),
                          angle=g.contact_angle[1], angle_slope=slope(g.contact_angle),
                          height_slope=slope(h), nominal_radius=float(tb.nominal_radius))


def contact_matrices(params: CarParameters | None, speed: float, geometry: LinearGeometry, *,
                     tread: str = 'lm', creep_factor: float = 1.0
                     ) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the linearised contact damping C_c and stiffness K_c (42 x 42) on rigid rails.

    Per contact k (side s, wheelset lateral DOF y_k = S_k q, maps hx, hy, hz,
    hyaw of :class:`ttb_sim.model.vehicle.car.ContactMap`) the force perturbations are

    * normal: dFz = Z q with Z = k_H (height' S - hz) (Hertz tangent at P0);
    * longitudinal: dFx = -f11 (hx q' / V - r' / r0 S q)
      - (2/3) f11 xi_x0 dFz / P0, with the static creepage
      xi_x0 = 1 - r(0) / r0 (rolling-radius difference);
    * lateral: dFy = -f22 (hy q' / V - hyaw q)
      - f23 (cos(gamma0) hyaw q' / V - s cos(gamma0) gamma' / r0 S q)
      - f23 xi_sp0 dFz / P0 - s tan(gamma0) dFz - s P0 gamma' / cos^2(gamma0) S q,
      with xi_sp0 = -s sin(gamma0) / r0.  The last two terms are the
      gravitational stiffness (lateral component of the normal force), the
      gamma' term of the spin creepage is the spin-creep stiffness that
      opposes it, and the dFz / P0 term is the load scaling of f23 acting on
      the static spin creepage;
    * spin moment: dMz = f23 (hy q' / V - hyaw q)
      - f33 (cos(gamma0) hyaw q' / V - s cos(gamma0) gamma' / r0 S q)
      - (4/3) f33 xi_sp0 dFz / P0.

    The static lateral creepage is 0, so the load scaling of f22 adds nothing.
    The generalised force hx^T dFx + hy^T dFy + hz^T dFz + hyaw^T dMz
    = -C_c q' - K_c q.

    Parameters
    ----------
    params : CarParameters or None
        Car parameters; Table 1 defaults if None.
    speed : float
        V (m/s), > 0.
    geometry : LinearGeometry
        Linearised contact geometry.
    tread : {'lm', 'conical'}
        Tread of Zhai's Hertz constant (``contact.tread``).
    creep_factor : float
        Factor eps on every creep coefficient (1 = linear Kalker), > 0.

    Returns
    -------
    damping, stiffness : numpy.ndarray
        C_c and K_c (42 x 42, not symmetric).

    """
    p = params or CarParameters()
    if not (math.isfinite(speed) and speed > 0.0):
        raise ModelError(f'speed = {speed!r} m/s is invalid; allowed: finite and > 0')
    if not (math.isfinite(creep_factor) and creep_factor > 0.0):
        raise ModelError(f'creep_factor = {creep_factor!r} is invalid; allowed: > 0')
    cm = contact_map(p)
    r0 = p.wheel_radius
    p0 = p.static_wheel_load
    k_h, f11, f22, f23, f33 = _hertz_and_creep(p, tread, creep_factor)
    n11, _, n23, n33 = ct.CREEP_LOAD_EXPONENTS
    s, r, dr, gam, dgam, dh = _per_contact(cm, geometry)
    cos_g, tan_g = np.cos(gam), np.tan(gam)
    xi_x0 = 1.0 - r / r0
    xi_sp0 = -s * np.sin(gam) / r0
    sel = np.zeros((8, N_DOF))                     # S: wheelset lateral DOF of each contact
    sel[np.arange(8), DOF_PER_BODY * np.asarray(WHEELSETS)[cm.wheelset] + 1] = 1.0
    hx, hy, hz, hyaw = cm.hx, cm.hy, cm.hz, cm.hyaw
    v = float(speed)
    # Force rows: dF = D q' + E q, each (8, 42).
    e_z = k_h * (dh * sel - hz)
    d_x = -f11 * hx / v
    e_x = f11 * dr / r0 * sel - n11 * f11 * xi_x0 * e_z / p0
    spin_y = s * cos_g * dgam / r0 * sel            # -(d xi_sp / dq) (displacement part)
    d_y = -f22 * hy / v - f23 * cos_g * hyaw / v
    e_y = (f22 * hyaw + f23 * spin_y - n23 * f23 * xi_sp0 * e_z / p0
           - s * tan_g * e_z - s * p0 * dgam / cos_g ** 2 * sel)
    d_m = f23 * hy / v - f33 * cos_g * hyaw / v
    e_m = -f23 * hyaw - f33 * spin_y - n33 * f33 * xi_sp0 * e_z / p0
    damping = -(hx.T @ d_x + hy.T @ d_y + hyaw.T @ d_m)
    stiffness = -(hx.T @ e_x + hy.T @ e_y + hz.T @ e_z + hyaw.T @ e_m)
    return damping, stiffness


def _hertz_and_creep(p: CarParameters, tread: str,
                     creep_factor: float) -> tuple[float, float, float, float, float]:
    """Return the Hertz tangent k_H and eps (f11, f22, f23, f33) at the static wheel load."""
    r0 = p.wheel_radius
    p0 = p.static_wheel_load
    k_h = float(ct.linearised_stiffness(p0, ct.hertz_constant(r0, tread)))
    ellipse = ct.hertz_ellipse(p0, r0)
    f11, f22, f23, f33 = (creep_factor * float(f)
                          for f in ct.creep_coefficients(ellipse.a, ellipse.b))
    return k_h, f11, f22, f23, f33


def _per_contact(cm: ContactMap, geometry: LinearGeometry) -> tuple[np.ndarray, ...]:
    """Return s, r, r', gamma, gamma', height' of each contact, (8, 1) each."""
    col = np.where(cm.side > 0, 0, 1)    # column 0 = left, 1 = right wheel
    s = cm.side.astype(float)[:, None]
    r, dr = geometry.radius[col][:, None], geometry.radius_slope[col][:, None]
    gam, dgam = geometry.angle[col][:, None], geometry.angle_slope[col][:, None]
    dh = geometry.height_slope[col][:, None]
    return s, r, dr, gam, dgam, dh
