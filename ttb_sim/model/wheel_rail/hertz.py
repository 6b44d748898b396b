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
Hertz normal contact between wheel and rail (PHYSICS.md section 2.1).

Contents:

* Zhai's Hertz law P = (delta / G)^(3/2) for delta > 0, else 0 (loss of
  contact), with G for conical and worn (LM) treads; its tangent stiffness,
  the static compression at a load and the linearised stiffness.
* Hertz elliptic contact (semi-axes, peak pressure, approach) from the
  principal curvatures, with complete elliptic integrals from scipy.
* The elastic constants of wheel and rail steel, shared with :mod:`.creep`.

A compression delta > 0 means the wheel and rail overlap.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.special import ellipe, ellipk

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail._checks import check_positive

__all__ = [
    'HertzEllipse',
    'POISSON_RATIO',
    'TREADS',
    'YOUNG_MODULUS',
    'hertz_constant',
    'hertz_ellipse',
    'linearised_stiffness',
    'normal_force',
    'normal_force_derivative',
    'static_compression',
]

#: Young's modulus of wheel and rail steel (Pa).
YOUNG_MODULUS = 2.06e11
#: Poisson's ratio of wheel and rail steel (-).
POISSON_RATIO = 0.3

#: Tread types with a Zhai contact constant.
TREADS = ('lm', 'conical')


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
    ModelError
        On a non-positive radius or an unknown tread.

    """
    r = check_positive('wheel radius', radius)
    if tread == 'lm':
        return 3.86e-8 * r ** -0.115
    if tread == 'conical':
        return 4.57e-8 * r ** -0.149
    raise ModelError(f'tread = {tread!r} is unknown; allowed: {", ".join(TREADS)}')


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
        raise ModelError(f'static load = {load!r} N is invalid; allowed: finite and >= 0')
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
    p = check_positive('static load', load)
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


def _axis_ratio(ratio: np.ndarray) -> np.ndarray:
    """Return the minor/major axis ratio g of the ellipse whose B/A is ``ratio`` (>= 1)."""
    # Vectorised bisection on log(g) for _curvature_ratio(g) = ratio (decreasing in g).
    lo = np.full(ratio.shape, math.log(1e-6))
    hi = np.zeros(ratio.shape)
    for _ in range(64):
        mid = 0.5 * (lo + hi)
        too_round = _curvature_ratio(np.exp(mid)) < ratio
        hi = np.where(too_round, mid, hi)
        lo = np.where(too_round, lo, mid)
    return np.where(ratio <= 1.0 + 1e-12, 1.0, np.exp(0.5 * (lo + hi)))


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
    ModelError
        If a load is not positive or the combined curvatures are not positive.

    """
    p = check_positive('normal load', load)
    curv_x = 1.0 / np.asarray(rolling_radius, dtype=float) \
        + 1.0 / np.asarray(rail_longitudinal_radius, dtype=float)
    curv_y = 1.0 / np.asarray(wheel_transverse_radius, dtype=float) \
        + 1.0 / np.asarray(rail_transverse_radius, dtype=float)
    a_cur, b_cur = np.broadcast_arrays(0.5 * curv_x, 0.5 * curv_y)
    if np.any(~(a_cur > 0.0)) or np.any(~(b_cur > 0.0)):
        raise ModelError('wheel-rail curvatures are invalid: the combined curvature along '
                         'x and y must be > 0 (radii: positive convex, negative concave)')
    p, a_cur, b_cur = np.broadcast_arrays(p, a_cur, b_cur)
    small = np.minimum(a_cur, b_cur)
    g = _axis_ratio(np.maximum(a_cur, b_cur) / small)
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
