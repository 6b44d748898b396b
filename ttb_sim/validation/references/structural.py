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
Independent reference solutions for the validation cases.

These are written from the closed forms in PHYSICS.md section 9 and share no
code with the finite-element pipeline they check.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

GRAVITY = 9.81


@dataclass(frozen=True)
class Beam:
    """A simply supported Euler-Bernoulli beam (SI units)."""

    length: float
    ei: float
    mass: float
    damping_ratio: float = 0.0

    def omega(self, j: ArrayLike) -> np.ndarray:
        """Return the circular frequencies of modes j (rad/s)."""
        return (np.asarray(j) * math.pi / self.length) ** 2 * math.sqrt(self.ei / self.mass)

    @property
    def f1(self) -> float:
        """Fundamental frequency (Hz)."""
        return float(self.omega(1)) / (2 * math.pi)

    def static_midspan(self, force: float) -> float:
        """Mid-span deflection under a static central force, F L^3 / (48 EI) (m)."""
        return force * self.length**3 / (48 * self.ei)


def fryba_midspan(beam: Beam, force: float, speed: float, t: np.ndarray,
                  n_modes: int = 60) -> np.ndarray:
    """
    Return the undamped mid-span deflection (m, downward positive) under a moving force.

    The force enters at x = 0 at t = 0. While it is on the span each mode obeys
    q'' + w_j^2 q = (2F/(mL)) sin(W_j t), W_j = j pi v / L, whose solution from
    rest is Fryba's series term (with the resonant limit when W_j = w_j); after
    the force leaves, each mode vibrates freely from its state at exit.

    """
    t = np.asarray(t, dtype=float)
    j = np.arange(1, n_modes + 1)[:, None]
    w = beam.omega(j)
    big_w = j * math.pi * speed / beam.length
    p = 2 * force / (beam.mass * beam.length)
    t_exit = beam.length / speed

    def on_span(tt: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        resonant = np.isclose(big_w, w, rtol=1e-9)
        den = np.where(resonant, 1.0, w**2 - big_w**2)
        q = p / den * (np.sin(big_w * tt) - big_w / w * np.sin(w * tt))
        dq = p / den * (big_w * np.cos(big_w * tt) - big_w * np.cos(w * tt))
        qr = p / (2 * w**2) * (np.sin(w * tt) - w * tt * np.cos(w * tt))
        dqr = p / (2 * w**2) * (w**2 * tt * np.sin(w * tt))
        return np.where(resonant, qr, q), np.where(resonant, dqr, dq)

    q_on, _ = on_span(np.minimum(t, t_exit)[None, :])
    q_x, dq_x = on_span(np.array([[t_exit]]))
    tau = np.maximum(t - t_exit, 0.0)[None, :]
    q_free = q_x * np.cos(w * tau) + dq_x / w * np.sin(w * tau)
    q = np.where(t[None, :] <= t_exit, q_on, q_free)
    return (q * np.sin(j * math.pi / 2)).sum(axis=0)


def fryba_peak(beam: Beam, force: float, speed: float, free_periods: float = 1.0,
               n_modes: int = 60) -> float:
    """
    Return the largest mid-span deflection (m) while the force crosses plus free vibration.

    The maximum is located on a fine grid and refined with a bounded scalar search.
    """
    t_end = beam.length / speed + free_periods / beam.f1
    n = 20000
    t = np.linspace(0.0, t_end, n)
    w = fryba_midspan(beam, force, speed, t, n_modes)
    i = int(np.argmax(w))
    lo, hi = t[max(i - 1, 0)], t[min(i + 1, n - 1)]
    res = minimize_scalar(lambda s: -fryba_midspan(beam, force, speed, np.array([s]),
                                                   n_modes)[0],
                          bounds=(lo, hi), method='bounded', options={'xatol': 1e-12})
    return max(float(w[i]), -float(res.fun))


@dataclass(frozen=True)
class QuarterCar:
    """A sprung mass on a spring-dashpot over a wheel of unsprung mass."""

    sprung_mass: float
    stiffness: float
    damping: float = 0.0
    unsprung_mass: float = 0.0


def sprung_mass_modal(beam: Beam, car: QuarterCar, speed: float, t_end: float,
                      n_modes: int = 20, rayleigh: tuple[float, float] | None = None,
                      n_out: int = 4000) -> dict[str, np.ndarray]:
    """
    Integrate a quarter car crossing a simply supported beam by modal superposition.

    Beam modes sin(j pi x / L), normalised to q'' + 2 zeta_j w_j q' + w_j^2 q =
    (2 / (m L)) phi_j(x_v) F(t). The wheel follows the beam (w_t + v w_x and
    w_tt + 2 v w_xt + v^2 w_xx), and rides on rigid ground outside it. All
    displacements are z up; the car starts in static equilibrium at x = 0.

    Parameters
    ----------
    beam : Beam
        The span.
    car : QuarterCar
        The vehicle.
    speed : float
        Constant speed (m/s).
    t_end : float
        End of the integration (s).
    n_modes : int
        Number of beam modes.
    rayleigh : (a0, a1), optional
        Rayleigh coefficients; zeta_j = a0 / (2 w_j) + a1 w_j / 2. Otherwise
        ``beam.damping_ratio`` for every mode.
    n_out : int
        Number of output samples.

    Returns
    -------
    dict
        ``t``, ``midspan`` (m, z up), ``acceleration`` of the sprung mass
        (m/s^2), ``contact`` force (N).

    """
    j = np.arange(1, n_modes + 1)
    w = beam.omega(j)
    if rayleigh is not None:
        zeta = rayleigh[0] / (2 * w) + rayleigh[1] * w / 2
    else:
        zeta = np.full(n_modes, beam.damping_ratio)
    kap = j * math.pi / beam.length
    gen = 2.0 / (beam.mass * beam.length)
    ms, k, c, mu = car.sprung_mass, car.stiffness, car.damping, car.unsprung_mass

    def parts(t: float, y: np.ndarray):
        q, dq = y[:n_modes], y[n_modes:2 * n_modes]
        zs, dzs = y[2 * n_modes], y[2 * n_modes + 1]
        x = speed * t
        on = 0.0 <= x <= beam.length
        phi = np.sin(kap * x) if on else np.zeros(n_modes)
        dphi = kap * np.cos(kap * x) if on else np.zeros(n_modes)
        ddphi = -kap**2 * np.sin(kap * x) if on else np.zeros(n_modes)
        zw = phi @ q
        dzw = phi @ dq + speed * dphi @ q
        spring = k * (zw - zs) + c * (dzw - dzs)
        # Contact force R = (ms + mu) g + mu zw'' + spring, and
        # zw'' = phi . q'' + 2 v dphi . q' + v^2 ddphi . q; solve for q'' (rank one).
        extra = 2 * speed * dphi @ dq + speed**2 * ddphi @ q
        base = -2 * zeta * w * dq - w**2 * q
        r0 = (ms + mu) * GRAVITY + spring + mu * extra
        # q'' = base - gen phi (r0 + mu phi . q'')
        denom = 1.0 + gen * mu * (phi @ phi)
        phi_qdd = (phi @ base - gen * (phi @ phi) * r0) / denom
        ddq = base - gen * phi * (r0 + mu * phi_qdd)
        contact = r0 + mu * phi_qdd
        return q, dq, ddq, spring / ms, contact, dzs

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        _, dq, ddq, acc, _, dzs = parts(t, y)
        return np.concatenate([dq, ddq, [dzs, acc]])

    t_eval = np.linspace(0.0, t_end, n_out)
    sol = solve_ivp(rhs, (0.0, t_end), np.zeros(2 * n_modes + 2), method='DOP853',
                    t_eval=t_eval, rtol=1e-10, atol=1e-13, max_step=0.2 / w[-1] * 2 * math.pi)
    mid = np.sin(kap * beam.length / 2) @ sol.y[:n_modes]
    acc = np.empty(sol.t.size)
    contact = np.empty(sol.t.size)
    for i, (ti, yi) in enumerate(zip(sol.t, sol.y.T)):
        _, _, _, acc[i], contact[i], _ = parts(ti, yi)
    return {'t': sol.t, 'midspan': mid, 'acceleration': acc, 'contact': contact}
