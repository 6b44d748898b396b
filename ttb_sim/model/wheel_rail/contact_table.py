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
The wheelset-track contact-geometry table on the parametric profiles of :mod:`.profiles`.

Contact-geometry table (:func:`contact_geometry_table`)
    For each wheelset lateral displacement y (REP 103, to the left) in a
    range such as -12 .. +12 mm, with no yaw, the wheelset roll and rise are
    solved so that both wheels touch their rails (rigid profiles, the
    minimum gap of each wheel is zero).  The table stores rolling radii,
    contact angles, contact positions on wheel and rail and the transverse
    curvatures at the contact for the left and right wheel.  Only the
    minimum-gap contact of each wheel is kept: where the tread and the flange
    both come close (two-point contact), the contact jumps to the flange.
    Lookups are vectorised linear interpolations (np.interp); y outside the
    table range is clamped to its ends.
"""

from __future__ import annotations

from dataclasses import dataclass
import functools
import math

import numpy as np
from numpy.typing import ArrayLike

from ttb_sim.errors import ModelError
from ttb_sim.model.wheel_rail.geometry import WheelsetGeometry
from ttb_sim.model.wheel_rail.profiles import (Profile, rail_profile, RailParameters,
                                               wheel_profile, WheelParameters)


@dataclass(frozen=True)
class ContactGeometryTable:
    """
    Rigid contact geometry of a wheelset on straight track versus lateral shift.

    Columns indexed ``[..., 0]`` are the left wheel (y > 0 side), ``[..., 1]``
    the right wheel.

    Attributes
    ----------
    lateral : numpy.ndarray
        Wheelset lateral displacement y relative to the track (m), ascending.
    roll : numpy.ndarray
        Wheelset roll angle (rad, positive raises the left wheel).
    rise : numpy.ndarray
        Vertical displacement of the wheelset centre relative to y = 0 (m, up).
    rolling_radius : numpy.ndarray
        Shape (n, 2), rolling radius at the contact (m).
    contact_angle : numpy.ndarray
        Shape (n, 2), contact angle (rad), > 0 when the normal on the wheel
        tilts towards the track centre.
    wheel_position : numpy.ndarray
        Shape (n, 2), contact position on the wheel profile, Y from the taping
        line, positive towards the field side (m).
    rail_position : numpy.ndarray
        Shape (n, 2), contact position on the rail head, u from the head
        centreline, positive towards the field side, in the canted rail's
        own axes (m).
    contact_y : numpy.ndarray
        Shape (n, 2), lateral track coordinate of the contact point (m).
    wheel_curvature, rail_curvature : numpy.ndarray
        Shape (n, 2), transverse profile curvatures at the contact (1/m): the
        rail's is positive for a convex head, the wheel's is negative for a
        hollow (concave) tread and positive for a convex flange tip.
    nominal_radius, semi_distance : float
        r0 and the taping-line semi-distance b (m).

    """

    lateral: np.ndarray
    roll: np.ndarray
    rise: np.ndarray
    rolling_radius: np.ndarray
    contact_angle: np.ndarray
    wheel_position: np.ndarray
    rail_position: np.ndarray
    contact_y: np.ndarray
    wheel_curvature: np.ndarray
    rail_curvature: np.ndarray
    nominal_radius: float
    semi_distance: float

    def _interp(self, y: ArrayLike, column: np.ndarray) -> np.ndarray:
        y = np.asarray(y, dtype=float)
        if column.ndim == 1:
            return np.interp(y, self.lateral, column)
        return np.stack([np.interp(y, self.lateral, column[:, k]) for k in range(2)], axis=-1)

    def lookup(self, y: ArrayLike, name: str) -> np.ndarray:
        """
        Interpolate one column of the table at lateral displacements y.

        Parameters
        ----------
        y : array_like
            Wheelset lateral displacement (m); clamped to the table range.
        name : str
            Attribute name of a column (e.g. ``'rolling_radius'``).

        Returns
        -------
        numpy.ndarray
            Shape ``y.shape`` for 1-D columns, ``y.shape + (2,)`` otherwise.

        """
        columns = ('roll', 'rise', 'rolling_radius', 'contact_angle', 'wheel_position',
                   'rail_position', 'contact_y', 'wheel_curvature', 'rail_curvature')
        if name not in columns:
            raise ModelError(f'contact table column {name!r} is unknown; '
                             f'allowed: {", ".join(columns)}')
        return self._interp(y, getattr(self, name))

    def wheelset_geometry(self, y: ArrayLike) -> WheelsetGeometry:
        """
        Return rolling radii and contact angles at lateral displacements y.

        Parameters
        ----------
        y : array_like
            Wheelset lateral displacement (m); clamped to the table range.

        Returns
        -------
        WheelsetGeometry
            For :func:`ttb_sim.model.wheel_rail.geometry.creepages`.

        """
        return WheelsetGeometry(rolling_radius=self._interp(y, self.rolling_radius),
                                contact_angle=self._interp(y, self.contact_angle))

    def wheel_height(self, y: ArrayLike, arm: float) -> np.ndarray:
        """
        Return the rigid-contact height of each wheel at lateral arm +/- ``arm`` (m).

        This is ``rise + s arm roll`` (s = +1 left, -1 right): the vertical
        position, relative to the centred wheelset, that a point of the wheelset
        at lateral offset ``s arm`` takes when both wheels touch rigid rails.
        A wheel's normal compression is this height minus the actual height of
        the same point (plus rail motion).  Unlike the rolling radius, it is
        continuous when the contact jumps from the tread to the flange, because
        the minimum gap it comes from is continuous in y.

        Parameters
        ----------
        y : array_like
            Wheelset lateral displacement (m); clamped to the table range.
        arm : float
            Lateral semi-distance at which the wheel heights are measured (m),
            the one the vehicle model uses for its contact points.

        Returns
        -------
        numpy.ndarray
            Shape ``y.shape + (2,)``: left, right (m, up).

        """
        y = np.asarray(y, dtype=float)
        rise = np.interp(y, self.lateral, self.rise)[..., None]
        roll = np.interp(y, self.lateral, self.roll)[..., None]
        return rise + np.array([1.0, -1.0]) * arm * roll

    def radius_difference(self, y: ArrayLike) -> np.ndarray:
        """
        Return the rolling-radius difference r_L - r_R at y (m).

        Parameters
        ----------
        y : array_like
            Wheelset lateral displacement (m).

        Returns
        -------
        numpy.ndarray
            r_L - r_R (m), positive for y > 0 on a coned tread.

        """
        r = self._interp(y, self.rolling_radius)
        return r[..., 0] - r[..., 1]

    def equivalent_conicity(self, amplitude: float) -> float:
        """
        Return the equivalent conicity (r_L - r_R) / (2 y) at y = amplitude.

        The mean of the values at +amplitude and -amplitude is returned.

        Parameters
        ----------
        amplitude : float
            Lateral amplitude (m), 0 < amplitude <= table range.

        Returns
        -------
        float
            lambda_e (-).

        """
        y_max = float(self.lateral[-1])
        if not (math.isfinite(amplitude) and 0.0 < amplitude <= y_max):
            raise ModelError(f'conicity amplitude = {amplitude!r} m is invalid; '
                             f'allowed: 0 < amplitude <= {y_max}')
        dr = self.radius_difference(np.array([amplitude, -amplitude]))
        return float(0.5 * (dr[0] / (2.0 * amplitude) + dr[1] / (-2.0 * amplitude)))


def _rail_points(rail: Profile, rp: RailParameters, step: float) -> tuple[np.ndarray, np.ndarray,
                                                                          np.ndarray]:
    """Return the left rail surface sampled in track axes (y ascending), and u."""
    u0, u1 = rail.t_range
    u = np.arange(u0, u1 + 0.5 * step, step)
    v, _, _ = rail.evaluate(u)
    ca, sa = math.cos(rp.cant), math.sin(rp.cant)
    # Left rail: u towards +y (field side); cant rotates the top towards the centre.
    y = u * ca - v * sa
    z = u * sa + v * ca
    z = z - z.max()
    # Gauge point: innermost point at gauge_depth below the top.
    inner = y < y[np.argmax(z)]
    yi, zi = y[inner], z[inner]
    order = np.argsort(zi)
    y_gauge = np.interp(-rp.gauge_depth, zi[order], yi[order])
    y = y - y_gauge + 0.5 * rp.gauge
    if np.any(np.diff(y) <= 0.0):
        raise ModelError('rail profile is not single-valued after cant; reduce '
                         'corner_end_angle or the cant')
    return y, z, u


def _min_gap(gap: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the minimum of each row with parabolic refinement, and its fractional index."""
    n = gap.shape[1]
    i = np.argmin(gap, axis=1)
    i = np.clip(i, 1, n - 2)
    rows = np.arange(gap.shape[0])
    gm, g0, gp = gap[rows, i - 1], gap[rows, i], gap[rows, i + 1]
    den = gm - 2.0 * g0 + gp
    ok = np.isfinite(den) & (den > 0.0)
    delta = np.where(ok, 0.5 * (gm - gp) / np.where(ok, den, 1.0), 0.0)
    delta = np.clip(delta, -0.5, 0.5)
    gmin = np.where(ok, g0 - 0.25 * (gm - gp) * delta, g0)
    return gmin, i + delta


@functools.lru_cache(maxsize=8)
def contact_geometry_table(wheel: WheelParameters | None = None,
                           rail: RailParameters | None = None, *, y_max: float = 0.012,
                           n_points: int = 241, step: float = 2.0e-5) -> ContactGeometryTable:
    """
    Compute the rigid contact geometry of a wheelset on a canted track.

    For each lateral displacement y in [-y_max, y_max] the wheelset roll is
    found (Newton iteration on the difference of the two wheels' minimum
    gaps) so that both wheels touch; each minimum gap is located on finely
    sampled profiles and refined with a parabola through its neighbours.

    Parameters
    ----------
    wheel : WheelParameters, optional
        Wheel profile dimensions; defaults if omitted.
    rail : RailParameters, optional
        Rail profile dimensions and laying; defaults if omitted.
    y_max : float
        Half-range of lateral displacement (m), 0 < y_max <= 0.03.
    n_points : int
        Number of table rows (odd, so that y = 0 is a row), 11 .. 2001.
    step : float
        Sampling step of the profiles (m), 1e-6 .. 1e-4.

    Returns
    -------
    ContactGeometryTable
        The table (cached for repeated calls with the same arguments).

    Raises
    ------
    ModelError
        On invalid arguments or if the roll iteration does not converge.

    """
    wp = wheel or WheelParameters()
    rp = rail or RailParameters()
    _check_arguments(y_max, n_points, step)
    wprof = wheel_profile(wp)
    rprof = rail_profile(rp)
    y_rail, z_rail, u_rail = _rail_points(rprof, rp, 0.5 * step)
    lateral = np.linspace(-y_max, y_max, n_points)
    contact = _WheelsetOnRails(wprof, wp.taping_semi_distance, wp.nominal_radius, step,
                               lateral, y_rail, z_rail)
    phi = contact.roll()
    return _table(contact, phi, rprof, u_rail)


def _check_arguments(y_max: float, n_points: int, step: float) -> None:
    """Refuse a table range, size or sampling step out of bounds."""
    if not (math.isfinite(y_max) and 0.0 < y_max <= 0.03):
        raise ModelError(f'y_max = {y_max!r} m is invalid; allowed: 0 < y_max <= 0.03')
    if isinstance(n_points, bool) or not isinstance(n_points, int) \
            or not (11 <= n_points <= 2001 and n_points % 2 == 1):
        raise ModelError(f'n_points = {n_points!r} is invalid; allowed: odd integer 11..2001')
    if not (math.isfinite(step) and 1e-6 <= step <= 1e-4):
        raise ModelError(f'step = {step!r} m is invalid; allowed: 1e-6..1e-4')


class _WheelsetOnRails:
    """The sampled wheel surface over the sampled rails, for every lateral displacement."""

    def __init__(self, wprof: Profile, b: float, r0: float, step: float, lateral: np.ndarray,
                 y_rail: np.ndarray, z_rail: np.ndarray) -> None:
        self.wprof, self.b, self.r0, self.step = wprof, b, r0, step
        self.lateral, self.y_rail, self.z_rail = lateral, y_rail, z_rail
        y0, y1 = wprof.t_range
        self.y0 = y0
        big_y = np.arange(y0, y1 + 0.5 * step, step)
        h, _, _ = wprof.evaluate(big_y)
        # Wheel surface in wheelset axes (left wheel): lateral b + Y, height -r = h - r0.
        self.wl = b + big_y
        self.wz = h - r0

    def gaps(self, phi: np.ndarray, side: float) -> tuple[np.ndarray, np.ndarray]:
        """Return each row's minimum gap of the ``side`` wheel at roll phi, and where it is."""
        c, s = np.cos(phi)[:, None], np.sin(phi)[:, None]
        yl = side * self.wl[None, :]
        yt = self.lateral[:, None] + yl * c - self.wz[None, :] * s
        zt = yl * s + self.wz[None, :] * c
        # Rail of this side: mirror of the left rail for the right side.
        zr = np.interp(side * yt, self.y_rail, self.z_rail, left=np.nan, right=np.nan)
        gap = np.where(np.isnan(zr), np.inf, zt - zr)
        return _min_gap(gap)

    def gap_rate(self, phi: np.ndarray, index: np.ndarray, side: float) -> np.ndarray:
        """Return d(min gap)/d(roll) of the ``side`` wheel at its contact ``index``."""
        # d(min gap)/d(roll): vertical motion of the contact point minus the rail
        # slope times its lateral motion (matters in flange contact).
        big_yc = self.y0 + index * self.step
        hc, slope_c, _ = self.wprof.evaluate(big_yc)
        yl, zl = side * (self.b + big_yc), hc - self.r0
        c, s = np.cos(phi), np.sin(phi)
        track_slope = np.tan(np.arctan(side * slope_c) + phi)
        return (yl * c - zl * s) - track_slope * (-yl * s - zl * c)

    def roll(self) -> np.ndarray:
        """Return the roll at which both wheels touch (Newton on the gap difference)."""
        phi = np.zeros(len(self.lateral))
        for _ in range(50):
            d_left, i_left = self.gaps(phi, 1.0)
            d_right, i_right = self.gaps(phi, -1.0)
            f = d_left - d_right
            if np.max(np.abs(f)) < 1e-12:
                break
            phi = phi - f / (self.gap_rate(phi, i_left, 1.0) - self.gap_rate(phi, i_right, -1.0))
        else:
            raise ModelError('contact geometry: the wheelset roll iteration did not converge')
        return phi


def _table(contact: _WheelsetOnRails, phi: np.ndarray, rprof: Profile,
           u_rail: np.ndarray) -> ContactGeometryTable:
    """Return the (read-only) table of the contacts of the wheelset at roll phi."""
    wprof, b, r0, step, y0 = contact.wprof, contact.b, contact.r0, contact.step, contact.y0
    lateral, y_rail = contact.lateral, contact.y_rail
    n_points = len(lateral)
    d_left, i_left = contact.gaps(phi, 1.0)
    d_right, i_right = contact.gaps(phi, -1.0)
    zc = -0.5 * (d_left + d_right)
    pos = np.stack([y0 + i_left * step, y0 + i_right * step], axis=-1)
    _, slope, wcurv = wprof.evaluate(pos)
    radius = r0 - wprof.evaluate(pos)[0]
    # Contact angle in track axes: wheel surface slope rotated by the roll.
    angle = np.stack([np.arctan(slope[:, 0]) + phi, np.arctan(slope[:, 1]) - phi], axis=-1)
    side = np.array([1.0, -1.0])
    wl_c = side * (b + pos)
    wz_c = -radius
    contact_y = lateral[:, None] + wl_c * np.cos(phi)[:, None] - wz_c * np.sin(phi)[:, None]
    u_c = np.interp(side * contact_y, y_rail, u_rail)
    _, _, rcurv = rprof.evaluate(u_c)
    table = ContactGeometryTable(
        lateral=lateral, roll=phi, rise=zc - zc[n_points // 2],
        rolling_radius=radius, contact_angle=angle, wheel_position=pos, rail_position=u_c,
        contact_y=contact_y, wheel_curvature=wcurv, rail_curvature=-rcurv,
        nominal_radius=r0, semi_distance=b)
    # The table is cached and shared: make its arrays read-only.
    for value in vars(table).values():
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return table
