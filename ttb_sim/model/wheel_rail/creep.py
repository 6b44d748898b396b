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
Compute wheel-rail contact forces: Hertz normal contact, Kalker creep, saturation.

Contents (PHYSICS.md section 2):

* Zhai's Hertz law P = (delta / G)^(3/2) for delta > 0, else 0 (loss of
  contact), with G for conical and worn (LM) treads; its tangent stiffness,
  the static compression at a load and the linearised stiffness.
* Hertz elliptic contact (semi-axes, peak pressure, approach) from the
  principal curvatures, with complete elliptic integrals from scipy.
* Kalker's linear creep coefficients f11, f22, f23, f33 from the ellipse and
  Kalker's tabulated C_ij(a/b, nu), and their exact Hertz scaling with load.
* Creepages from the simplified (equivalent-cone) contact geometry of
  PHYSICS.md section 2.3, or from profile rolling radii and contact angles.
* Shen-Hedrick-Elkins saturation of the linear creep forces.

Sign conventions (REP 103 track frame: x forward, y left, z up)
---------------------------------------------------------------
Side s = +1 is the left wheel, s = -1 the right wheel.  A compression
delta > 0 means the wheel and rail overlap.  Creepages are the slip velocity
of the wheel relative to the rail at the contact point divided by V (spin:
relative angular velocity about the contact normal divided by V), and the
linear forces on the wheel are Fx = -f11 xi_x, Fy = -f22 xi_y - f23 xi_sp,
Mz = f23 xi_y - f33 xi_sp (PHYSICS.md section 2.2).  The contact angle
gamma_s > 0 tilts the normal force on wheel s towards the track centre (the
usual coned-tread case, for both wheels).  PHYSICS.md writes the creepages
in Zhai's axes; with y to the left here, the longitudinal creepage of the
left wheel of a wheelset displaced to the left is negative, so the creep
forces steer the wheelset back to the track centre.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipe, ellipk

from ttb_sim.errors import ScenarioError

#: Young's modulus of wheel and rail steel (Pa).
YOUNG_MODULUS = 2.06e11
#: Poisson's ratio of wheel and rail steel (-).
POISSON_RATIO = 0.3
#: Default friction coefficient for saturation (-).
FRICTION_COEFFICIENT = 0.3

#: Tread types with a Zhai contact constant.
TREADS = ('lm', 'conical')

# Kalker (1990), "Three-dimensional elastic bodies in rolling contact", Kluwer,
# Table E.3: C11, C22, C23 of the linear theory for elliptic contact, at
# nu = 0, 0.25, 0.5, for g = min(a/b, b/a) = 0.1 ... 1.0.  Values as transcribed
# in the open-source CONTACT program by E.A.H. Vollebregt and J.J. Kalker
# (https://github.com/eve70a/CONTACT, file src/m_hertz.f90, routine linrol).
# Rows: g = 0.1, 0.2, ..., 1.0; columns: nu = 0, 0.25, 0.5.
_KALKER_G = np.linspace(0.1, 1.0, 10)
_KALKER_NU = np.array([0.0, 0.25, 0.5])
_C11_A_LT_B = np.array([
    [2.51, 3.31, 4.85], [2.59, 3.37, 4.81], [2.68, 3.44, 4.80], [2.78, 3.53, 4.82],
    [2.88, 3.62, 4.83], [2.98, 3.72, 4.91], [3.09, 3.81, 4.97], [3.19, 3.91, 5.05],
    [3.29, 4.01, 5.12], [3.40, 4.12, 5.20]])
_C22_A_LT_B = np.array([
    [2.51, 2.52, 2.53], [2.59, 2.63, 2.66], [2.68, 2.75, 2.81], [2.78, 2.88, 2.98],
    [2.88, 3.01, 3.14], [2.98, 3.14, 3.31], [3.09, 3.28, 3.48], [3.19, 3.41, 3.65],
    [3.29, 3.54, 3.82], [3.40, 3.67, 3.98]])
_C23_A_LT_B = np.array([
    [0.334, 0.473, 0.731], [0.483, 0.603, 0.809], [0.607, 0.715, 0.889],
    [0.720, 0.823, 0.977], [0.827, 0.929, 1.07], [0.930, 1.03, 1.18],
    [1.03, 1.14, 1.29], [1.13, 1.25, 1.40], [1.23, 1.36, 1.51], [1.33, 1.47, 1.63]])
# a > b, rows g = b/a = 0.1 ... 1.0.
_C11_A_GT_B = np.array([
    [10.7, 11.7, 12.9], [6.96, 7.78, 8.82], [5.57, 6.34, 7.34], [4.84, 5.57, 6.57],
    [4.37, 5.10, 6.11], [4.06, 4.78, 5.80], [3.82, 4.54, 5.58], [3.65, 4.36, 5.42],
    [3.51, 4.22, 5.30], [3.40, 4.12, 5.20]])
_C22_A_GT_B = np.array([
    [10.7, 12.8, 16.0], [6.96, 8.14, 9.79], [5.57, 6.40, 7.51], [4.84, 5.48, 6.31],
    [4.37, 4.90, 5.56], [4.06, 4.50, 5.04], [3.82, 4.21, 4.67], [3.65, 3.99, 4.39],
    [3.51, 3.81, 4.16], [3.40, 3.67, 3.98]])
_C23_A_GT_B = np.array([
    [12.2, 14.6, 18.0], [5.72, 6.63, 7.89], [3.79, 4.32, 5.01], [2.88, 3.24, 3.70],
    [2.35, 2.62, 2.96], [2.01, 2.23, 2.50], [1.76, 1.95, 2.18], [1.58, 1.75, 1.94],
    [1.44, 1.59, 1.77], [1.33, 1.47, 1.63]])
# C33 (spin) is not in the transcribed table.  Documented limitation: the
# g = 1, nu = 0.3 value of PHYSICS.md section 2.2 is used for every a/b and nu.
_C33_CONSTANT = 1.18

# One monotone abscissa s for both halves: s = a/b (a <= b), s = 2 - b/a (a > b).
_KALKER_S = np.concatenate([_KALKER_G, 2.0 - _KALKER_G[-2::-1]])


def _both_halves(lt: np.ndarray, gt: np.ndarray) -> np.ndarray:
    return np.concatenate([lt, gt[-2::-1]], axis=0)


_KALKER_TABLE = {
    'c11': _both_halves(_C11_A_LT_B, _C11_A_GT_B),
    'c22': _both_halves(_C22_A_LT_B, _C22_A_GT_B),
    'c23': _both_halves(_C23_A_LT_B, _C23_A_GT_B),
}

#: Range of a/b covered by Kalker's table (-).
KALKER_RATIO_RANGE = (0.1, 10.0)


def _check_positive(name: str, value: ArrayLike) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr) & (arr > 0.0)):
        bad = arr[~(np.isfinite(arr) & (arr > 0.0))].ravel()[0]
        raise ScenarioError(f'{name} = {bad!r} is invalid; allowed: finite and > 0')
    return arr


def hertz_constant(radius: ArrayLike = 0.46, tread: str = 'lm') -> np.ndarray:
    """
    Return Zhai's wheel-rail contact constant G (m/N^(2/3)).

    G = 4.57e-8 R^-0.149 for a conical tread and G = 3.86e-8 R^-0.115 for a
    worn (LM-type) tread, R being the wheel radius in m (PHYSICS.md 2.1).

    Parameters
    ----------
    radius : array_like
        Wheel rolling radius R (m), > 0.
    tread : {'lm', 'conical'}
        Tread type.

    Returns
    -------
    numpy.ndarray
        G (m/N^(2/3)), same shape as ``radius`` (4.22e-8 for LM at 0.46 m).

    Raises
    ------
    ScenarioError
        On a non-positive radius or an unknown tread.

    """
    r = _check_positive('wheel radius', radius)
    if tread == 'lm':
        return 3.86e-8 * r ** -0.115
    if tread == 'conical':
        return 4.57e-8 * r ** -0.149
    raise ScenarioError(f'tread = {tread!r} is unknown; allowed: {", ".join(TREADS)}')


def normal_force(compression: ArrayLike, g_constant: ArrayLike) -> np.ndarray:
    """
    Return the Hertz normal force P = (delta / G)^(3/2), zero where delta <= 0.

    Parameters
    ----------
    compression : array_like
        Elastic compression delta (m), positive when wheel and rail overlap.
    g_constant : array_like
        Contact constant G (m/N^(2/3)), broadcast against ``compression``.

    Returns
    -------
    numpy.ndarray
        Normal force (N) pushing wheel and rail apart; 0 on loss of contact.

    """
    d = np.maximum(np.asarray(compression, dtype=float), 0.0)
    return (d / np.asarray(g_constant, dtype=float)) ** 1.5


def normal_force_derivative(compression: ArrayLike, g_constant: ArrayLike) -> np.ndarray:
    """
    Return the tangent stiffness dP/d(delta) = 1.5 delta^(1/2) / G^(3/2).

    Parameters
    ----------
    compression : array_like
        Elastic compression delta (m).
    g_constant : array_like
        Contact constant G (m/N^(2/3)).

    Returns
    -------
    numpy.ndarray
        Tangent stiffness (N/m); 0 where delta <= 0.

    """
    d = np.maximum(np.asarray(compression, dtype=float), 0.0)
    return 1.5 * np.sqrt(d) / np.asarray(g_constant, dtype=float) ** 1.5


def static_compression(load: ArrayLike, g_constant: ArrayLike) -> np.ndarray:
    """
    Return the compression delta0 = G P0^(2/3) under a static load.

    Parameters
    ----------
    load : array_like
        Static wheel load P0 (N), >= 0.
    g_constant : array_like
        Contact constant G (m/N^(2/3)).

    Returns
    -------
    numpy.ndarray
        delta0 (m); 77 um for P0 = 78.48 kN and the LM tread at R = 0.46 m.

    """
    p = np.asarray(load, dtype=float)
    if np.any(~np.isfinite(p) | (p < 0.0)):
        raise ScenarioError(f'static load = {load!r} N is invalid; allowed: finite and >= 0')
    return np.asarray(g_constant, dtype=float) * p ** (2.0 / 3.0)


def linearised_stiffness(load: ArrayLike, g_constant: ArrayLike) -> np.ndarray:
    """
    Return the linearised Hertz stiffness k_H = 1.5 P0^(1/3) / G at a load.

    Parameters
    ----------
    load : array_like
        Static wheel load P0 (N), > 0.
    g_constant : array_like
        Contact constant G (m/N^(2/3)).

    Returns
    -------
    numpy.ndarray
        k_H (N/m); 1.52e9 N/m for P0 = 78.48 kN and the LM tread at 0.46 m.

    """
    p = _check_positive('static load', load)
    return 1.5 * p ** (1.0 / 3.0) / np.asarray(g_constant, dtype=float)


@dataclass(frozen=True)
class HertzEllipse:
    """
    Hertz solution of an elliptic contact.

    Attributes
    ----------
    a : numpy.ndarray
        Semi-axis along the rolling direction x (m).
    b : numpy.ndarray
        Semi-axis along the lateral direction y (m).
    peak_pressure : numpy.ndarray
        p0 = 3 P / (2 pi a b) (Pa).
    approach : numpy.ndarray
        Elastic approach delta of the two bodies (m).
    g_equivalent : numpy.ndarray
        delta / P^(2/3) (m/N^(2/3)), comparable with Zhai's G.

    """

    a: np.ndarray
    b: np.ndarray
    peak_pressure: np.ndarray
    approach: np.ndarray
    g_equivalent: np.ndarray


def _curvature_ratio(g: np.ndarray) -> np.ndarray:
    """Return B/A (>= 1) of the Hertz ellipse whose minor/major axis ratio is g."""
    m = np.clip(1.0 - g * g, 1e-14, 1.0)
    k, e = ellipk(m), ellipe(m)
    return (e / (g * g) - k) / (k - e)


def hertz_ellipse(load: ArrayLike, rolling_radius: ArrayLike = 0.46,
                  rail_transverse_radius: ArrayLike = 0.30, *,
                  wheel_transverse_radius: ArrayLike = math.inf,
                  rail_longitudinal_radius: ArrayLike = math.inf,
                  young_modulus: float = YOUNG_MODULUS,
                  poisson_ratio: float = POISSON_RATIO) -> HertzEllipse:
    """
    Solve Hertz's elliptic contact between wheel and rail (vectorised).

    The gap is h = A x^2 + B y^2 with A = (1/R_wx + 1/R_rx)/2 and
    B = (1/R_wy + 1/R_ry)/2; radii are positive for convex surfaces and negative
    for concave ones (a worn, hollow wheel tread has a negative transverse
    radius), infinite for flat directions.  With e^2 = 1 - g^2 (g = minor/major
    axis ratio), the ratio of the curvatures fixes g through
    B/A = (E(e)/g^2 - K(e)) / (K(e) - E(e)) (larger over smaller curvature), the
    major semi-axis follows from c^3 = 3 P (K - E) / (2 pi E* e^2 A_min), and
    delta = p0 b_minor K(e) / E*, with E* = E / (2 (1 - nu^2)) for equal
    materials (Johnson, Contact Mechanics, section 3.4).

    Parameters
    ----------
    load : array_like
        Normal load P (N), > 0.
    rolling_radius : array_like
        Wheel rolling radius R_wx (m), > 0.
    rail_transverse_radius : array_like
        Rail head (crown) radius R_ry (m).
    wheel_transverse_radius : array_like
        Wheel profile radius R_wy (m); infinite for a conical tread.
    rail_longitudinal_radius : array_like
        Rail radius along the track R_rx (m); infinite for straight rail.
    young_modulus : float
        E (Pa) of both bodies.
    poisson_ratio : float
        nu (-) of both bodies.

    Returns
    -------
    HertzEllipse
        a, b, p0, approach and G-equivalent, broadcast over the inputs.

    Raises
    ------
    ScenarioError
        If a load is not positive or the combined curvatures are not positive.

    """
    p = _check_positive('normal load', load)
    curv_x = 1.0 / np.asarray(rolling_radius, dtype=float) \
        + 1.0 / np.asarray(rail_longitudinal_radius, dtype=float)
    curv_y = 1.0 / np.asarray(wheel_transverse_radius, dtype=float) \
        + 1.0 / np.asarray(rail_transverse_radius, dtype=float)
    a_cur, b_cur = np.broadcast_arrays(0.5 * curv_x, 0.5 * curv_y)
    if np.any(~(a_cur > 0.0)) or np.any(~(b_cur > 0.0)):
        raise ScenarioError('wheel-rail curvatures are invalid: the combined curvature along '
                            'x and y must be > 0 (radii: positive convex, negative concave)')
    p, a_cur, b_cur = np.broadcast_arrays(p, a_cur, b_cur)
    small = np.minimum(a_cur, b_cur)
    ratio = np.maximum(a_cur, b_cur) / small
    # Vectorised bisection on log(g) for _curvature_ratio(g) = ratio (decreasing in g).
    lo = np.full(ratio.shape, math.log(1e-6))
    hi = np.zeros(ratio.shape)
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        too_round = _curvature_ratio(np.exp(mid)) < ratio
        hi = np.where(too_round, mid, hi)
        lo = np.where(too_round, lo, mid)
    g = np.where(ratio <= 1.0 + 1e-12, 1.0, np.exp(0.5 * (lo + hi)))
    m = 1.0 - g * g
    k, e = ellipk(m), ellipe(m)
    e_star = young_modulus / (2.0 * (1.0 - poisson_ratio ** 2))
    # (K - E) / e^2 -> pi / 4 for a circle.
    k_minus_e_over_m = np.where(m > 1e-10, (k - e) / np.where(m > 1e-10, m, 1.0),
                                math.pi / 4.0)
    major = (3.0 * p * k_minus_e_over_m / (2.0 * math.pi * e_star * small)) ** (1.0 / 3.0)
    minor = g * major
    p0 = 3.0 * p / (2.0 * math.pi * major * minor)
    approach = p0 * minor * k / e_star
    along_x_is_major = a_cur <= b_cur
    a = np.where(along_x_is_major, major, minor)
    b = np.where(along_x_is_major, minor, major)
    return HertzEllipse(a=a, b=b, peak_pressure=p0, approach=approach,
                        g_equivalent=approach / p ** (2.0 / 3.0))


def kalker_coefficients(a_over_b: ArrayLike, poisson_ratio: float = POISSON_RATIO, *,
                        clip: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                     np.ndarray]:
    """
    Return Kalker's linear-theory coefficients C11, C22, C23, C33.

    C11, C22 and C23 are interpolated linearly in Kalker's Table E.3 (see the
    source note in this module): in g = a/b for a <= b and in g = b/a for
    a > b (the table's own grids), then linearly in nu between 0, 0.25, 0.5.
    C33 is not in the sourced table: the g = 1, nu = 0.3 value 1.18 of
    PHYSICS.md is returned for all inputs (documented limitation; spin moments
    are a minor term in vehicle dynamics).

    Parameters
    ----------
    a_over_b : array_like
        Ratio of the semi-axis along the rolling direction to the lateral one.
    poisson_ratio : float
        nu, 0 <= nu <= 0.5.
    clip : bool
        If True, clamp a/b to the table range 0.1 .. 10 instead of raising.

    Returns
    -------
    tuple of numpy.ndarray
        (C11, C22, C23, C33), dimensionless, shaped like ``a_over_b``.

    Raises
    ------
    ScenarioError
        If a/b is outside 0.1 .. 10 (and ``clip`` is False) or nu outside 0 .. 0.5.

    """
    r = np.asarray(a_over_b, dtype=float)
    lo, hi = KALKER_RATIO_RANGE
    if not 0.0 <= poisson_ratio <= 0.5:
        raise ScenarioError(f'poisson_ratio = {poisson_ratio!r} is invalid; allowed: 0..0.5')
    if clip:
        r = np.clip(r, lo, hi)
    elif np.any(~((r >= lo * (1 - 1e-12)) & (r <= hi * (1 + 1e-12)))):
        bad = r[~((r >= lo * (1 - 1e-12)) & (r <= hi * (1 + 1e-12)))].ravel()[0]
        raise ScenarioError(f'contact ellipse a/b = {bad!r} is outside the Kalker table; '
                            f'allowed: {lo}..{hi}')
    s = np.where(r <= 1.0, r, 2.0 - 1.0 / np.where(r > 0.0, r, 1.0))
    out = []
    for key in ('c11', 'c22', 'c23'):
        table = _KALKER_TABLE[key]
        per_nu = [np.interp(s, _KALKER_S, table[:, j]) for j in range(3)]
        out.append(_lerp_nu(per_nu, poisson_ratio))
    c33 = np.full(r.shape, _C33_CONSTANT)
    return out[0], out[1], out[2], c33


def _lerp_nu(per_nu: list[np.ndarray], nu: float) -> np.ndarray:
    if nu <= 0.25:
        w = nu / 0.25
        return (1.0 - w) * per_nu[0] + w * per_nu[1]
    w = (nu - 0.25) / 0.25
    return (1.0 - w) * per_nu[1] + w * per_nu[2]


def creep_coefficients(a: ArrayLike, b: ArrayLike, *, young_modulus: float = YOUNG_MODULUS,
                       poisson_ratio: float = POISSON_RATIO,
                       clip: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray,
                                                    np.ndarray]:
    """
    Return Kalker's linear creep coefficients of an elliptic contact.

    f11 = G a b C11, f22 = G a b C22, f23 = G (a b)^1.5 C23, f33 = G (a b)^2 C33
    with the shear modulus G = E / (2 (1 + nu)).

    Parameters
    ----------
    a, b : array_like
        Semi-axes along x (rolling) and y (m), > 0.
    young_modulus : float
        E (Pa).
    poisson_ratio : float
        nu (-).
    clip : bool
        Passed to :func:`kalker_coefficients`.

    Returns
    -------
    tuple of numpy.ndarray
        f11 (N), f22 (N), f23 (N m), f33 (N m^2).

    """
    a = _check_positive('contact semi-axis a', a)
    b = _check_positive('contact semi-axis b', b)
    c11, c22, c23, c33 = kalker_coefficients(a / b, poisson_ratio, clip=clip)
    shear = young_modulus / (2.0 * (1.0 + poisson_ratio))
    ab = a * b
    return shear * ab * c11, shear * ab * c22, shear * ab ** 1.5 * c23, shear * ab ** 2 * c33


#: Exponents of the load scaling of f11, f22, f23, f33 at fixed curvatures.
CREEP_LOAD_EXPONENTS = (2.0 / 3.0, 2.0 / 3.0, 1.0, 4.0 / 3.0)


def scale_creep_coefficients(coefficients: tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike],
                             reference_load: float, load: ArrayLike) -> tuple[
                                 np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Scale creep coefficients computed at one normal load to other loads.

    For fixed curvatures the Hertz semi-axes grow as P^(1/3) and a/b does not
    change, so f11, f22 scale as (P/P0)^(2/3), f23 as P/P0 and f33 as
    (P/P0)^(4/3) exactly.  Loads <= 0 (no contact) give zero coefficients.

    Parameters
    ----------
    coefficients : tuple
        (f11, f22, f23, f33) at ``reference_load``.
    reference_load : float
        Load P0 (N) of ``coefficients``, > 0.
    load : array_like
        Normal loads P (N).

    Returns
    -------
    tuple of numpy.ndarray
        (f11, f22, f23, f33) at ``load``.

    """
    _check_positive('reference load', reference_load)
    ratio = np.maximum(np.asarray(load, dtype=float), 0.0) / reference_load
    f11, f22, f23, f33 = (np.asarray(c, dtype=float) for c in coefficients)
    e11, e22, e23, e33 = CREEP_LOAD_EXPONENTS
    return f11 * ratio ** e11, f22 * ratio ** e22, f23 * ratio ** e23, f33 * ratio ** e33


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
        raise ScenarioError(f'conicity = {conicity!r} is invalid; allowed: 0..1')
    _check_positive('nominal rolling radius', nominal_radius)
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
        raise ScenarioError(f'speed = {speed!r} m/s is invalid; allowed: finite and > 0')
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


def linear_creep_forces(xi_x: ArrayLike, xi_y: ArrayLike, xi_sp: ArrayLike,
                        coefficients: tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike]
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return Kalker's linear creep forces on the wheel.

    Fx = -f11 xi_x, Fy = -f22 xi_y - f23 xi_sp, Mz = f23 xi_y - f33 xi_sp.

    Parameters
    ----------
    xi_x, xi_y : array_like
        Longitudinal and lateral creepage (-).
    xi_sp : array_like
        Spin creepage (1/m).
    coefficients : tuple
        (f11, f22, f23, f33) from :func:`creep_coefficients`.

    Returns
    -------
    fx, fy, mz : numpy.ndarray
        Forces (N) and spin moment (N m) on the wheel in the contact plane.

    """
    f11, f22, f23, f33 = (np.asarray(c, dtype=float) for c in coefficients)
    xi_x, xi_y, xi_sp = (np.asarray(v, dtype=float) for v in (xi_x, xi_y, xi_sp))
    return -f11 * xi_x, -f22 * xi_y - f23 * xi_sp, f23 * xi_y - f33 * xi_sp


def she_ratio(beta: ArrayLike) -> np.ndarray:
    """
    Return the Shen-Hedrick-Elkins saturated-to-available force ratio.

    F'/(mu N) = beta - beta^2/3 + beta^3/27 for beta <= 3, else 1, where
    beta = F / (mu N) is the linear-theory force over the friction limit.

    Parameters
    ----------
    beta : array_like
        Non-negative normalised linear creep force.

    Returns
    -------
    numpy.ndarray
        Saturated normalised force in 0 .. 1, monotonic in beta.

    """
    x = np.maximum(np.asarray(beta, dtype=float), 0.0)
    return np.where(x <= 3.0, x - x * x / 3.0 + x ** 3 / 27.0, 1.0)


def she_factor_derivative(beta: ArrayLike) -> np.ndarray:
    """
    Return d epsilon / d beta of the Shen-Hedrick-Elkins reduction factor.

    epsilon = she_ratio(beta) / beta = 1 - beta/3 + beta^2/27 for beta <= 3 and
    1/beta beyond, so the derivative is -1/3 + 2 beta/27, resp. -1/beta^2
    (continuous at beta = 3, where both are -1/9).  Used for the Jacobian of
    the saturated creep forces.

    Parameters
    ----------
    beta : array_like
        Non-negative normalised linear creep force.

    Returns
    -------
    numpy.ndarray
        The derivative (-), between -1/3 and 0.

    """
    x = np.maximum(np.asarray(beta, dtype=float), 0.0)
    return np.where(x <= 3.0, -1.0 / 3.0 + 2.0 * x / 27.0, -1.0 / np.maximum(x, 3.0) ** 2)


def she_factor_gradient(fx: ArrayLike, fy: ArrayLike, normal: ArrayLike,
                        friction: float = FRICTION_COEFFICIENT
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the partial derivatives of the Shen-Hedrick-Elkins factor epsilon.

    epsilon depends on beta = |(Fx, Fy)| / (mu N) only, so
    d eps / dFx = eps'(beta) Fx / (|F| mu N), likewise for Fy, and
    d eps / dN = -eps'(beta) beta / N (:func:`she_factor_derivative`).  Where
    N <= 0 or F = 0 the derivatives are 0 (epsilon is constant there).

    Parameters
    ----------
    fx, fy : array_like
        Linear-theory creep forces (N).
    normal : array_like
        Normal contact force N (N).
    friction : float
        Friction coefficient mu.

    Returns
    -------
    d_fx, d_fy, d_normal : numpy.ndarray
        Derivatives of epsilon (1/N).

    """
    fx, fy, n = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (fx, fy, normal)))
    f = np.hypot(fx, fy)
    limit = friction * n
    active = (limit > 0.0) & (f > 0.0)
    f_safe = np.where(active, f, 1.0)
    limit_safe = np.where(active, limit, 1.0)
    beta = f / limit_safe
    slope = np.where(active, she_factor_derivative(beta), 0.0)
    per_force = slope / (f_safe * limit_safe)
    return per_force * fx, per_force * fy, -slope * beta / np.where(active, n, 1.0)


def she_saturation(fx: ArrayLike, fy: ArrayLike, mz: ArrayLike, normal: ArrayLike,
                   friction: float = FRICTION_COEFFICIENT) -> tuple[np.ndarray, np.ndarray,
                                                                    np.ndarray, np.ndarray]:
    """
    Saturate linear creep forces with the Shen-Hedrick-Elkins law (vectorised).

    F = sqrt(Fx^2 + Fy^2), beta = F / (mu N), F' = mu N she_ratio(beta); Fx, Fy
    and Mz are scaled by epsilon = F' / F (epsilon = 1 where F = 0).  Where
    N <= 0 (no contact) all outputs are 0.

    Parameters
    ----------
    fx, fy : array_like
        Linear-theory creep forces (N).
    mz : array_like
        Linear-theory spin moment (N m).
    normal : array_like
        Normal contact force N (N).
    friction : float
        Friction coefficient mu, 0 < mu <= 2 (default 0.3).

    Returns
    -------
    fx, fy, mz, epsilon : numpy.ndarray
        Saturated forces, moment and the reduction factor (-).

    """
    if not (math.isfinite(friction) and 0.0 < friction <= 2.0):
        raise ScenarioError(f'friction = {friction!r} is invalid; allowed: 0 < mu <= 2')
    fx, fy, mz, n = np.broadcast_arrays(*(np.asarray(v, dtype=float)
                                          for v in (fx, fy, mz, normal)))
    f = np.hypot(fx, fy)
    limit = friction * np.maximum(n, 0.0)
    in_contact = limit > 0.0
    beta = np.where(in_contact, f / np.where(in_contact, limit, 1.0), 0.0)
    saturated = limit * she_ratio(beta)
    eps = np.where(f > 0.0, saturated / np.where(f > 0.0, f, 1.0), 1.0)
    eps = np.where(in_contact, eps, 0.0)
    return fx * eps, fy * eps, mz * eps, eps
