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
Closed-form track references for validation cases V2 and V6.

V2 (PHYSICS.md 9.2): an infinite Euler-Bernoulli beam (bending stiffness EI,
mass per length m) on a Winkler foundation (stiffness k per length, optional
viscous damping c per length) under a constant point load P moving at speed v.

V6 (PHYSICS.md 3.1, 4): the P2-type resonance of a half wheelset on the rail,
the rail smeared into a Winkler beam on its fasteners over a rigid slab, in
series with the linearised Hertz spring.

Conventions used throughout: SI units (N, m, s, kg); forces, deflections and
receptances positive downward; harmonic quantities are complex amplitudes of
exp(i omega t) with omega >= 0 in rad/s. The module shares no code with the
finite-element pipeline it checks.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

# PHYSICS.md section 4 ([P] Tables 2 and 4) and section 3.1 ([P] Table 1), SI units.
# Bending stiffness of the CHN60 rail about its horizontal axis (N m^2).
RAIL_EI = 2.059e11 * 3.217e-5
# Rail mass per length (kg/m).
RAIL_MASS = 60.64
# Vertical stiffness of one fastener (N/m).
FASTENER_STIFFNESS = 5e7
# Vertical damping of one fastener (N s/m).
FASTENER_DAMPING = 3.6e4
# Fastener spacing (m).
FASTENER_SPACING = 0.63
# Unsprung mass per wheel, M_w / 2 (kg).
HALF_WHEELSET_MASS = 1200.0
# Linearised Hertz stiffness at the static wheel load, LM tread (N/m).
HERTZ_STIFFNESS = 1.52e9
# Fastener stiffness smeared along the rail (N/m^2).
WINKLER_STIFFNESS = FASTENER_STIFFNESS / FASTENER_SPACING
# Fastener damping smeared along the rail (N s/m^2).
WINKLER_DAMPING = FASTENER_DAMPING / FASTENER_SPACING


def winkler_beta(ei: float, k: float) -> float:
    """
    Return the Winkler wavenumber beta = (k / 4EI)^(1/4) (1/m).

    Parameters
    ----------
    ei : float
        Bending stiffness EI (N m^2).
    k : float
        Foundation stiffness per length (N/m^2).

    Returns
    -------
    float
        beta (1/m).

    """
    return (k / (4.0 * ei)) ** 0.25


def critical_speed(ei: float, m: float, k: float) -> float:
    """
    Return the critical speed v_cr = (4 k EI / m^2)^(1/4) of the undamped beam (m/s).

    Parameters
    ----------
    ei : float
        Bending stiffness EI (N m^2).
    m : float
        Beam mass per length (kg/m).
    k : float
        Foundation stiffness per length (N/m^2).

    Returns
    -------
    float
        The lowest phase speed of free bending waves on the foundation (m/s).

    """
    return (4.0 * k * ei / m**2) ** 0.25


def static_peak_deflection(p: float, ei: float, k: float) -> float:
    """
    Return the static deflection under a point load, P beta / (2k) (m, downward).

    Parameters
    ----------
    p : float
        Point load (N, downward positive).
    ei : float
        Bending stiffness EI (N m^2).
    k : float
        Foundation stiffness per length (N/m^2).

    Returns
    -------
    float
        Deflection under the load (m, downward positive); it equals P / (8 EI beta^3).

    """
    return p * winkler_beta(ei, k) / (2.0 * k)


def _moving_roots(ei: float, m: float, k: float, v: float, c: float) -> np.ndarray:
    """
    Return the roots s = r / beta of the scaled characteristic quartic.

    EI r^4 + m v^2 r^2 - c v r + k = 0 divided by EI beta^4 reads
    s^4 + 4 a^2 s^2 - (c v / (EI beta^3)) s + 4 = 0 with a = v / v_cr.
    """
    if v < 0.0 or c < 0.0:
        raise ValueError('speed and damping must be non-negative')
    beta = winkler_beta(ei, k)
    alpha = v / critical_speed(ei, m, k)
    if c == 0.0 and alpha >= 1.0:
        raise ValueError('an undamped beam has no bounded steady state at or above v_cr '
                         f'(v / v_cr = {alpha:.4g}); give c > 0')
    s = np.roots([1.0, 0.0, 4.0 * alpha**2, -c * v / (ei * beta**3), 4.0])
    if np.count_nonzero(s.real < 0.0) != 2 or np.any(s.real == 0.0):
        raise ValueError('characteristic roots are not split two by two between the '
                         'half-planes; the parameters are outside the closed form')
    return s


def moving_load_deflection(xi: np.ndarray, p: float, ei: float, m: float, k: float,
                           v: float, c: float = 0.0) -> np.ndarray:
    """
    Return the steady-state deflection under a constant moving point load (m, downward).

    The beam obeys EI w'''' + m w_tt + c w_t + k w = P delta(x - v t), with w and
    P positive downward and the load moving towards +x. In the moving frame
    xi = x - v t (xi > 0 ahead of the load) the steady state solves
    EI w'''' + m v^2 w'' - c v w' + k w = P delta(xi), whose characteristic
    quartic Q(r) = EI r^4 + m v^2 r^2 - c v r + k has two roots in each
    half-plane. Closing the Fourier inversion
    w = (P / 2 pi) int exp(i kappa xi) / Q(i kappa) d kappa by residues gives

        w(xi) =  P sum_{Re r_j < 0} exp(r_j xi) / Q'(r_j)   for xi >= 0,
        w(xi) = -P sum_{Re r_j > 0} exp(r_j xi) / Q'(r_j)   for xi < 0.

    Valid for 0 <= v < v_cr when c = 0, and for any v >= 0 when c > 0 (no root
    then lies on the imaginary axis).

    Parameters
    ----------
    xi : array_like
        Positions relative to the load, x - v t (m).
    p : float
        Load (N, downward positive).
    ei : float
        Bending stiffness EI (N m^2).
    m : float
        Beam mass per length (kg/m).
    k : float
        Foundation stiffness per length (N/m^2).
    v : float
        Load speed (m/s), v >= 0.
    c : float
        Viscous foundation damping per length (N s/m^2), c >= 0.

    Returns
    -------
    numpy.ndarray
        Deflection w(xi) (m, downward positive), same shape as ``xi``.

    Raises
    ------
    ValueError
        For negative v or c, or c = 0 with v >= v_cr.

    """
    xi = np.asarray(xi, dtype=float)
    beta = winkler_beta(ei, k)
    s = _moving_roots(ei, m, k, v, c)
    alpha = v / critical_speed(ei, m, k)
    # Q'(r) = EI beta^3 q'(s), q'(s) = 4 s^3 + 8 a^2 s - c v / (EI beta^3).
    dq = 4.0 * s**3 + 8.0 * alpha**2 * s - c * v / (ei * beta**3)
    amp = p / (ei * beta**3) / dq
    left = s.real < 0.0
    bx = beta * xi[..., None]
    ahead = np.where(left, amp, 0.0) * np.exp(np.where(left, s, 0.0) * np.maximum(bx, 0.0))
    behind = np.where(left, 0.0, amp) * np.exp(np.where(left, 0.0, s) * np.minimum(bx, 0.0))
    w = np.where(xi >= 0.0, ahead.sum(axis=-1), -behind.sum(axis=-1))
    return w.real


def moving_load_peak(p: float, ei: float, m: float, k: float, v: float,
                     c: float = 0.0) -> tuple[float, float]:
    """
    Return the largest downward steady-state deflection and where it occurs.

    The maximum is bracketed on a dense grid of xi (spanning the decay length of
    the slowest-decaying root) and refined with a bounded scalar search.

    Parameters
    ----------
    p : float
        Load (N, downward positive).
    ei : float
        Bending stiffness EI (N m^2).
    m : float
        Beam mass per length (kg/m).
    k : float
        Foundation stiffness per length (N/m^2).
    v : float
        Load speed (m/s), as in :func:`moving_load_deflection`.
    c : float
        Viscous foundation damping per length (N s/m^2).

    Returns
    -------
    (float, float)
        Peak deflection (m, downward positive) and its position xi = x - v t (m);
        xi < 0 is behind the load.

    """
    beta = winkler_beta(ei, k)
    s = _moving_roots(ei, m, k, v, c)
    decay = float(np.min(np.abs(s.real)))
    wave = float(np.max(np.abs(s.imag)))
    half = min(2.0 * math.pi + 6.0 / decay, 400.0) / beta
    n = int(min(max(2001, 40.0 * 2.0 * half * beta * max(wave, 1.0) / (2 * math.pi)), 200001))
    grid = np.linspace(-half, half, n)
    w = moving_load_deflection(grid, p, ei, m, k, v, c)
    i = int(np.argmax(w))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, n - 1)]
    res = minimize_scalar(lambda x: -float(moving_load_deflection(x, p, ei, m, k, v, c)),
                          bounds=(lo, hi), method='bounded',
                          options={'xatol': 1e-10 / beta})
    if -res.fun >= w[i]:
        return float(-res.fun), float(res.x)
    return float(w[i]), float(grid[i])


def infinite_beam_receptance(omega: np.ndarray, ei: float, m: float, k: float,
                             c: float = 0.0) -> np.ndarray:
    """
    Return the point receptance of an infinite Winkler beam under a harmonic load (m/N).

    For a load F exp(i omega t) the beam obeys EI w'''' + k* w = F delta(x) with
    the dynamic foundation stiffness k* = k + i omega c - m omega^2. The free
    wavenumbers are the four roots of EI kappa^4 = -k*, kappa = lambda (+-1 +- i)
    with lambda = (k* / 4EI)^(1/4) on the principal branch (0 <= arg lambda <= pi/4).
    Closing the Fourier inversion in the upper half-plane picks up the two roots
    kappa_1 = (1 + i) lambda and kappa_2 = (i - 1) lambda, so

        alpha(omega) = (i / 4EI) (kappa_1^-3 + kappa_2^-3) = 1 / (8 EI lambda^3).

    Above the cut-on frequency sqrt(k / m) with c = 0 the propagating root sits
    on the real axis; the principal branch is the c -> 0+ limit (outgoing waves).
    At omega = 0 the receptance is 1 / (8 EI beta^3) = beta / (2k).

    Parameters
    ----------
    omega : array_like
        Circular frequency (rad/s), omega >= 0.
    ei : float
        Bending stiffness EI (N m^2).
    m : float
        Beam mass per length (kg/m).
    k : float
        Foundation stiffness per length (N/m^2).
    c : float
        Viscous foundation damping per length (N s/m^2).

    Returns
    -------
    numpy.ndarray
        Complex receptance (displacement per force, both downward positive, m/N).

    """
    omega = np.asarray(omega, dtype=float)
    if np.any(omega < 0.0):
        raise ValueError('omega must be non-negative')
    k_dyn = (k - m * omega**2) + 1j * (omega * c)
    lam = (k_dyn / (4.0 * ei)) ** 0.25
    kappa_1 = (1.0 + 1.0j) * lam
    kappa_2 = (-1.0 + 1.0j) * lam
    return 1j / (4.0 * ei) * (kappa_1**-3 + kappa_2**-3)


def contact_force_frf(omega: np.ndarray, wheel_mass: float, k_hertz: float,
                      rail_receptance: np.ndarray) -> np.ndarray:
    """
    Return the dynamic contact force per unit roughness amplitude (N/m).

    Displacements and forces are downward positive. The roughness r is the
    downward offset of the rail running surface under the wheel (a dip is r > 0;
    PHYSICS.md 2.1 writes the compression as Z_w - Z_r - z_irr), so the Hertz
    compression is u_w - u_r - r and the contact force F = k_H (u_w - u_r - r)
    pushes the rail down and the wheel up. With the wheel receptance
    alpha_w = -1 / (M omega^2), the contact receptance alpha_H = 1 / k_H and the
    rail receptance alpha_r,

        F / r = -1 / (alpha_w + alpha_H + alpha_r)
              = M omega^2 / (1 - M omega^2 (alpha_H + alpha_r)).

    For a roughness bump (height positive upward) the sign flips. The second
    form is used, so omega = 0 gives 0 without a division by zero; as
    omega -> infinity F / r -> -k_H.

    Parameters
    ----------
    omega : array_like
        Circular frequency (rad/s).
    wheel_mass : float
        Unsprung mass carried by the contact (kg).
    k_hertz : float
        Linearised Hertz stiffness (N/m).
    rail_receptance : array_like
        Complex rail point receptance at ``omega`` (m/N), downward positive.

    Returns
    -------
    numpy.ndarray
        Complex F / r (N/m).

    """
    omega = np.asarray(omega, dtype=float)
    mw2 = wheel_mass * omega**2
    return mw2 / (1.0 - mw2 * (1.0 / k_hertz + np.asarray(rail_receptance)))


def p2_resonance_frequency(wheel_mass: float = HALF_WHEELSET_MASS, ei: float = RAIL_EI,
                           m: float = RAIL_MASS, k: float = WINKLER_STIFFNESS,
                           c: float = WINKLER_DAMPING, k_hertz: float = HERTZ_STIFFNESS,
                           band: tuple[float, float] = (1.0, 200.0),
                           n_grid: int = 4000) -> float:
    """
    Return the frequency of the peak of |F / r| for a wheel on an infinite Winkler rail (Hz).

    The rail receptance is :func:`infinite_beam_receptance` (rail mass and
    foundation damping included) and the contact force follows
    :func:`contact_force_frf`. The peak is bracketed on a logarithmic grid over
    ``band`` and refined with a bounded scalar search. The default band stops
    below the rail cut-on (about 182 Hz for the defaults) and the P1 range.

    Parameters
    ----------
    wheel_mass : float
        Unsprung mass per wheel (kg).
    ei : float
        Rail bending stiffness (N m^2).
    m : float
        Rail mass per length (kg/m).
    k : float
        Smeared fastener stiffness (N/m^2).
    c : float
        Smeared fastener damping (N s/m^2).
    k_hertz : float
        Linearised Hertz stiffness (N/m).
    band : (float, float)
        Search band (Hz).
    n_grid : int
        Number of grid frequencies used to bracket the peak.

    Returns
    -------
    float
        Frequency of the maximum of |F / r| in ``band`` (Hz).

    """
    def magnitude(f: np.ndarray) -> np.ndarray:
        om = 2.0 * math.pi * np.asarray(f, dtype=float)
        return np.abs(contact_force_frf(om, wheel_mass, k_hertz,
                                        infinite_beam_receptance(om, ei, m, k, c)))

    f = np.geomspace(band[0], band[1], n_grid)
    i = int(np.argmax(magnitude(f)))
    lo, hi = f[max(i - 1, 0)], f[min(i + 1, n_grid - 1)]
    res = minimize_scalar(lambda x: -float(magnitude(x)), bounds=(lo, hi), method='bounded',
                          options={'xatol': 1e-9 * hi})
    return float(res.x)


def p2_frequency_estimate(wheel_mass: float = HALF_WHEELSET_MASS, ei: float = RAIL_EI,
                          k: float = WINKLER_STIFFNESS,
                          k_hertz: float = HERTZ_STIFFNESS) -> float:
    """
    Return the simplified P2 estimate of PHYSICS.md 3.1 (Hz).

    The wheel mass sits on the static point stiffness of the rail,
    k_eff = 2k / beta = 8 EI beta^3, in series with k_H:
    f = sqrt(k_s / M) / (2 pi), 1 / k_s = 1 / k_eff + 1 / k_H. Rail inertia and
    fastener damping are ignored, so it lies above :func:`p2_resonance_frequency`.

    Parameters
    ----------
    wheel_mass : float
        Unsprung mass per wheel (kg).
    ei : float
        Rail bending stiffness (N m^2).
    k : float
        Smeared fastener stiffness (N/m^2).
    k_hertz : float
        Linearised Hertz stiffness (N/m).

    Returns
    -------
    float
        Natural frequency (Hz).

    """
    k_eff = 2.0 * k / winkler_beta(ei, k)
    k_series = 1.0 / (1.0 / k_eff + 1.0 / k_hertz)
    return math.sqrt(k_series / wheel_mass) / (2.0 * math.pi)
