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
Closed forms for the pile-soil validation cases V11-V16 (PHYSICS.md 9.4-9.5).

Independent of the finite-element code: the Randolph-Wroth head stiffness of
a single pile, Gazetas' fit for the same, the modes of a layered shear column
on a rigid base (exact, from the layer transfer matrices, and the
quarter-wavelength estimate with the travel-time average Vs), the damped
first mode of such a column restrained along its depth by distributed springs
and dashpots (a block's side boundary spread over its plan), the surface
receptance of a layered column on a half-space under a harmonic load, and the
Clough-Duncan hyperbola with its Mohr-Coulomb cap.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np
from scipy.optimize import brentq, newton


def randolph_wroth_stiffness(g_l: float, nu: float, length: float, radius: float,
                             pile_modulus: float, rho: float = 1.0, xi: float = 1.0) -> float:
    """
    Return the axial head stiffness of a compressible pile (N/m), Randolph & Wroth (1978).

    Parameters
    ----------
    g_l : float
        Soil shear modulus at the depth of the pile tip (Pa).
    nu : float
        Soil Poisson's ratio.
    length, radius : float
        Pile length and radius (m).
    pile_modulus : float
        Young's modulus of the pile (Pa).
    rho : float
        Mean shear modulus over the length over g_l (homogeneity factor).
    xi : float
        g_l over the shear modulus below the tip.

    """
    lam = pile_modulus / g_l
    zeta = math.log(2.5 * length * rho * (1 - nu) / radius)
    mu_l = (length / radius) * math.sqrt(2.0 / (zeta * lam))
    shaft = math.tanh(mu_l) / mu_l * (length / radius)
    base = 4.0 / ((1 - nu) * xi)
    ratio = (base + 2 * math.pi * rho / zeta * shaft) / (1 + base * shaft / (math.pi * lam))
    return ratio * g_l * radius


def layered_pile_stiffness(thicknesses: Sequence[float], shear_moduli: Sequence[float],
                           nu: float, length: float, diameter: float,
                           pile_modulus: float) -> float:
    """
    Return Randolph-Wroth for a pile in horizontal layers (N/m).

    G_L is the modulus of the layer at the tip, rho the length-average of G
    over G_L, and the soil below the tip is taken as the tip layer (xi = 1).
    """
    z = 0.0
    integral = 0.0
    g_tip = shear_moduli[-1]
    for t, g in zip(thicknesses, shear_moduli):
        inside = max(0.0, min(t, length - z))
        integral += inside * g
        if z <= length < z + t:
            g_tip = g
        z += t
    rho = integral / length / g_tip
    return randolph_wroth_stiffness(g_tip, nu, length, 0.5 * diameter, pile_modulus, rho, 1.0)


def scoured_pile_stiffness(thicknesses: Sequence[float], shear_moduli: Sequence[float],
                           nu: float, length: float, diameter: float, pile_modulus: float,
                           area: float, depth: float) -> float:
    """
    Return the axial head stiffness of a pile whose top ``depth`` of soil is removed (N/m).

    The free length above the scour line in series with Randolph-Wroth
    (:func:`layered_pile_stiffness`) for the embedded rest, in the layers below
    the scour line (the one it cuts shortened): 1 / (depth / (E_p A) + 1 / K_RW).
    """
    kept_thickness: list[float] = []
    kept_modulus: list[float] = []
    top = 0.0
    for t, g in zip(thicknesses, shear_moduli):
        bottom = top + t
        if bottom > depth:
            kept_thickness.append(bottom - max(top, depth))
            kept_modulus.append(g)
        top = bottom
    embedded = layered_pile_stiffness(kept_thickness, kept_modulus, nu, length - depth,
                                      diameter, pile_modulus)
    return 1.0 / (depth / (pile_modulus * area) + 1.0 / embedded)


def gazetas_stiffness(young: float, diameter: float, length: float) -> float:
    """Return Gazetas' (1991) floating-pile fit K = 1.9 E d (L/d)^(2/3) (N/m)."""
    return 1.9 * young * diameter * (length / diameter)**(2.0 / 3.0)


def quarter_wavelength_frequencies(thicknesses: Sequence[float], vs: Sequence[float],
                                   n: int) -> np.ndarray:
    """Return f_k = (2k - 1) Vs_avg / (4 H), k = 1..n, Vs_avg the travel-time average (Hz)."""
    h = float(sum(thicknesses))
    vs_avg = h / sum(t / v for t, v in zip(thicknesses, vs))
    return (2 * np.arange(1, n + 1) - 1) * vs_avg / (4 * h)


def shear_column_frequencies(thicknesses: Sequence[float], shear_moduli: Sequence[float],
                             densities: Sequence[float], n: int) -> np.ndarray:
    """
    Return the first n natural frequencies (Hz) of a layered shear column on a rigid base.

    Free surface on top, fixed base; each layer carries u'' = (G / rho) u_zz,
    solved exactly by layer transfer matrices of (u, tau); the roots of the base
    displacement are bracketed on a fine frequency grid.
    """
    def base_displacement(f: float) -> float:
        w = 2 * math.pi * f
        u, tau = 1.0, 0.0
        for t, g, rho in zip(thicknesses, shear_moduli, densities):
            k = w * math.sqrt(rho / g)
            c, s = math.cos(k * t), math.sin(k * t)
            u, tau = u * c + tau * s / (g * k), -u * g * k * s + tau * c
        return u

    vs_min = min(math.sqrt(g / r) for g, r in zip(shear_moduli, densities))
    f_top = (2 * n + 2) * vs_min / (4 * sum(thicknesses))
    grid = np.linspace(1e-6, f_top, 20000)
    values = np.array([base_displacement(f) for f in grid])
    roots = []
    for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:])):
        roots.append(brentq(base_displacement, grid[i], grid[i + 1], xtol=1e-12))
        if len(roots) == n:
            break
    return np.array(roots)


SUBLAYER = 0.05
"""Thickness (m) of the uniform slices of :func:`restrained_column_root` (its restraint varies
with depth; halving it moves the root of ``pile_harmonic``'s column by 2e-8)."""


def restrained_column_root(thicknesses: Sequence[float], moduli: Sequence[float],
                           densities: Sequence[float], springs: Callable[[float], float],
                           dashpots: Callable[[float], float], guess: float) -> complex:
    """
    Return the complex root s (1/s) of a layered column on a rigid base, restrained in depth.

    Free surface on top, fixed base; at depth z the column carries
    rho u_tt = E u_zz - k(z) u - c(z) u_t (E the layer's modulus, k and c per unit
    volume, N/m^4 and N s/m^4). In slices of :data:`SUBLAYER` (each layer cut
    evenly, k and c at the slice's mid-depth) the solution is exact:
    kappa^2 = (rho s^2 + c s + k) / E, transfer matrix of (u, tau) in cosh and sinh
    of kappa t. The root of the base displacement is found by the secant method
    in the complex plane from s = i 2 pi ``guess`` (Hz), e.g. the unrestrained
    column's mode of :func:`shear_column_frequencies`. Its natural frequency is
    abs(s) / 2 pi, its damping ratio -Re(s) / abs(s).
    """
    slices = []
    top = 0.0
    for t, e, rho in zip(thicknesses, moduli, densities):
        n = max(1, math.ceil(t / SUBLAYER))
        h = t / n
        for k in range(n):
            z = top + (k + 0.5) * h
            slices.append((h, e, rho, springs(z), dashpots(z)))
        top += t

    def base_displacement(s: complex) -> complex:
        u, tau = 1.0 + 0j, 0j
        for h, e, rho, k, c in slices:
            kappa = np.sqrt(complex((rho * s * s + c * s + k) / e))
            ch, sh = np.cosh(kappa * h), np.sinh(kappa * h)
            u, tau = u * ch + tau * sh / (e * kappa), u * e * kappa * sh + tau * ch
        return complex(u)

    start = 2j * math.pi * guess
    return complex(newton(base_displacement, start, x1=start * 1.02 - 0.02 * abs(start),
                          tol=1e-12, maxiter=200))


def layered_column_receptance(thicknesses: Sequence[float], moduli: Sequence[float],
                              densities: Sequence[float], alphas: Sequence[float],
                              betas: Sequence[float], frequency: float) -> complex:
    """
    Return the surface displacement per unit surface traction of layers on a half-space (m/Pa).

    One-dimensional waves (a uniform load on the whole surface of laterally
    unbounded layers): constrained modulus E(1-nu)/((1+nu)(1-2nu)) for a normal
    load, G for a shear load. The last entry of every list is the half-space
    (its thickness is ignored). Rayleigh damping C = alpha M + beta K per
    layer: the modulus becomes M (1 + i w beta) and the density
    rho (1 - i alpha / w). Each layer's transfer matrix carries the surface
    impedance I = tau / u (tau = M du/dz, z down) of what lies below it up to
    its top, from I = -i k M of the outgoing wave in the half-space
    (Im k < 0: decaying with depth); the receptance is -1 / I at the surface.
    """
    w = 2.0 * math.pi * frequency
    if not w > 0:
        raise ValueError('the receptance of a column on a half-space needs f > 0')
    m = np.asarray(moduli, dtype=float) * (1.0 + 1j * w * np.asarray(betas, dtype=float))
    rho = np.asarray(densities, dtype=float) * (1.0 - 1j * np.asarray(alphas, dtype=float) / w)
    k = w * np.sqrt(rho / m)
    k = np.where(k.imag > 0, -k, k)
    impedance = -1j * k[-1] * m[-1]
    for h, kj, mj in zip(reversed(list(thicknesses[:-1])), reversed(k[:-1]), reversed(m[:-1])):
        c, s = np.cos(kj * h), np.sin(kj * h)
        impedance = (impedance * c + mj * kj * s) / (c - impedance * s / (mj * kj))
    return complex(-1.0 / impedance)


def hyperbola_stress(strain: np.ndarray, k0: float, strength: float,
                     failure_ratio: float) -> np.ndarray:
    """Return Clough-Duncan tau(g) = g / (1/k0 + R_f g / tau_f), capped at tau_f (Pa)."""
    g = np.asarray(strain, dtype=float)
    return np.minimum(g / (1.0 / k0 + failure_ratio * g / strength), strength)


def hyperbola_tangent(strain: np.ndarray, k0: float, strength: float,
                      failure_ratio: float) -> np.ndarray:
    """Return d tau / d g of the uncapped hyperbola, (1/k0) / (1/k0 + R_f g / tau_f)^2 (Pa)."""
    g = np.asarray(strain, dtype=float)
    a = 1.0 / k0
    return a / (a + failure_ratio * g / strength)**2
