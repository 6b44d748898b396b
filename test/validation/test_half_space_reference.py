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
The half-space closed form (Lamb's problem) against limits it must reach.

Each limit is physics the kernel is not written from: the one-dimensional P
wave at k = 0, Boussinesq's static kernel at large k, the Rayleigh wave's
speed of a Poisson solid, and the mean settlement of a uniformly loaded square.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttb_sim.validation.references.half_space import (HalfSpace, rayleigh_speed,
                                                      SQUARE_MEAN_SETTLEMENT,
                                                      square_patch_compliance, surface_kernel)

SOIL = HalfSpace(5e6, 0.25, 1900.0, alpha=0.6, beta=7.6e-4)


def test_kernel_at_zero_wavenumber_is_the_plane_p_wave() -> None:
    omega = 2 * math.pi * 5.0
    k_p, _ = SOIL.wavenumbers(omega)
    mu = SOIL.complex_shear_modulus(omega)
    lam = 2 * mu * SOIL.poisson / (1 - 2 * SOIL.poisson)
    rho = SOIL.density * (1 - 1j * SOIL.alpha / omega)
    plane_wave = 1 / (1j * omega * rho * np.sqrt((lam + 2 * mu) / rho))
    # a uniform surface pressure sends a plane P wave down: u / p = 1 / (i w rho Vp)
    assert abs(surface_kernel(SOIL, omega, np.array([0.0]))[0] / plane_wave - 1) < 1e-12
    assert k_p.imag < 0   # waves decay along their way with exp(i w t)


def test_kernel_at_large_wavenumber_is_boussinesq() -> None:
    omega = 2 * math.pi * 5.0
    mu = SOIL.complex_shear_modulus(omega)
    k_s = abs(SOIL.wavenumbers(omega)[1])
    k = np.array([1e2, 1e3]) * k_s
    ratio = surface_kernel(SOIL, omega, k) * mu * k / (1 - SOIL.poisson)
    # the first correction is of order (k_s / k)^2: 1e-4 and 1e-6 here
    assert np.all(np.abs(ratio - 1) < 3 * (k_s / k)**2), ratio


def test_rayleigh_speed_of_a_poisson_solid() -> None:
    # nu = 1/4: c_R^2 = (2 - 2 / sqrt 3) Vs^2 exactly (Rayleigh 1885)
    assert rayleigh_speed(0.25) == pytest.approx(math.sqrt(2 - 2 / math.sqrt(3)), rel=1e-10)
    elastic = HalfSpace(5e6, 0.25, 1900.0)
    omega = 2 * math.pi * 5.0
    k_r = omega / (rayleigh_speed(0.25) * elastic.vs)
    # the elastic kernel has its pole there: it grows without bound as k nears k_R
    near = np.abs(surface_kernel(elastic, omega, k_r * (1 + np.array([1e-3, 1e-6]))))
    assert near[1] > 500 * near[0]


def test_static_settlement_of_a_square() -> None:
    side = 0.886
    exact = SQUARE_MEAN_SETTLEMENT * (1 - SOIL.poisson) / (2 * SOIL.shear_modulus * side)
    assert SQUARE_MEAN_SETTLEMENT == pytest.approx(0.9464, abs=5e-5)   # Giroud's table
    assert square_patch_compliance(SOIL, 0.0, side) == pytest.approx(exact, rel=1e-14)
    # a low frequency tends to it, at first order in k_s b (the radiation dashpot): 3.1 % at
    # 0.4 Hz, 0.76 % at 0.1 Hz (measured; stiffness damping only, so that the mass damping's
    # alpha / w does not grow as w falls)
    nearly = HalfSpace(5e6, 0.25, 1900.0, beta=SOIL.beta)
    errors = [abs(square_patch_compliance(nearly, f, side) / exact - 1) for f in (0.4, 0.1)]
    assert errors[1] < 0.01 and 3.6 < errors[0] / errors[1] < 4.4, errors


@pytest.mark.parametrize('frequency', [2.0, 10.0])
def test_patch_integral_has_converged(frequency: float) -> None:
    coarse = square_patch_compliance(SOIL, frequency, 0.886)
    fine = square_patch_compliance(SOIL, frequency, 0.886, cutoff=800.0, angles=2048)
    # doubling the wavenumber range and quadrupling the angles moves it by < 1e-8 (measured
    # 2e-12 at 2 Hz, 3e-10 at 10 Hz)
    assert abs(fine / coarse - 1) < 1e-8
    assert coarse.imag < 0   # radiation: the displacement lags the force


def test_a_wide_patch_is_the_plane_wave() -> None:
    omega = 2 * math.pi * 10.0
    k_s = abs(SOIL.wavenumbers(omega)[1])
    plane = surface_kernel(SOIL, omega, np.array([0.0]))[0]
    errors = []
    for side in (40.0 / k_s, 160.0 / k_s):
        mean = square_patch_compliance(SOIL, 10.0, side) * side**2
        errors.append(abs(mean / plane - 1))
    # the edges' share of the response falls as 1 / (k b): a quarter at four times the side
    assert errors[1] < 0.35 * errors[0] and errors[1] < 0.05, errors


def test_bad_input_is_refused() -> None:
    with pytest.raises(ValueError, match='nu'):
        HalfSpace(5e6, 0.5, 1900.0)
    with pytest.raises(ValueError, match='side'):
        square_patch_compliance(SOIL, 1.0, 0.0)
    with pytest.raises(ValueError, match='damping'):
        square_patch_compliance(HalfSpace(5e6, 0.25, 1900.0), 1.0, 1.0)


def test_static_surface_points_of_a_square() -> None:
    side = 0.886
    scale = (1 - SOIL.poisson) / (2 * SOIL.shear_modulus * side)
    centre = square_patch_compliance(SOIL, 0.0, side, at=0.0) / scale
    # the centre of a flexible square settles 1.122 p b (1 - nu^2) / E (Giroud's table),
    # (4 / pi) ln(1 + sqrt 2) exactly
    assert centre.real == pytest.approx(4 / math.pi * math.log(1 + math.sqrt(2)), rel=1e-12)
    for x in (20.0, 200.0):
        far = square_patch_compliance(SOIL, 0.0, side, at=x)
        point = (1 - SOIL.poisson) / (2 * math.pi * SOIL.shear_modulus * x)
        # far away the square is a point load (Boussinesq): the difference falls as (b / x)^2
        assert abs(far / point - 1) < 0.1 * (side / x)**2


@pytest.mark.parametrize('frequency', [1.0, 10.0])
def test_surface_point_integral_has_converged(frequency: float) -> None:
    coarse = square_patch_compliance(SOIL, frequency, 0.886, at=2.0)
    fine = square_patch_compliance(SOIL, frequency, 0.886, cutoff=800.0, angles=2048, at=2.0)
    # measured 2e-10 at 1 Hz, 2e-9 at 10 Hz
    assert abs(fine / coarse - 1) < 1e-7
