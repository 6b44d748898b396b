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
Tests of the contact-geometry table of a wheelset on the LMA-type / CHN60-type profiles.

The profiles are approximations (see ttb_sim.model.wheel_rail.profiles); the tests check
geometric consistency and plausibility, with the measured numbers recorded.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail import contact_table, geometry, hertz, profiles


@pytest.fixture(scope='module')
def table() -> contact_table.ContactGeometryTable:
    return contact_table.contact_geometry_table()


def test_gauge_and_rail_position(table):
    """Gauge 1435 mm measured 16 mm below the canted rail top; crown peak 7.5 mm to the field."""
    rp = profiles.RailParameters()
    y, z, u = contact_table._rail_points(profiles.rail_profile(rp), rp, 1e-5)
    inner = y < y[np.argmax(z)]
    order = np.argsort(z[inner])
    assert np.interp(-0.016, z[inner][order], y[inner][order]) == pytest.approx(0.7175)
    # With a 1:40 cant the highest point of the R300 crown is 300/40 = 7.5 mm outboard.
    assert u[np.argmax(z)] == pytest.approx(0.0075, abs=2e-5)


def test_table_mirror_symmetry(table):
    """Left/right mirror: r_L(y) = r_R(-y), gamma_L(y) = gamma_R(-y), roll odd, rise even."""
    for column in (table.rolling_radius, table.contact_angle, table.wheel_position,
                   table.rail_position, table.wheel_curvature, table.rail_curvature):
        assert column[:, 0] == pytest.approx(column[::-1, 1], abs=1e-12)
    assert table.contact_y[:, 0] == pytest.approx(-table.contact_y[::-1, 1], abs=1e-12)
    assert table.roll == pytest.approx(-table.roll[::-1], abs=1e-14)
    assert table.rise == pytest.approx(table.rise[::-1], abs=1e-12)
    mid = len(table.lateral) // 2
    assert table.lateral[mid] == 0.0 and table.roll[mid] == pytest.approx(0.0, abs=1e-15)


def test_centred_contact_near_taping_line(table):
    """At y = 0 both wheels touch within 1 mm of the taping line, radius within 0.05 mm of r0."""
    mid = len(table.lateral) // 2
    assert np.abs(table.wheel_position[mid]).max() < 1e-3
    assert table.rolling_radius[mid] == pytest.approx([0.46, 0.46], abs=5e-5)
    assert table.contact_y[mid, 0] == pytest.approx(0.7465, abs=1e-3)
    assert table.wheel_curvature[mid, 0] == pytest.approx(-1.0)       # R1000 hollow tread
    assert table.rail_curvature[mid, 0] == pytest.approx(1 / 0.3)      # R300 crown


def test_rolling_radius_difference_and_conicity(table):
    """
    r_L - r_R = 2 lambda_e y for small y, with 0.02 <= lambda_e <= 0.2 (LMA on CHN60 1:40).

    lambda_e from the table at 1 mm; linearity checked for |y| <= 3 mm to 1 %.
    Measured: lambda_e = 0.0759 (1-4 mm), 0.0741 at 6 mm.
    """
    lam = table.equivalent_conicity(0.001)
    assert 0.02 <= lam <= 0.2
    assert lam == pytest.approx(0.0759, abs=0.001)
    y = np.linspace(-0.003, 0.003, 25)
    y = y[y != 0.0]
    assert table.radius_difference(y) == pytest.approx(2.0 * lam * y, rel=0.01)
    # Klingel wavelength 2 pi sqrt(r0 b / lambda_e) for the record (PHYSICS.md 2.3).
    wavelength = 2 * math.pi * math.sqrt(0.46 * 0.7465 / lam)
    assert 10.0 < wavelength < 20.0


def test_contact_angle_continuity_on_tread(table):
    """
    On the tread (|y| < flange onset) contact angle and positions vary smoothly.

    Tolerances: |d gamma / d y| <= 1 deg/mm, |d Y_wheel / d y| <= 3 (contact
    point moves 1.5 mm on the wheel per mm of shift for R1000 on R300).
    gamma_L is non-decreasing in y there.
    """
    tread = np.abs(table.lateral) < 0.009
    y = table.lateral[tread]
    gamma = table.contact_angle[tread, 0]
    dy = np.diff(y)
    assert np.all(np.abs(np.diff(gamma)) / dy <= math.radians(1.0) / 1e-3)
    assert np.all(np.diff(gamma) >= -1e-12)
    assert np.all(np.abs(np.diff(table.wheel_position[tread, 0])) / dy <= 3.0)
    assert np.all(np.abs(gamma) < math.radians(5.0))


def test_flange_contact_at_large_displacement(table):
    """
    The left flange takes the contact for y beyond the flange clearance (about 9 mm).

    Onset (first y with gamma_L > 45 deg) expected between 8 and 11 mm; there
    the left contact lies on the flange (Y < -24.8 mm, flange root start), the
    contact angle is close to the 70 deg flange angle and the wheelset climbs.
    Measured: onset y = 9.35 mm, gamma_L = 70.1 deg.  The contact jumps from
    the tread to the flange (two-point contact is not represented).
    """
    gamma = table.contact_angle[:, 0]
    flange = gamma > math.radians(45.0)
    onset = table.lateral[np.argmax(flange)]
    assert 0.008 < onset < 0.011
    assert np.all(flange[table.lateral >= onset])
    first = np.argmax(flange)
    assert table.wheel_position[first, 0] < -0.0248
    assert math.degrees(gamma[first]) == pytest.approx(70.0, abs=2.0)
    assert table.rise[-1] > table.rise[first - 1] + 1e-3
    # The right wheel stays on its tread when the left flange is in contact.
    assert np.all(np.abs(table.contact_angle[flange, 1]) < math.radians(5.0))


def test_wheel_height_is_continuous_and_follows_rigid_kinematics(table):
    """
    The rigid-contact wheel height is continuous at the flange jump, with the closed-form slope.

    At the jump the rolling radius changes by > 10 mm between adjacent rows
    (measured 12.4 mm), the wheel height by less than a fifth of that (1.7 mm),
    and nowhere faster than the flange-contact slope (|dh/dy| < 40; 30.8).
    In flange contact the slope dh_L/dy follows from the two contact
    constraints of a rigid wheelset: (dz + a_L dphi) = tan(g_L) (dy + r_L dphi)
    on the left flange, (dz - a_R dphi) = -tan(g_R) (dy + r_R dphi) on the right
    tread (a = lateral arm of the contact point, r = rolling radius), with
    h_L = dz + b dphi; compared with the table's slope to 5 %.
    Measured at y = 10.3 mm: slope 3.59 from the table, closed form 3.64 (1.3 %).
    """
    b = 0.7465
    h = table.wheel_height(table.lateral, b)
    mid = len(table.lateral) // 2
    assert h[mid] == pytest.approx([0.0, 0.0], abs=1e-15)
    jump = int(np.argmax(np.abs(np.diff(table.rolling_radius[:, 0]))))
    radius_jump = abs(table.rolling_radius[jump + 1, 0] - table.rolling_radius[jump, 0])
    assert radius_jump > 0.01
    assert abs(h[jump + 1, 0] - h[jump, 0]) < 0.2 * radius_jump
    assert np.max(np.abs(np.diff(h[:, 0]) / np.diff(table.lateral))) < 40.0
    # Closed-form slope 1 mm into the flange contact (the rigid-body formula
    # ignores the contact point's travel over the curved flange root, which
    # matters in the first 0.3 mm).
    k = int(np.searchsorted(table.lateral, table.lateral[jump] + 1e-3))
    y, dy = table.lateral[k], table.lateral[k + 1] - table.lateral[k]
    tan_l, tan_r = np.tan(table.contact_angle[k])
    a_l, a_r = table.contact_y[k, 0] - y, y - table.contact_y[k, 1]
    r_l, r_r = table.rolling_radius[k]
    lhs = np.array([[1.0, a_l - tan_l * r_l], [1.0, -a_r + tan_r * r_r]])
    dz, dphi = np.linalg.solve(lhs, [tan_l, -tan_r])
    slope = (h[k + 1, 0] - h[k - 1, 0]) / (2 * dy)
    assert slope == pytest.approx(dz + b * dphi, rel=0.05)


def test_lookup_is_vectorised(table):
    """Lookups interpolate with np.interp, keep the input shape and clamp outside the range."""
    y = np.array([[0.0, 0.001], [0.002, 0.02]])
    r = table.lookup(y, 'rolling_radius')
    assert r.shape == (2, 2, 2)
    assert table.lookup(y, 'roll').shape == (2, 2)
    assert r[1, 1] == pytest.approx(table.rolling_radius[-1])
    geo = table.wheelset_geometry(np.zeros(4))
    assert geo.rolling_radius.shape == (4, 2)
    xi_x, _, _ = geometry.creepages(80.0, geo)
    assert xi_x.shape == (4, 2)
    with pytest.raises(ModelError, match='column'):
        table.lookup(0.0, 'radius')
    with pytest.raises(ModelError, match='amplitude'):
        table.equivalent_conicity(0.05)


def test_hertz_ellipse_from_table_curvatures(table):
    """The table's curvatures give a Hertz ellipse inside Kalker's a/b range on the tread."""
    mid = len(table.lateral) // 2
    e = hertz.hertz_ellipse(78.48e3, table.rolling_radius[mid, 0],
                            1.0 / table.rail_curvature[mid, 0],
                            wheel_transverse_radius=1.0 / table.wheel_curvature[mid, 0])
    assert 0.1 < e.a / e.b < 10.0
    assert e.peak_pressure < 1.13e9       # conformal hollow tread lowers the pressure
