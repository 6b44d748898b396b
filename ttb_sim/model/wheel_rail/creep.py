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
Tangential wheel-rail contact: Kalker's linear creep theory and its saturation.

Contents (PHYSICS.md section 2.2):

* Kalker's linear creep coefficients f11, f22, f23, f33 from the contact
  ellipse and Kalker's tabulated C_ij(a/b, nu), and their exact Hertz scaling
  with load (:data:`CREEP_LOAD_EXPONENTS`).
* Kalker's linear creep forces from the creepages of :mod:`.geometry`.
* Shen-Hedrick-Elkins saturation of the linear creep forces, with the
  derivatives of its reduction factor for Jacobians.

Sign conventions (REP 103 track frame: x forward, y left, z up): the linear
forces on the wheel are Fx = -f11 xi_x, Fy = -f22 xi_y - f23 xi_sp,
Mz = f23 xi_y - f33 xi_sp (PHYSICS.md section 2.2), with the creepages
defined in :mod:`.geometry`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail._checks import check_positive
from ttb_sim.model.wheel_rail.hertz import POISSON_RATIO, YOUNG_MODULUS

__all__ = [
    'CREEP_LOAD_EXPONENTS',
    'FRICTION_COEFFICIENT',
    'KALKER_RATIO_RANGE',
    'creep_coefficients',
    'kalker_coefficients',
    'linear_creep_forces',
    'scale_creep_coefficients',
    'scaled_creep_coefficients',
    'she_factor_derivative',
    'she_factor_gradient',
    'she_ratio',
    'she_saturation',
]

#: Default friction coefficient for saturation (-).
FRICTION_COEFFICIENT = 0.3

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
    ModelError
        If a/b is outside 0.1 .. 10 (and ``clip`` is False) or nu outside 0 .. 0.5.

    """
    r = np.asarray(a_over_b, dtype=float)
    lo, hi = KALKER_RATIO_RANGE
    if not 0.0 <= poisson_ratio <= 0.5:
        raise ModelError(f'poisson_ratio = {poisson_ratio!r} is invalid; allowed: 0..0.5')
    if clip:
        r = np.clip(r, lo, hi)
    elif np.any(~((r >= lo * (1 - 1e-12)) & (r <= hi * (1 + 1e-12)))):
        bad = r[~((r >= lo * (1 - 1e-12)) & (r <= hi * (1 + 1e-12)))].ravel()[0]
        raise ModelError(f'contact ellipse a/b = {bad!r} is outside the Kalker table; '
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
    a = check_positive('contact semi-axis a', a)
    b = check_positive('contact semi-axis b', b)
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
    check_positive('reference load', reference_load)
    return scaled_creep_coefficients(coefficients, reference_load, load)


def scaled_creep_coefficients(coefficients: tuple[ArrayLike, ArrayLike, ArrayLike, ArrayLike],
                              reference_load: float, load: ArrayLike) -> tuple[
                                  np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Return :func:`scale_creep_coefficients` without checking ``reference_load``.

    For a time step whose reference load was checked once, before the run.
    """
    ratio = np.maximum(np.asarray(load, dtype=float), 0.0) / reference_load
    f11, f22, f23, f33 = (np.asarray(c, dtype=float) for c in coefficients)
    e11, e22, e23, e33 = CREEP_LOAD_EXPONENTS
    return f11 * ratio ** e11, f22 * ratio ** e22, f23 * ratio ** e23, f33 * ratio ** e33


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
        raise ModelError(f'friction = {friction!r} is invalid; allowed: 0 < mu <= 2')
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
