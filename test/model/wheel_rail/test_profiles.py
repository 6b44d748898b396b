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
Tests of the parametric LMA-type / CHN60-type profiles (the table: test_contact_table.py).

The profiles are approximations (see ttb_sim.model.wheel_rail.profiles); the tests check
geometric consistency and plausibility, with the measured numbers recorded.
"""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail import contact_table, profiles


def _joins_are_tangent(profile: profiles.Profile) -> None:
    """Each segment's own formula, evaluated at the joins, agrees in height and slope."""
    segments = profile._segments
    for left, right in zip(segments[:-1], segments[1:]):
        t = right.t0
        assert left.t1 == t
        h_l, s_l, _ = profiles.Profile([left], 'left').evaluate(np.array([t]))
        h_r, s_r, _ = profiles.Profile([right], 'right').evaluate(np.array([t]))
        assert h_l == pytest.approx(h_r, abs=1e-12)
        assert s_l == pytest.approx(s_r, rel=1e-9, abs=1e-12)


def test_rail_profile_dimensions():
    """CHN60-type head: crown top at 0, symmetric, R300/R80/R13 tangent, 73 mm wide."""
    rail = profiles.rail_profile()
    _joins_are_tangent(rail)
    u = np.linspace(-0.03, 0.03, 61)
    v, s, c = rail.evaluate(u)
    assert v.max() == pytest.approx(0.0, abs=1e-15)
    assert v == pytest.approx(v[::-1], abs=1e-15)
    assert c[30] == pytest.approx(-1 / 0.300)
    assert rail.evaluate(0.02)[2] == pytest.approx(-1 / 0.080)
    assert rail.evaluate(0.035)[2] == pytest.approx(-1 / 0.013)
    # The corner arc would be vertical at the head half-width 36.5 mm.
    seg = rail._segments[-2]
    assert seg.centre_t + seg.radius == pytest.approx(0.0365)


def test_wheel_profile_dimensions():
    """LMA-type wheel: taping line at h = 0 with slope 1:20, flange 27 mm high, 32 mm thick."""
    wheel = profiles.wheel_profile()
    _joins_are_tangent(wheel)
    p = profiles.WheelParameters()
    h, s, _ = wheel.evaluate(0.0)
    assert h == pytest.approx(0.0, abs=1e-15) and s == pytest.approx(0.05, rel=1e-9)
    t0, _ = wheel.t_range
    assert wheel.evaluate(t0)[0] == pytest.approx(-0.027)
    # Flange face passes 12 mm below the taping-line level at 70 - 32 = 38 mm from it.
    assert wheel.evaluate(-0.038)[0] == pytest.approx(-0.012, abs=1e-12)
    assert p.taping_semi_distance == pytest.approx(0.7465)


def test_invalid_parameters():
    """Inconsistent or out-of-range dimensions raise ModelError naming the parameter."""
    with pytest.raises(ModelError, match='tread_radius'):
        profiles.WheelParameters(tread_radius=-1.0)
    with pytest.raises(ModelError, match='crown_half_width'):
        profiles.RailParameters(crown_half_width=0.05)
    with pytest.raises(ModelError, match='y_max'):
        contact_table.contact_geometry_table(y_max=0.1)
    with pytest.raises(ModelError, match='n_points'):
        contact_table.contact_geometry_table(n_points=100)
