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
Tests of Hertz normal contact (PHYSICS.md 2.1, VALIDATION.md V5).

Reference values are typed again from PHYSICS.md 2.1.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail import hertz

P0 = (48000 / 8 + 3200 / 4 + 2400 / 2) * 9.81     # 78.48 kN, PHYSICS.md 2.1


def test_v5_hertz_lm_tread():
    """
    V5: LM tread, R = 0.46 m, P0 = 78.5 kN: delta0 = 77 um, k_H = 1.52e9 N/m (1 %).

    Reference PHYSICS.md 2.1 [derived]; G = 4.22e-8 m/N^(2/3).
    Measured: G = 4.2206e-8, delta0 = 77.36 um, k_H = 1.5216e9 N/m.
    """
    g = hertz.hertz_constant(0.46, 'lm')
    assert g == pytest.approx(4.22e-8, rel=0.005)
    assert hertz.static_compression(P0, g) == pytest.approx(77e-6, rel=0.01)
    assert hertz.linearised_stiffness(P0, g) == pytest.approx(1.52e9, rel=0.01)


def test_v5_hertz_conical_tread():
    """Conical tread: G = 5.13e-8, delta0 = 94 um, k_H = 1.25e9 N/m (PHYSICS.md 2.1, 1 %)."""
    g = hertz.hertz_constant(0.46, 'conical')
    assert g == pytest.approx(5.13e-8, rel=0.005)
    assert hertz.static_compression(P0, g) == pytest.approx(94e-6, rel=0.01)
    assert hertz.linearised_stiffness(P0, g) == pytest.approx(1.25e9, rel=0.01)


def test_hertz_force_law_and_loss_of_contact():
    """P = (delta/G)^1.5 inverts delta0 = G P0^(2/3); P = 0 for delta <= 0; vectorised."""
    g = hertz.hertz_constant(0.46)
    d0 = hertz.static_compression(P0, g)
    assert hertz.normal_force(d0, g) == pytest.approx(P0, rel=1e-12)
    delta = np.array([[-1e-4, 0.0], [5e-5, 1e-4]])
    p = hertz.normal_force(delta, g)
    assert p.shape == (2, 2)
    assert p[0, 0] == 0.0 and p[0, 1] == 0.0
    assert p[1, 1] == pytest.approx((1e-4 / g) ** 1.5)
    assert np.all(hertz.normal_force_derivative(delta[0], g) == 0.0)


def test_hertz_derivative_matches_finite_differences():
    """dP/d(delta) against central differences (relative 1e-6) over 10-200 um."""
    g = hertz.hertz_constant(0.46)
    delta = np.linspace(10e-6, 200e-6, 20)
    h = 1e-10
    fd = (hertz.normal_force(delta + h, g) - hertz.normal_force(delta - h, g)) / (2 * h)
    assert hertz.normal_force_derivative(delta, g) == pytest.approx(fd, rel=1e-6)
    k_h = hertz.linearised_stiffness(P0, g)
    assert hertz.normal_force_derivative(hertz.static_compression(P0, g), g) == \
        pytest.approx(k_h, rel=1e-12)


def test_hertz_ellipse_cross_check():
    """
    Hertz ellipse for R_w = 0.46 m on a 0.30 m crown at P0 (PHYSICS.md 2.1, within 3 %).

    Reference [derived]: a = 6.65 mm (rolling direction), b = 5.0 mm,
    p0 = 1.13 GPa, G_equivalent = 4.9e-8 m/N^(2/3).
    Measured: a = 6.648 mm, b = 5.001 mm, p0 = 1.127 GPa, G = 4.895e-8.
    """
    e = hertz.hertz_ellipse(P0, 0.46, 0.30)
    assert e.a == pytest.approx(6.65e-3, rel=0.03)
    assert e.b == pytest.approx(5.0e-3, rel=0.03)
    assert e.peak_pressure == pytest.approx(1.13e9, rel=0.03)
    assert e.g_equivalent == pytest.approx(4.9e-8, rel=0.03)
    assert e.peak_pressure == pytest.approx(3 * P0 / (2 * math.pi * e.a * e.b), rel=1e-12)


def test_hertz_ellipse_circular_limit():
    """Equal curvatures give a circle: a = (3 P R / 4 E*)^(1/3), delta = a^2 / R (1e-9)."""
    r = 0.4
    e_star = 2.06e11 / (2 * (1 - 0.3 ** 2))
    e = hertz.hertz_ellipse(np.array([1e4, P0]), r, r)
    a_ref = (3 * np.array([1e4, P0]) * r / (4 * e_star)) ** (1 / 3)
    assert e.a == pytest.approx(a_ref, rel=1e-9)
    assert e.b == pytest.approx(a_ref, rel=1e-9)
    assert e.approach == pytest.approx(a_ref ** 2 / r, rel=1e-9)


def test_hertz_ellipse_orientation_and_hollow_tread():
    """A sharper lateral curvature makes b < a; a hollow (negative radius) tread widens b."""
    sharp = hertz.hertz_ellipse(P0, 0.46, 0.08)
    assert sharp.b < sharp.a
    hollow = hertz.hertz_ellipse(P0, 0.46, 0.30, wheel_transverse_radius=-1.0)
    flat = hertz.hertz_ellipse(P0, 0.46, 0.30)
    assert hollow.b > flat.b
    with pytest.raises(ModelError, match='curvature'):
        hertz.hertz_ellipse(P0, 0.46, 0.30, wheel_transverse_radius=-0.2)
    with pytest.raises(ModelError, match='normal load'):
        hertz.hertz_ellipse(-1.0)


def test_invalid_hertz_inputs():
    """Bad inputs raise ModelError naming the parameter and the allowed range."""
    with pytest.raises(ModelError, match='tread'):
        hertz.hertz_constant(0.46, 'S1002')
    with pytest.raises(ModelError, match='wheel radius'):
        hertz.hertz_constant(-0.46)
