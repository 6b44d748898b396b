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
Tests of the simplified wheelset contact geometry and the creepages (PHYSICS.md 2.3).

Reference values are typed again from PHYSICS.md 2.3.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttb_sim.errors import ModelError
import ttb_sim.model.vehicle as car
from ttb_sim.model.wheel_rail import creep, geometry


def test_creepages_simplified_geometry_and_restoring_yaw():
    """
    Equivalent cone (PHYSICS.md 2.3) in REP-103 axes: a left shift gives a restoring yaw couple.

    For y > 0 the left wheel rolls on a larger radius, slips backwards
    (xi_x < 0) and is pushed forwards; the couple -b (Fx_L - Fx_R) about z is
    negative, steering the wheelset to the right, towards the track centre.
    """
    lam, r0, b, v = 0.05, 0.46, 0.7465, 83.3
    geo = geometry.simplified_geometry(np.array([0.0, 0.002]), lam, r0)
    assert geo.rolling_radius[1] == pytest.approx([r0 + lam * 0.002, r0 - lam * 0.002])
    xi_x, xi_y, xi_sp = geometry.creepages(v, geo, nominal_radius=r0, semi_distance=b)
    assert xi_x[0] == pytest.approx([0.0, 0.0], abs=1e-15)
    assert xi_x[1] == pytest.approx([-lam * 0.002 / r0, lam * 0.002 / r0])
    assert np.all(xi_y == 0.0)
    assert xi_sp[0] == pytest.approx([-math.sin(math.atan(lam)) / r0,
                                      math.sin(math.atan(lam)) / r0])
    fx, _, _ = creep.linear_creep_forces(xi_x, xi_y, xi_sp, (1e7, 1e7, 3e4, 100.0))
    yaw_moment = -b * (fx[1, 0] - fx[1, 1])
    assert yaw_moment < 0.0
    # Yaw angle and lateral velocity: xi_y = y'/V - psi; yaw rate enters xi_x and spin.
    _, xi_y2, _ = geometry.creepages(v, geo, lateral_velocity=0.1, yaw=1e-3)
    assert xi_y2 == pytest.approx(np.full((2, 2), 0.1 / v - 1e-3))
    xi_x3, _, xi_sp3 = geometry.creepages(v, geo, yaw_rate=0.01)
    assert xi_x3[0] == pytest.approx([-b * 0.01 / v, b * 0.01 / v])
    assert xi_sp3[0] - xi_sp[0] == pytest.approx(np.full(2, 0.01 * math.cos(math.atan(lam)) / v))


def test_creepages_match_car_contact_map():
    """xi_x and xi_y equal the contact-point velocities of car.contact_map divided by V."""
    cmap = car.contact_map()
    rng = np.random.default_rng(3)
    qdot = rng.normal(0.0, 0.05, 42)
    v = 70.0
    geo = geometry.simplified_geometry(np.zeros(4), 0.0, 0.46)
    ws = [car.wheelset_dofs(j) for j in range(4)]
    xd, yd, rolld, spind, yawd = (np.array([qdot[w[k]] for w in ws]) for k in (0, 1, 3, 4, 5))
    xi_x, xi_y, _ = geometry.creepages(v, geo, longitudinal_velocity=xd, lateral_velocity=yd,
                                       yaw_rate=yawd, spin_rate=spind, roll_rate=rolld)
    assert xi_x.reshape(-1) == pytest.approx(cmap.hx @ qdot / v, rel=1e-12)
    assert xi_y.reshape(-1) == pytest.approx(cmap.hy @ qdot / v, rel=1e-12)


def test_invalid_geometry_inputs():
    """Bad inputs raise ModelError naming the parameter and the allowed range."""
    with pytest.raises(ModelError, match='speed'):
        geometry.creepages(0.0, geometry.simplified_geometry(0.0, 0.05))
    with pytest.raises(ModelError, match='conicity'):
        geometry.simplified_geometry(0.0, 2.0)
