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
Checks of the V2 and V6 closed-form track references against independent routes.

V2: residue closed form vs numerical Fourier inversion of the moving-frame
equation, the static Winkler solution, Fryba's w(0) = P beta / (2k sqrt(1 - a^2))
and the PHYSICS.md 9.2 critical speed. V6: the receptance vs its Fourier
integral, the contact-force FRF vs a direct solve of the wheel/Hertz/rail
equations, and the P2 frequency vs the PHYSICS.md 3.1 value (48 Hz, 10 %).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from ttb_sim.validation.references import track as tr

EI = 2.059e11 * 3.217e-5
M = 60.64
K = 5e7 / 0.63
C = 3.6e4 / 0.63
P = 78.5e3
BETA = (K / (4 * EI)) ** 0.25
V_CR = (4 * K * EI / M**2) ** 0.25


def _fourier_moving(xi: float, v: float, c: float) -> float:
    """
    Return w(xi) by numerical Fourier inversion of the moving-frame equation.

    EI w'''' + m v^2 w'' - c v w' + k w = P delta(xi) with w = (1/2pi) int W
    exp(i kappa xi) d kappa gives W = P / D, D = EI kappa^4 - m v^2 kappa^2
    - i c v kappa + k; D(-kappa) = conj D(kappa), so
    w = (P / pi) int_0^inf [cos(kappa xi) Re(1/D) - sin(kappa xi) Im(1/D)] d kappa.
    Integrated in s = kappa / beta with the integrand scaled by k (dimensionless).
    """
    def inv(s: float) -> complex:
        kap = s * BETA
        return K / (EI * kap**4 - M * v**2 * kap**2 - 1j * c * v * kap + K)

    # Finite range with QAWO; the tail beyond S is bounded by int_S^inf 4 / s^4 ds
    # = 4 / (3 S^3) ~ 2e-10 of the O(1) integral.
    top = 2000.0
    wv = BETA * xi
    re = quad(lambda s: inv(s).real, 0.0, top, weight='cos', wvar=wv, epsabs=1e-13,
              epsrel=1e-12, limit=2000)[0]
    im = quad(lambda s: inv(s).imag, 0.0, top, weight='sin', wvar=wv, epsabs=1e-13,
              epsrel=1e-12, limit=2000)[0]
    val = re - im
    return P * BETA / (math.pi * K) * val


def _static_winkler(x: np.ndarray) -> np.ndarray:
    bx = BETA * np.abs(x)
    return P * BETA / (2 * K) * np.exp(-bx) * (np.cos(bx) + np.sin(bx))


XI = np.array([-4.0, -2.0, -1.1, -0.6, -0.25, 0.0, 0.1, 0.4, 0.9, 1.7, 3.0]) / BETA


@pytest.mark.parametrize('c', [0.0, C / 10, C])
@pytest.mark.parametrize('ratio', [0.0, 0.3, 0.7])
def test_closed_form_matches_fourier_integral(ratio, c):
    v = ratio * V_CR
    closed = tr.moving_load_deflection(XI, P, EI, M, K, v, c)
    fourier = np.array([_fourier_moving(x, v, c) for x in XI])
    # 1e-6 relative to the largest deflection of the sample (pointwise relative
    # error is meaningless near the sign changes of w).
    assert np.max(np.abs(closed - fourier)) <= 1e-6 * np.max(np.abs(fourier))


@pytest.mark.parametrize('ratio', [1.2, 2.0])
def test_damped_supercritical_matches_fourier_integral(ratio):
    v = ratio * V_CR
    closed = tr.moving_load_deflection(XI, P, EI, M, K, v, C)
    fourier = np.array([_fourier_moving(x, v, C) for x in XI])
    assert np.max(np.abs(closed - fourier)) <= 1e-6 * np.max(np.abs(fourier))


def test_undamped_at_or_above_critical_speed_is_rejected():
    with pytest.raises(ValueError):
        tr.moving_load_deflection(XI, P, EI, M, K, V_CR * 1.01)
    with pytest.raises(ValueError):
        tr.moving_load_deflection(XI, P, EI, M, K, -1.0, C)


def test_slow_load_reproduces_static_winkler_solution():
    x = np.linspace(-6.0, 6.0, 241) / BETA
    static = _static_winkler(x)
    peak = P * BETA / (2 * K)
    assert tr.moving_load_deflection(x, P, EI, M, K, 0.0) == pytest.approx(
        static, abs=1e-12 * peak)
    for c in (0.0, C):
        slow = tr.moving_load_deflection(x, P, EI, M, K, 1e-7 * V_CR, c)
        assert np.max(np.abs(slow - static)) <= 1e-6 * peak
    assert tr.static_peak_deflection(P, EI, K) == pytest.approx(peak, rel=1e-12)


def test_static_rail_deflection_matches_physics_md():
    # PHYSICS.md section 4: about 0.65 mm under the static wheel load P0 = 78.5 kN.
    assert tr.static_peak_deflection(P, EI, K) == pytest.approx(0.65e-3, rel=0.01)


def test_symmetry_without_damping_and_lag_with_damping():
    x = np.linspace(0.05, 5.0, 60) / BETA
    peak = P * BETA / (2 * K)
    for ratio in (0.0, 0.5, 0.9):
        v = ratio * V_CR
        ahead = tr.moving_load_deflection(x, P, EI, M, K, v)
        behind = tr.moving_load_deflection(-x, P, EI, M, K, v)
        assert np.max(np.abs(ahead - behind)) <= 1e-10 * peak
    v = 0.5 * V_CR
    ahead = tr.moving_load_deflection(x, P, EI, M, K, v, C)
    behind = tr.moving_load_deflection(-x, P, EI, M, K, v, C)
    assert np.max(np.abs(ahead - behind)) > 0.05 * peak
    # The viscous foundation makes the deflection lag: the trough trails the load.
    w_max, xi_max = tr.moving_load_peak(P, EI, M, K, v, C)
    assert xi_max < -0.01 / BETA
    assert w_max >= tr.moving_load_deflection(0.0, P, EI, M, K, v, C)


@pytest.mark.parametrize('ratio', [0.0, 0.3, 0.7, 0.95])
def test_undamped_peak_follows_fryba(ratio):
    # int_0^inf dx / (x^4 + 2 p x^2 + q^2) = pi / (2 q sqrt(2 (p + q))) gives
    # w(0) = P beta / (2 k sqrt(1 - a^2)), a = v / v_cr (Fryba); by symmetry the
    # undamped peak is under the load.
    w_max, xi_max = tr.moving_load_peak(P, EI, M, K, ratio * V_CR)
    assert w_max == pytest.approx(P * BETA / (2 * K) / math.sqrt(1 - ratio**2), rel=1e-9)
    assert abs(xi_max) < 1e-6 / BETA


def test_damped_peak_is_the_maximum_on_a_fine_grid():
    for ratio in (0.3, 0.7, 1.2):
        v = ratio * V_CR
        w_max, xi_max = tr.moving_load_peak(P, EI, M, K, v, C)
        x = np.linspace(-15.0, 15.0, 60001) / BETA
        w = tr.moving_load_deflection(x, P, EI, M, K, v, C)
        assert w_max >= w.max() - 1e-12 * w_max
        assert w_max == pytest.approx(w.max(), rel=1e-6)
        assert xi_max == pytest.approx(x[np.argmax(w)], abs=1e-3 / BETA)


def test_critical_speed_matches_physics_md():
    # PHYSICS.md 9.2: v_cr = 870 m/s for k = 7.94e7 N/m^2 on the CHN60 rail.
    assert tr.critical_speed(EI, M, 7.94e7) == pytest.approx(870.0, rel=0.005)
    # And it is the speed where the undamped w(0) blows up.
    w = [tr.moving_load_deflection(0.0, P, EI, M, K, r * V_CR) for r in (0.99, 0.999)]
    assert w[1] > 3 * w[0]


def _fourier_receptance(omega: float, c: float) -> complex:
    """Return (1/pi) int_0^inf d kappa / (EI kappa^4 + k - m omega^2 + i omega c)."""
    k_dyn = K - M * omega**2 + 1j * omega * c
    pts = [1.0]
    if M * omega**2 > K:
        pts.append(((M * omega**2 - K) / EI) ** 0.25 / BETA)
    split = 4.0 * max(pts)

    def f(s: float) -> complex:
        return K / (EI * (s * BETA) ** 4 + k_dyn)

    val = 0.0j
    for part in (np.real, np.imag):
        head = quad(lambda s: part(f(s)), 0.0, split, points=pts, epsabs=1e-14,
                    epsrel=1e-12, limit=500)[0]
        tail = quad(lambda s: part(f(s)), split, np.inf, epsabs=1e-14, epsrel=1e-12,
                    limit=500)[0]
        val += (head + tail) * (1.0 if part is np.real else 1.0j)
    return val * BETA / (math.pi * K)


def test_receptance_static_limit():
    static = 1.0 / (8 * EI * BETA**3)
    assert static == pytest.approx(BETA / (2 * K), rel=1e-12)
    for c in (0.0, C):
        low = tr.infinite_beam_receptance(np.array([0.0, 1e-4]), EI, M, K, c)
        assert low[0] == pytest.approx(static, rel=1e-12)
        assert low[1] == pytest.approx(static, rel=1e-6)


@pytest.mark.parametrize('freq', [5.0, 48.0, 150.0, 300.0, 1000.0])
def test_receptance_matches_fourier_integral(freq):
    omega = 2 * math.pi * freq
    for c in (C, C / 5):
        ref = _fourier_receptance(omega, c)
        got = complex(tr.infinite_beam_receptance(omega, EI, M, K, c))
        assert abs(got - ref) <= 1e-7 * abs(ref)
        # Damping dissipates power: Im(alpha) < 0 for exp(i omega t).
        assert got.imag < 0.0


def test_receptance_undamped_above_cut_on_is_the_damped_limit():
    omega = 2 * math.pi * 400.0
    undamped = complex(tr.infinite_beam_receptance(omega, EI, M, K))
    nearly = complex(tr.infinite_beam_receptance(omega, EI, M, K, 1e-3))
    assert undamped == pytest.approx(nearly, rel=1e-6)
    assert undamped.imag < 0.0


def test_contact_force_frf_matches_direct_solve():
    omega = 2 * math.pi * np.array([3.0, 30.0, 48.0, 120.0, 800.0])
    alpha_r = tr.infinite_beam_receptance(omega, EI, M, K, C)
    mass, k_h = 1200.0, 1.52e9
    got = tr.contact_force_frf(omega, mass, k_h, alpha_r)
    for w, a, g in zip(omega, alpha_r, got):
        # Unknowns u_w, u_r, F for unit dip r = 1 (downward positive):
        # -M w^2 u_w = -F;  u_r = a F;  F = k_H (u_w - u_r - 1).
        mat = np.array([[-mass * w**2, 0.0, 1.0], [0.0, 1.0, -a], [k_h, -k_h, -1.0]],
                       dtype=complex)
        u_w, u_r, force = np.linalg.solve(mat, np.array([0.0, 0.0, k_h], dtype=complex))
        assert g == pytest.approx(force, rel=1e-10)
    assert tr.contact_force_frf(0.0, mass, k_h, alpha_r[0]) == 0.0
    high = tr.contact_force_frf(2 * math.pi * 1e6, mass, k_h,
                                tr.infinite_beam_receptance(2 * math.pi * 1e6, EI, M, K, C))
    assert high == pytest.approx(-k_h, rel=1e-3)


def test_p2_frequency_matches_physics_md():
    # PHYSICS.md 3.1: about 48 Hz for the half wheelset on fasteners on a rigid slab.
    full = tr.p2_resonance_frequency()
    simple = tr.p2_frequency_estimate()
    assert full == pytest.approx(48.0, rel=0.10)
    assert simple == pytest.approx(48.0, rel=0.10)
    # The simplified estimate ignores the rail mass that moves with the wheel;
    # including it (and the fastener damping) lowers the peak, by about 1.6 %.
    assert full < simple
    assert (simple - full) / simple < 0.05


def test_p2_frequency_is_the_peak_of_the_frf():
    full = tr.p2_resonance_frequency()
    f = np.linspace(20.0, 100.0, 8001)
    om = 2 * math.pi * f
    mag = np.abs(tr.contact_force_frf(om, 1200.0, 1.52e9,
                                      tr.infinite_beam_receptance(om, EI, M, K, C)))
    assert full == pytest.approx(f[np.argmax(mag)], abs=0.02)


def test_p2_undamped_is_where_the_receptances_cancel():
    # Undamped below cut-on everything is real: the peak is the root of
    # 1 / (M w^2) = 1 / k_H + alpha_r(w).
    def g(freq: float) -> float:
        w = 2 * math.pi * freq
        lam = ((K - M * w**2) / (4 * EI)) ** 0.25
        return 1 / (1200.0 * w**2) - 1 / 1.52e9 - 1 / (8 * EI * lam**3)

    root = brentq(g, 10.0, 150.0, xtol=1e-12)
    assert tr.p2_resonance_frequency(c=0.0) == pytest.approx(root, rel=1e-6)
    k_series = 1 / (BETA / (2 * K) + 1 / 1.52e9)
    assert tr.p2_frequency_estimate() == pytest.approx(
        math.sqrt(k_series / 1200.0) / (2 * math.pi), rel=1e-12)
