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
Parametric wheel and rail profiles.

The profiles are PARAMETRIC APPROXIMATIONS built from tangent circular arcs
and straight lines; they are not the official drawings, which were not
available.  Their dimensions and sources:

Rail, CHN60-type head (:class:`RailParameters`)
    Head width 73 mm (public 60 kg/m rail data, e.g.
    https://www.railroad-fastener.com/info/detailed-explanation-of-60kg-m-rail-parameters-102867528.html);
    head composed of R300 (crown), R80 and R13 (gauge corner) arcs, the arc
    composition commonly quoted for Chinese 60 kg/m rail [unverified]; the
    R300 arc spans +/-10 mm [assumed]; the R80 arc ends where the R13 corner
    reaches a vertical tangent at the head half-width.  Laid with a 1:40
    inward cant, gauge 1435 mm measured 16 mm below the rail top.

Wheel, LMA-type worn tread (:class:`WheelParameters`)
    Nominal rolling radius 0.46 m at the taping line, 70 mm from the flange
    back; back-to-back distance 1353 mm, so the taping lines are
    2 x 0.7465 m apart, matching b of PHYSICS.md 2.3; flange height 27 mm,
    flange thickness 32 mm measured 12 mm below the taping-line level, flange
    angle 70 deg (typical LM/LMA values [unverified]).  The tread is one
    R1000 arc with a 1:20 slope at the taping line [assumed, chosen so that the
    centred wheelset touches the canted R300 crown at the taping line], a
    tangent straight outer tread from 30 mm outboard, an R15 flange root and
    an R10 flange tip [assumed].

Profile coordinates: for the wheel, Y is the lateral distance from the taping
line, positive towards the field side (away from the flange), and
h(Y) = r0 - r(Y) the height of the tread surface relative to the taping
line point (r is the rolling radius).  For the rail, u is the lateral
distance from the head centreline, positive towards the field side, and v(u)
the height relative to the crown top (before cant).

The contact-geometry table of a wheelset on these profiles is in
:mod:`.contact_table`.
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import ModelError


@dataclass(frozen=True)
class _Segment:
    """One arc or line of a profile h(t) on [t0, t1]."""

    t0: float
    t1: float
    radius: float  # math.inf for a line
    centre_t: float = 0.0
    centre_h: float = 0.0
    branch: float = 1.0  # +1: upper half of the circle (concave h), -1: lower half
    line_h0: float = 0.0
    line_slope: float = 0.0


class Profile:
    """
    A single-valued profile h(t) made of tangent arcs and lines.

    Parameters
    ----------
    segments : list of _Segment
        Contiguous segments in increasing t.
    name : str
        Label for messages.

    """

    def __init__(self, segments: list[_Segment], name: str) -> None:
        self.name = name
        self._segments = tuple(segments)
        self._breaks = np.array([s.t0 for s in segments] + [segments[-1].t1])
        self._radius = np.array([s.radius for s in segments])
        self._ct = np.array([s.centre_t for s in segments])
        self._ch = np.array([s.centre_h for s in segments])
        self._branch = np.array([s.branch for s in segments])
        self._h0 = np.array([s.line_h0 for s in segments])
        self._k = np.array([s.line_slope for s in segments])
        self._t0 = np.array([s.t0 for s in segments])

    @property
    def t_range(self) -> tuple[float, float]:
        """Lateral extent (t_min, t_max) of the profile (m)."""
        return float(self._breaks[0]), float(self._breaks[-1])

    def _which(self, t: np.ndarray) -> np.ndarray:
        i = np.searchsorted(self._breaks, t, side='right') - 1
        return np.clip(i, 0, len(self._segments) - 1)

    def evaluate(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return height, slope and signed curvature at lateral positions t.

        Parameters
        ----------
        t : array_like
            Lateral positions (m) inside :attr:`t_range`.

        Returns
        -------
        h, dh_dt, curvature : numpy.ndarray
            Height (m), slope (-) and curvature (1/m, negative where the
            profile is concave, i.e. h'' < 0).

        """
        t = np.asarray(t, dtype=float)
        i = self._which(t)
        radius = self._radius[i]
        is_arc = np.isfinite(radius)
        r = np.where(is_arc, radius, 1.0)
        dt = t - self._ct[i]
        root = np.sqrt(np.maximum(r * r - dt * dt, 1e-30))
        br = self._branch[i]
        h_arc = self._ch[i] + br * root
        s_arc = -br * dt / root
        c_arc = -br / r
        h_line = self._h0[i] + self._k[i] * (t - self._t0[i])
        h = np.where(is_arc, h_arc, h_line)
        s = np.where(is_arc, s_arc, self._k[i])
        curvature = np.where(is_arc, c_arc, 0.0)
        return h, s, curvature


def _arc(t0: float, t1: float, radius: float, ct: float, ch: float, branch: float) -> _Segment:
    return _Segment(t0=t0, t1=t1, radius=radius, centre_t=ct, centre_h=ch, branch=branch)


def _line(t0: float, t1: float, h0: float, slope: float) -> _Segment:
    return _Segment(t0=t0, t1=t1, radius=math.inf, line_h0=h0, line_slope=slope)


def _check(name: str, value: float, lo: float, hi: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and lo < value < hi):
        raise ModelError(f'profile parameter {name} = {value!r} is invalid; '
                         f'allowed: {lo} < value < {hi}')


@dataclass(frozen=True)
class RailParameters:
    """
    Dimensions of the CHN60-type rail head and its laying (m, rad).

    Attributes
    ----------
    crown_radius, shoulder_radius, corner_radius : float
        Radii of the R300 crown, R80 shoulder and R13 gauge-corner arcs (m).
    crown_half_width : float
        Half-width of the crown arc (m) [assumed 10 mm].
    head_half_width : float
        Half the head width (m), 36.5 mm for a 73 mm head.
    corner_end_angle : float
        Slope angle (rad) at which the corner arc is continued by a straight
        side face (kept below 90 deg minus the cant so the canted profile
        stays single-valued).
    side_depth : float
        Depth below the crown top to which the side face is modelled (m).
    cant : float
        Inward rail cant (rad), atan(1/40).
    gauge : float
        Track gauge (m).
    gauge_depth : float
        Depth below the rail top at which the gauge is measured (m).

    """

    crown_radius: float = 0.300
    crown_half_width: float = 0.010
    shoulder_radius: float = 0.080
    corner_radius: float = 0.013
    head_half_width: float = 0.0365
    corner_end_angle: float = math.radians(85.0)
    side_depth: float = 0.024
    cant: float = math.atan(1.0 / 40.0)
    gauge: float = 1.435
    gauge_depth: float = 0.016

    def __post_init__(self) -> None:
        _check('crown_radius', self.crown_radius, 0.05, 2.0)
        _check('shoulder_radius', self.shoulder_radius, self.corner_radius, self.crown_radius)
        _check('corner_radius', self.corner_radius, 0.002, 0.05)
        _check('crown_half_width', self.crown_half_width, 0.0, self.head_half_width)
        _check('head_half_width', self.head_half_width, 0.02, 0.05)
        _check('corner_end_angle', self.corner_end_angle, math.radians(60.0),
               math.pi / 2 - abs(self.cant))
        _check('side_depth', self.side_depth, self.gauge_depth, 0.05)
        _check('cant', self.cant, -0.1, 0.1)
        _check('gauge', self.gauge, 0.9, 2.0)
        _check('gauge_depth', self.gauge_depth, 0.0, 0.03)


@dataclass(frozen=True)
class WheelParameters:
    """
    Dimensions of the LMA-type wheel profile (m, rad).

    Attributes
    ----------
    nominal_radius : float
        Rolling radius at the taping line r0 (m).
    tread_radius : float
        Radius of the (hollow) tread arc through the taping line (m).
    taping_slope : float
        Tread slope at the taping line, -dr/dY (-).
    outer_tread_start : float
        Y where the straight outer tread begins (m, outboard of the taping line).
    outer_edge : float
        Y of the outer edge of the modelled profile (m).
    root_radius, tip_radius : float
        Flange root and flange tip radii (m).
    flange_angle : float
        Flange face angle from the horizontal (rad).
    flange_thickness, flange_thickness_depth : float
        Flange thickness (m) measured at this depth below the taping-line level.
    flange_height : float
        Flange tip depth below the taping-line level (m).
    taping_line_offset : float
        Distance from the flange back face to the taping line (m).
    back_to_back : float
        Distance between the flange back faces of the wheelset (m).

    """

    nominal_radius: float = 0.46
    tread_radius: float = 1.0
    taping_slope: float = 0.05
    outer_tread_start: float = 0.030
    outer_edge: float = 0.065
    root_radius: float = 0.015
    tip_radius: float = 0.010
    flange_angle: float = math.radians(70.0)
    flange_thickness: float = 0.032
    flange_thickness_depth: float = 0.012
    flange_height: float = 0.027
    taping_line_offset: float = 0.070
    back_to_back: float = 1.353

    def __post_init__(self) -> None:
        _check('nominal_radius', self.nominal_radius, 0.2, 0.7)
        _check('tread_radius', self.tread_radius, 0.1, 100.0)
        _check('taping_slope', self.taping_slope, 0.0, 0.3)
        _check('outer_tread_start', self.outer_tread_start, 0.0,
               min(self.outer_edge, self.taping_slope * self.tread_radius))
        _check('outer_edge', self.outer_edge, 0.0, 0.1)
        _check('root_radius', self.root_radius, 0.003, self.tread_radius)
        _check('tip_radius', self.tip_radius, 0.002, 0.03)
        _check('flange_angle', self.flange_angle, math.radians(45.0), math.radians(85.0))
        _check('flange_thickness', self.flange_thickness, 0.015, self.taping_line_offset)
        _check('flange_thickness_depth', self.flange_thickness_depth, 0.0, self.flange_height)
        _check('flange_height', self.flange_height, 0.01, 0.05)
        _check('taping_line_offset', self.taping_line_offset, 0.03, 0.1)
        _check('back_to_back', self.back_to_back, 0.9, 2.0)

    @property
    def taping_semi_distance(self) -> float:
        """Half the distance between the two taping lines (m), 0.7465 m by default."""
        return 0.5 * self.back_to_back + self.taping_line_offset


def rail_profile(params: RailParameters | None = None) -> Profile:
    """
    Build the CHN60-type rail head profile v(u) (before cant).

    Parameters
    ----------
    params : RailParameters, optional
        Dimensions; defaults if omitted.

    Returns
    -------
    Profile
        Symmetric about u = 0, crown top at v = 0, v < 0 elsewhere.

    """
    p = params or RailParameters()
    r1, r2, r3 = p.crown_radius, p.shoulder_radius, p.corner_radius
    # Angles from the vertical of the normals at the junctions.
    th1 = math.asin(p.crown_half_width / r1)
    c1 = (0.0, -r1)
    c2 = (c1[0] + (r1 - r2) * math.sin(th1), c1[1] + (r1 - r2) * math.cos(th1))
    # The corner arc ends vertical at the head half-width: c3_u + r3 = half width.
    s2 = (p.head_half_width - r3 - c2[0]) / (r2 - r3)
    if not 0.0 < s2 < 1.0 or math.asin(s2) <= th1:
        raise ModelError('rail profile parameters are inconsistent: the R80 arc cannot join '
                         'the crown and the corner within the head half-width')
    th2 = math.asin(s2)
    c3 = (c2[0] + (r2 - r3) * math.sin(th2), c2[1] + (r2 - r3) * math.cos(th2))
    th3 = p.corner_end_angle
    u1 = p.crown_half_width
    u2 = c2[0] + r2 * math.sin(th2)
    u3 = c3[0] + r3 * math.sin(th3)
    v3 = c3[1] + r3 * math.cos(th3)
    slope3 = -math.tan(th3)
    u4 = u3 + (-p.side_depth - v3) / slope3
    half = [
        _arc(0.0, u1, r1, c1[0], c1[1], 1.0),
        _arc(u1, u2, r2, c2[0], c2[1], 1.0),
        _arc(u2, u3, r3, c3[0], c3[1], 1.0),
        _line(u3, u4, v3, slope3),
    ]
    mirrored = []
    for s in reversed(half):
        if math.isfinite(s.radius):
            mirrored.append(_arc(-s.t1, -s.t0, s.radius, -s.centre_t, s.centre_h, s.branch))
        else:
            h_end = s.line_h0 + s.line_slope * (s.t1 - s.t0)
            mirrored.append(_line(-s.t1, -s.t0, h_end, -s.line_slope))
    return Profile(mirrored + half, 'CHN60-type rail head')


def wheel_profile(params: WheelParameters | None = None) -> Profile:
    """
    Build the LMA-type wheel profile h(Y) = r0 - r(Y).

    Parameters
    ----------
    params : WheelParameters, optional
        Dimensions; defaults if omitted.

    Returns
    -------
    Profile
        From the flange tip (lowest point, h = -flange_height) to the outer
        edge; the taping line is Y = 0, h = 0.

    """
    p = params or WheelParameters()
    rt, lam = p.tread_radius, p.taping_slope
    # Tread arc: concave h (upper branch), slope lam at Y = 0, through (0, 0).
    ct = lam * rt / math.sqrt(1.0 + lam * lam)
    ch = -math.sqrt(rt * rt - ct * ct)
    # Flange face line h = hf + m (Y - yf), rising towards the tread.
    m = math.tan(p.flange_angle)
    yf = -(p.taping_line_offset - p.flange_thickness)
    hf = -p.flange_thickness_depth
    root = math.hypot(1.0, m)
    # Root arc centre (cr_t, cr_h): below the line by rf*root (vertically) and at
    # distance rt - rf from the tread centre (internally tangent).
    rf = p.root_radius
    # cr_h = hf + m (cr_t - yf) - rf*root; solve |c - (ct, ch)| = rt - rf for cr_t.
    k0 = hf - m * yf - rf * root - ch
    qa = 1.0 + m * m
    qb = -2.0 * ct + 2.0 * m * k0
    qc = ct * ct + k0 * k0 - (rt - rf) ** 2
    disc = qb * qb - 4.0 * qa * qc
    if disc <= 0.0:
        raise ModelError('wheel profile parameters are inconsistent: the flange root arc '
                         'cannot touch both the tread arc and the flange face')
    cr_t = (-qb + math.sqrt(disc)) / (2.0 * qa)
    cr_h = hf + m * (cr_t - yf) - rf * root
    # Tangent points: root/tread along the line of centres, root/face by projection.
    dist = math.hypot(cr_t - ct, cr_h - ch)
    y_rt = ct + (cr_t - ct) * rt / dist
    y_rf = cr_t - rf * m / root
    # Tip arc: convex (lower branch), lowest point at h = -flange_height.
    ri = p.tip_radius
    ci_h = -p.flange_height + ri
    ci_t = yf + (ci_h - hf - ri * root) / m
    y_tf = ci_t + ri * m / root
    if not (ci_t < y_tf < y_rf < y_rt < 0.0 < p.outer_tread_start):
        raise ModelError('wheel profile parameters are inconsistent: arcs and flange face '
                         'do not follow each other from the flange tip to the tread')
    y_o = p.outer_tread_start
    h_o = ch + math.sqrt(rt * rt - (y_o - ct) ** 2)
    s_o = -(y_o - ct) / math.sqrt(rt * rt - (y_o - ct) ** 2)
    segments = [
        _arc(ci_t, y_tf, ri, ci_t, ci_h, -1.0),
        _line(y_tf, y_rf, hf + m * (y_tf - yf), m),
        _arc(y_rf, y_rt, rf, cr_t, cr_h, 1.0),
        _arc(y_rt, y_o, rt, ct, ch, 1.0),
        _line(y_o, p.outer_edge, h_o, s_o),
    ]
    return Profile(segments, 'LMA-type wheel')
