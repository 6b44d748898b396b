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
A homogeneous viscoelastic half-space under a harmonic vertical surface load.

Independent of the finite-element code: the three-dimensional wave field is
written as a sum of plane P-SV waves over the horizontal wavenumber k (Lamb's
problem, 1904). For a vertical surface traction of wavenumber k the vertical
surface displacement per unit traction is (time factor exp(i w t), z into the
ground)

    g(k) = -k_s^2 nu_p / (mu F(k)),   F(k) = (2 k^2 - k_s^2)^2 - 4 k^2 nu_p nu_s,

with nu_j = sqrt(k^2 - k_j^2) (real part >= 0, the waves decay into the
ground), k_s = w / Vs, k_p = w / Vp and F the Rayleigh function (zero at the
Rayleigh wavenumber). At k >> k_s it becomes the static kernel (1 - nu) / (mu k)
(Boussinesq).

Damping enters as the finite-element model's Rayleigh damping C = a M + b K
does at one frequency: complex moduli mu (1 + i w b), lambda (1 + i w b) and a
complex density rho (1 - i a / w). It moves the Rayleigh pole off the real k
axis, so the wavenumber integrals are taken along it.

:func:`square_patch_compliance` is the mean vertical displacement of a square
loaded by a uniform vertical pressure, per newton of its resultant: the 2-D
wavenumber integral of g(|k|) times the patch's transform squared, in polar
coordinates. The static kernel is subtracted and added back in closed form
(the mean settlement of a uniformly loaded square, (4 / pi)[ln(1 + sqrt 2) -
(sqrt 2 - 1) / 3] p b (1 - nu^2) / E = 0.9464 p b (1 - nu^2) / E), so the
integral that remains decays fast.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

SQUARE_MEAN_SETTLEMENT = 4.0 / math.pi * (math.log(1.0 + math.sqrt(2.0))
                                          - (math.sqrt(2.0) - 1.0) / 3.0)
"""Mean settlement of a uniformly loaded square, in p b (1 - nu^2) / E (0.9464)."""


@dataclass(frozen=True)
class HalfSpace:
    """
    A homogeneous half-space with Rayleigh damping C = alpha M + beta K.

    Attributes
    ----------
    young : float
        Young's modulus E (Pa).
    poisson : float
        Poisson's ratio.
    density : float
        Density (kg/m^3).
    alpha, beta : float
        Rayleigh coefficients (1/s and s); 0, 0 for an elastic half-space.

    """

    young: float
    poisson: float
    density: float
    alpha: float = 0.0
    beta: float = 0.0

    def __post_init__(self) -> None:
        """Check the fields."""
        if not (self.young > 0 and self.density > 0 and 0 <= self.poisson < 0.5):
            raise ValueError(f'half-space needs E > 0, rho > 0 and 0 <= nu < 0.5, not E = '
                             f'{self.young}, rho = {self.density}, nu = {self.poisson}')
        if self.alpha < 0 or self.beta < 0:
            raise ValueError(f'Rayleigh coefficients must be >= 0, not {self.alpha}, '
                             f'{self.beta}')

    @property
    def shear_modulus(self) -> float:
        """Elastic shear modulus G (Pa)."""
        return self.young / (2.0 * (1.0 + self.poisson))

    @property
    def vs(self) -> float:
        """Elastic shear-wave speed (m/s)."""
        return math.sqrt(self.shear_modulus / self.density)

    def complex_shear_modulus(self, omega: float) -> complex:
        """Return mu (1 + i w beta), the shear modulus with the stiffness damping."""
        return self.shear_modulus * (1.0 + 1j * omega * self.beta)

    def wavenumbers(self, omega: float) -> tuple[complex, complex]:
        """Return (k_p, k_s), complex with damping (imaginary parts <= 0)."""
        mu = self.complex_shear_modulus(omega)
        rho = self.density * (1.0 - 1j * self.alpha / omega)
        k_s = np.sqrt(omega**2 * rho / mu)
        return complex(k_s * math.sqrt(speed_ratio_squared(self.poisson))), complex(k_s)


def surface_kernel(space: HalfSpace, omega: float, k: np.ndarray) -> np.ndarray:
    """Return g(k) (m per Pa per unit wavenumber area), the vertical surface compliance."""
    k_p, k_s = space.wavenumbers(omega)
    k = np.asarray(k, dtype=complex)
    nu_p = np.sqrt(k * k - k_p * k_p)
    nu_s = np.sqrt(k * k - k_s * k_s)
    rayleigh = (2.0 * k * k - k_s * k_s)**2 - 4.0 * k * k * nu_p * nu_s
    return -k_s * k_s * nu_p / (space.complex_shear_modulus(omega) * rayleigh)


def speed_ratio_squared(poisson: float) -> float:
    """Return (Vs / Vp)^2 = (1 - 2 nu) / (2 (1 - nu))."""
    return (1.0 - 2.0 * poisson) / (2.0 * (1.0 - poisson))


def rayleigh_speed(poisson: float) -> float:
    """Return the Rayleigh-wave speed over Vs of an elastic half-space (root of F, Brent)."""
    ratio = speed_ratio_squared(poisson)

    def rayleigh(c: float) -> float:
        return (2.0 - c * c)**2 - 4.0 * math.sqrt(1.0 - ratio * c * c) * math.sqrt(1.0 - c * c)

    # F > 0 at c = 0.5 and < 0 just below 1 for every 0 <= nu < 0.5: one root between
    return float(brentq(rayleigh, 0.5, 1.0 - 1e-12, xtol=1e-15, rtol=1e-15))


def _patch_angular(k: float, side: float, n: int, x: float | None = None) -> float:
    """
    Return an integral over the angle at |k| = k of the square's transform.

    With ``x`` None: of the transform squared (the mean over the square); else of
    the transform times cos(k x cos(theta)) (the surface point (x, 0)).
    """
    theta = (np.arange(n) + 0.5) * (0.5 * math.pi / n)   # midpoints on [0, pi / 2]
    half = 0.5 * k * side
    s = np.sinc(half * np.cos(theta) / math.pi) * np.sinc(half * np.sin(theta) / math.pi)
    weight = s if x is None else np.cos(k * x * np.cos(theta))
    return 4.0 * float(np.sum(s * weight)) * (0.5 * math.pi / n)


def _inverse_distance_integral(x: float, side: float) -> float:
    """Return the integral of 1 / r over the square centred at 0, seen from (x, 0, 0) (m)."""
    def primitive(u: float, v: float) -> float:
        r = math.hypot(u, v)
        return (u * math.log(v + r) if u else 0.0) + v * math.log(u + r)

    lo, hi = -0.5 * side, 0.5 * side
    return (primitive(hi - x, hi) - primitive(lo - x, hi) - primitive(hi - x, lo)
            + primitive(lo - x, lo))


def square_patch_compliance(space: HalfSpace, frequency: float, side: float, *,
                            cutoff: float = 400.0, angles: int = 512,
                            at: float | None = None) -> complex:
    """
    Return the vertical displacement of a uniformly loaded square per newton (m/N).

    Parameters
    ----------
    space : HalfSpace
        The ground.
    frequency : float
        Hz; 0 gives the static settlement (Boussinesq, exact).
    side : float
        Side b of the square (m), centred at the origin.
    cutoff : float
        Upper end of the wavenumber integral, in 1 / side (the static kernel
        is subtracted, so the remainder beyond it is of relative order
        (k_s side / cutoff)^2).
    angles : int
        Midpoints of the angular integral on a quarter turn.
    at : float, optional
        None: the mean over the square; x (m): the surface point (x, 0, 0).

    """
    if not side > 0:
        raise ValueError(f'the patch side must be > 0 m, not {side}')
    nu = space.poisson
    if at is None:
        shape = SQUARE_MEAN_SETTLEMENT / (2.0 * side)
    else:
        shape = _inverse_distance_integral(float(at), side) / (2.0 * math.pi * side**2)
    if frequency == 0.0:
        return complex(shape * (1.0 - nu) / space.shear_modulus)
    if space.alpha == 0.0 and space.beta == 0.0:
        raise ValueError('the wavenumber integral runs along the real axis: it needs damping '
                         '(alpha or beta > 0) to keep the Rayleigh pole off it')
    omega = 2.0 * math.pi * frequency
    mu = space.complex_shear_modulus(omega)
    static = shape * (1.0 - nu) / mu
    k_p, k_s = space.wavenumbers(omega)
    k_r = k_s.real / rayleigh_speed(nu)

    def remainder(k: float) -> complex:
        g = surface_kernel(space, omega, np.array([k]))[0] - (1.0 - nu) / (mu * k)
        return complex(g * k * _patch_angular(k, side, angles, at))

    top = cutoff / side
    points = sorted(p for p in (k_p.real, k_s.real, k_r, 1.2 * k_r, 2.0 * k_r) if p < top)
    total = 0j
    floor = 1e-9 * abs(static) * 4.0 * math.pi**2   # 1e-9 of the answer's scale
    for part in (np.real, np.imag):
        value, _ = quad(lambda k: float(part(remainder(k))), 0.0, top, points=points,
                        limit=400, epsabs=floor, epsrel=1e-8)
        total += value if part is np.real else 1j * value
    return complex(static + total / (4.0 * math.pi**2))
