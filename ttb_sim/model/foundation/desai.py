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
The Desai thin-layer interface law: Bandis normal closure, hyperbolic shear, slip.

Vectorised over Gauss points. Strains are the layer strains of
:mod:`ttb_sim.fe.interface`, local axes (n, s1, s2): relative displacement
over the notional thickness t, opening positive along n. Stresses returned are
the *increments* from the geostatic state (tension positive along n), the
quantities that balance the dynamic load; the total normal compression is
p = sigma_n0 - sigma_n.

Normal (Bandis et al., IJRMMS 20, 1983, with the maximum closure V_m = t as in
[P] Eq. 6): with closure e = -eps_n (a fraction of t),
sigma_n = -k_n0 e / (1 - e), tangent k_n = k_n0 / (1 - e)^2, which is [P]'s
k_yy0 / (1 + v/t)^2 with v = -e t opening positive. Beyond e = ``max_closure``
the law continues linearly with the tangent there. When p <= 0 the layer has
separated: zero total traction (normal and shear) and a residual tangent.

Shear (Clough & Duncan, JSMFD 97(SM12), 1971): on the reversible shear strain
g_e = g - g_p the traction magnitude follows the hyperbola
tau = |g_e| / (1/k_s0 + R_f |g_e| / tau_f), tangent k_s = k_s0 (1 - R_f tau/tau_f)^2,
along g_e; the Mohr-Coulomb strength tau_f = c + p tan(delta) caps it: when
the hyperbola would exceed tau_f, tau = tau_f exactly and the plastic slip g_p
moves so that |g_e| stays at the strain where the hyperbola reaches tau_f;
the tangent is then ``residual`` k_s0. Reversal before slip retraces the
hyperbola (nonlinear elastic, as in Clough-Duncan); hysteresis comes from slip.
Both shear directions share one tangent (PHYSICS.md 6.3, [P] Eq. 9).

Initial moduli. k_n0 is the constrained modulus E(1-nu)/((1+nu)(1-2nu)) of
[P] Eq. 6. For k_s0, [P] writes E nu/((1+nu)(1-2nu)), which is Lame's lambda,
not the shear modulus G; they agree only for nu = 0.25 (for the 0.35 surface
layer lambda = 2.16 G). A thin layer of soil shears with G, so the default is
G (``shear_modulus='G'``); ``'lame'`` reproduces [P] as printed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from ttb_sim.errors import ModelError

ShearModulus = Literal['G', 'lame']


def initial_moduli(young: np.ndarray, poisson: np.ndarray,
                   shear_modulus: ShearModulus = 'G') -> tuple[np.ndarray, np.ndarray]:
    """
    Return (k_n0, k_s0) of a thin layer of the given soil (Pa).

    k_n0 is the constrained modulus ([P] Eq. 6); k_s0 is G = E / (2 (1 + nu))
    or, with ``shear_modulus='lame'``, [P]'s lambda = E nu / ((1 + nu)(1 - 2 nu)).
    """
    e = np.asarray(young, dtype=float)
    nu = np.asarray(poisson, dtype=float)
    k_n0 = e * (1 - nu) / ((1 + nu) * (1 - 2 * nu))
    if shear_modulus == 'G':
        k_s0 = e / (2 * (1 + nu))
    elif shear_modulus == 'lame':
        k_s0 = e * nu / ((1 + nu) * (1 - 2 * nu))
    else:
        raise ModelError(f"shear_modulus must be 'G' or 'lame', not {shear_modulus!r}")
    return k_n0, k_s0


@dataclass(frozen=True)
class DesaiLaw:
    """
    Parameters of the Desai layer at each Gauss point (arrays of one shape).

    Attributes
    ----------
    k_n0, k_s0 : arrays
        Initial normal and shear moduli of the layer (Pa).
    cohesion : array
        Adhesion c (Pa).
    tan_delta : array
        Interface friction coefficient tan(delta).
    sigma_n0 : array
        Geostatic normal compression on the interface (Pa, >= 0).
    failure_ratio : float
        R_f = tau_f / tau_ult, in (0, 1].
    residual : float
        Residual tangent after slip or separation, as a fraction of the initial.
    max_closure : float
        Closure (fraction of t) beyond which the normal law is continued linearly.

    """

    k_n0: np.ndarray
    k_s0: np.ndarray
    cohesion: np.ndarray
    tan_delta: np.ndarray
    sigma_n0: np.ndarray
    failure_ratio: float = 0.9
    residual: float = 1e-3
    max_closure: float = 0.9

    def initial_tangent(self) -> np.ndarray:
        """Return the tangent (n, s1, s2) at the geostatic state, shape (..., 3)."""
        return np.stack([self.k_n0, self.k_s0, self.k_s0], axis=-1)

    def strength(self, compression: np.ndarray) -> np.ndarray:
        """Return the Mohr-Coulomb strength c + p tan(delta) at compression p (Pa)."""
        return self.cohesion + np.maximum(compression, 0.0) * self.tan_delta

    def evaluate(self, strain: np.ndarray, slip: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return stress increments, tangent moduli and the updated plastic slip.

        Parameters
        ----------
        strain : array, shape (..., 3)
            Layer strain (n opening positive, s1, s2).
        slip : array, shape (..., 2)
            Plastic shear slip strain at the start of the step.

        Returns
        -------
        stress : array, shape (..., 3)
            Traction increment from the geostatic state (Pa).
        tangent : array, shape (..., 3)
            Tangent moduli (k_n, k_s, k_s) (Pa).
        slip : array, shape (..., 2)
            Plastic slip after this state (commit it when the step converges).

        """
        e = -strain[..., 0]
        e_max = self.max_closure
        ec = np.minimum(e, e_max)
        sig_n = -self.k_n0 * ec / (1.0 - ec)
        k_n = self.k_n0 / (1.0 - ec)**2
        beyond = e > e_max
        sig_n = np.where(beyond, sig_n - k_n * (e - e_max), sig_n)
        p = self.sigma_n0 - sig_n
        separated = p <= 0.0
        p = np.maximum(p, 0.0)
        tau_f = self.strength(p)
        g_e = strain[..., 1:] - slip
        mag = np.linalg.norm(g_e, axis=-1)
        a = 1.0 / self.k_s0
        with np.errstate(divide='ignore', invalid='ignore'):
            b = np.where(tau_f > 0, self.failure_ratio / tau_f, np.inf)
            tau = np.where(tau_f > 0, mag / (a + b * mag), 0.0)
            direction = np.where(mag[..., None] > 0, g_e / mag[..., None], 0.0)
        yielding = tau >= tau_f
        tau = np.where(yielding, tau_f, tau)
        k_s = np.where(yielding, self.residual * self.k_s0,
                       self.k_s0 * (1.0 - self.failure_ratio * tau
                                    / np.where(tau_f > 0, tau_f, 1.0))**2)
        g_f = a * tau_f / (1.0 - self.failure_ratio) if self.failure_ratio < 1 else \
            np.zeros_like(tau_f)
        new_slip = np.where(yielding[..., None],
                            strain[..., 1:] - g_f[..., None] * direction, slip)
        shear = tau[..., None] * direction
        stress = np.concatenate([sig_n[..., None], shear], axis=-1)
        stress = np.where(separated[..., None],
                          np.stack([np.broadcast_to(self.sigma_n0, p.shape), np.zeros_like(p),
                                    np.zeros_like(p)], -1),
                          stress)
        k_n = np.where(separated, self.residual * self.k_n0, k_n)
        k_s = np.where(separated, self.residual * self.k_s0, k_s)
        new_slip = np.where(separated[..., None], strain[..., 1:], new_slip)
        return stress, np.stack([k_n, k_s, k_s], axis=-1), new_slip
