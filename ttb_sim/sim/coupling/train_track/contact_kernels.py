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
The contact iteration of the multibody cars, compiled (numba sources).

* :func:`contact_setup`: the step's constants of the contact iteration (the creep
  coefficients at the last step's loads, the rail's motion and velocity without
  contact force, the wheelsets' lateral predictor).
* :func:`contact_newton`: the Newton iteration of the contact laws of every
  car (Hertz, contact geometry, Kalker's creep saturated by Shen-Hedrick-Elkins)
  on the local track model; per car 32 unknowns and one dense 32 x 32 solve
  (Gaussian elimination with partial pivoting) per iteration.

Each function is written as plain loops for numba; run uncompiled it is correct
but slow. Its test oracle is the numpy step of ``test/sim/contact_oracle.py``,
which evaluates the same laws with the vectorised functions of
:mod:`ttb_sim.model.wheel_rail`.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.fe.dense_kernels import solve_in_place
from ttb_sim.model.wheel_rail.creep import CREEP_LOAD_EXPONENTS
from ttb_sim.sim.coupling.train_track.rail_kernels import COMPONENTS, wheel_force_products

HELPERS = ('_car_motion', '_interp', '_interval', '_sensitivities', '_she_factor',
           'solve_in_place', '_wheel_equations', '_wheel_geometry', 'wheel_force_products')
"""Functions the kernels call: :func:`ttb_sim.fe.compiled.jit` compiles them first."""


def contact_setup(force: np.ndarray, creep0: np.ndarray, p0: float, r_star: np.ndarray,
                  rs_star: np.ndarray, r_hist: np.ndarray, interior_r: np.ndarray,
                  interior_v: np.ndarray, dr: np.ndarray, ds: np.ndarray, a1: float,
                  speed: float,
                  q_star: np.ndarray, wheelset_y: np.ndarray, creep: np.ndarray,
                  r0p: np.ndarray, rv0: np.ndarray, rvel: np.ndarray,
                  y_star: np.ndarray) -> None:
    """
    Fill the constants of one step's contact iteration.

    Parameters
    ----------
    force : numpy.ndarray
        (n, 8, 4) the last step's contact forces (their Fz scales the creep coefficients).
    creep0 : numpy.ndarray
        (4,) Kalker's f11, f22, f23, f33 at the reference load, scaled with the
        load by CREEP_LOAD_EXPONENTS (:func:`scaled_creep_coefficients`).
    p0 : float
        The reference load (N).
    r_star, rs_star, r_hist : numpy.ndarray
        (n, 8, 3) rail-head motion and slope of the predictor under each wheel, and
        the rail rows applied to the velocity history.
    interior_r, interior_v : numpy.ndarray
        (n, 8, 3) the last step's interior deflection of the rail element under each
        wheel and its velocity (the trapezoidal rule continues it: its end-of-step
        velocity is a1 (r_i - interior_r) - interior_v).
    dr, ds : numpy.ndarray
        (n, 8, 3, 3) local rail compliance of the motion (the interior flexibility
        included) and the slope.
    a1, speed : float
        2 / dt (1/s) and the train speed (m/s).
    q_star : numpy.ndarray
        (n, 42) the cars' predictor.
    wheelset_y : numpy.ndarray
        (8,) the car DOF of each wheel's wheelset lateral displacement.
    creep : numpy.ndarray
        Out, (4, n, 8): f11, f22, f23, f33 of every wheel.
    r0p, rv0 : numpy.ndarray
        Out, (n, 8, 4): rail-head motion and velocity without contact force (the
        fourth slot zero).
    rvel : numpy.ndarray
        Out, (n, 8, 3, 3): a1 dr + speed ds.
    y_star : numpy.ndarray
        Out, (n, 8): wheelset lateral displacement of the predictor.

    """
    n_cars, n_wheels = r_star.shape[0], r_star.shape[1]
    for c in range(n_cars):
        for k in range(n_wheels):
            ratio = max(force[c, k, 2], 0.0) / p0
            for t in range(4):
                creep[t, c, k] = creep0[t] * ratio ** CREEP_LOAD_EXPONENTS[t]
            y_star[c, k] = q_star[c, wheelset_y[k]]
            for i in range(3):
                r0p[c, k, i] = r_star[c, k, i]
                rv0[c, k, i] = (a1 * r_star[c, k, i] + r_hist[c, k, i] + speed * rs_star[c, k, i]
                                - a1 * interior_r[c, k, i] - interior_v[c, k, i])
                for j in range(3):
                    rvel[c, k, i, j] = a1 * dr[c, k, i, j] + speed * ds[c, k, i, j]
            r0p[c, k, 3] = 0.0
            rv0[c, k, 3] = 0.0


def contact_newton(g: np.ndarray, w0: np.ndarray, wv0: np.ndarray, r0p: np.ndarray,
                   rv0: np.ndarray, offset: np.ndarray, slope_offset: np.ndarray,
                   dw: np.ndarray, dr: np.ndarray, rvel: np.ndarray,
                   ey: np.ndarray, y_star: np.ndarray, irr_y: np.ndarray, irr_z: np.ndarray,
                   irr_dy: np.ndarray, side: np.ndarray, creep: np.ndarray, lateral: np.ndarray,
                   radius_table: np.ndarray, angle_table: np.ndarray, rise: np.ndarray,
                   roll: np.ndarray, arm: float, conicity: float, r0: float, g_hertz: float,
                   friction: float, a1: float, speed: float, step: float, tol: float,
                   max_iter: int, y_rel: np.ndarray, compression: np.ndarray,
                   saturation: np.ndarray) -> tuple[int, float]:
    """
    Solve the contact laws of every car on the local track model (Newton, in place on g).

    The quantities are those of :meth:`TrainTrackCoupling.step`: per car the end-of-step
    wheel motion w = w0 + Dw g (velocity wv0 + a1 Dw g), the rail-head motion under
    each wheel r = r0p + offset - Dr g (velocity rv0 + a1 offset + V slope_offset - Rv g,
    Dr and Rv 3 x 3 per wheel), the
    wheelset lateral position y* + Ey g; the contact geometry from the profile table
    (``lateral`` not empty) or the equivalent cone (``conicity``).

    Parameters
    ----------
    g : numpy.ndarray
        (n, 32) contact forces (Fx, Fy, Fz, Mz per wheel): the start, then the solution.
    w0, wv0 : numpy.ndarray
        (n, 32) wheel contact-point motion and velocity without contact force.
    r0p, rv0 : numpy.ndarray
        (n, 8, 4) rail-head motion and velocity under each wheel without contact
        force (x, y, z; the fourth slot is zero).
    offset, slope_offset : numpy.ndarray
        (n, 8, 4) and (n, 8, 3): the corrections of the local rail model (motion,
        and slope for the velocity; zero for the two-solve step).
    dw : numpy.ndarray
        (32, 32) wheel compliance of a car: w = w0 + dw g.
    dr, rvel : numpy.ndarray
        (n, 8, 3, 3) rail compliance under each wheel for the motion and the
        velocity (a1 Dr + V Ds).
    ey : numpy.ndarray
        (8, 32) wheelset lateral displacement per contact force.
    y_star : numpy.ndarray
        (n, 8) wheelset lateral displacement without contact force (m).
    irr_y, irr_z, irr_dy : numpy.ndarray
        (n, 8) lateral and vertical irregularity and lateral slope under each wheel.
    side : numpy.ndarray
        (n, 8) +1 for a left wheel, -1 for a right one.
    creep : numpy.ndarray
        (4, n, 8) Kalker's creep coefficients f11, f22, f23, f33.
    lateral, radius_table, angle_table, rise, roll : numpy.ndarray
        Profile contact-geometry table (:class:`ContactGeometryTable` columns);
        ``lateral`` empty for the equivalent cone.
    arm : float
        Lateral semi-distance of the contact points (m), for the wheel heights.
    conicity : float
        Equivalent conicity (used without a table).
    r0, g_hertz, friction : float
        Nominal wheel radius (m), Hertz constant (m/N^(2/3)), friction coefficient.
    a1, speed : float
        2 / dt (1/s) and the train speed (m/s).
    step : float
        Lateral step of the central differences of the geometry (m).
    tol : float
        Convergence tolerance on the change of a compression (m).
    max_iter : int
        Iterations allowed.
    y_rel, compression, saturation : numpy.ndarray
        Out, (n, 8): wheelset position relative to the rail, Hertz compression and
        the creep saturation factor at the last iterate.

    Returns
    -------
    (iterations, change)
        Iterations taken and the last largest change of a compression (m); the
        iteration converged when change < tol.

    """
    n_cars, m = g.shape
    n_wheels = m // COMPONENTS
    w = np.empty(m)
    wv = np.empty(m)
    r = np.empty(m)
    rv = np.empty(m)
    d_delta = np.empty((n_wheels, m))
    d_yrel = np.empty(m)
    d_xi_x = np.empty(m)
    d_xi_y = np.empty(m)
    d_xi_sp = np.empty(m)
    a = np.empty((m, m))
    b = np.empty(m)
    radius = np.empty(3)
    angle = np.empty(3)
    height = np.empty(3)
    use_table = lateral.shape[0] > 0
    cone_angle = math.atan(conicity)
    g15 = g_hertz ** 1.5
    iterations = 0
    change = math.inf
    while iterations < max_iter:
        iterations += 1
        change = 0.0
        for c in range(n_cars):
            _car_motion(c, g, w0, wv0, r0p, rv0, offset, slope_offset, dw, dr, rvel, a1, speed,
                        w, wv, r, rv)
            for k in range(n_wheels):
                o = COMPONENTS * k
                s = side[c, k]
                acc = 0.0
                for j in range(m):
                    acc += ey[k, j] * g[c, j]
                y = y_star[c, k] + acc - r[o + 1] - irr_y[c, k]
                y_rel[c, k] = y
                _wheel_geometry(y, s, use_table, lateral, radius_table, angle_table, rise, roll,
                                arm, conicity, cone_angle, r0, step, radius, angle, height)
                height_slope = (height[1] - height[2]) / (2 * step)
                tan_slope = (math.tan(angle[1]) - math.tan(angle[2])) / (2 * step)
                cosg = math.cos(angle[0])
                _sensitivities(c, k, dw, dr, rvel, ey, a1, speed, cosg, height_slope, d_delta,
                               d_yrel, d_xi_x, d_xi_y, d_xi_sp)
                delta = r[o + 2] + irr_z[c, k] - w[o + 2] + height[0]
                compression[c, k] = delta
                saturation[c, k] = _wheel_equations(
                    c, k, s, g, w, wv, r, rv, delta, radius[0], angle[0], tan_slope,
                    irr_dy[c, k], creep, d_delta, d_yrel, d_xi_x, d_xi_y, d_xi_sp, r0, g_hertz,
                    g15, friction, speed, a, b)
            if not solve_in_place(a, b):
                b[:] = np.nan   # a singular Newton system: the divergence check stops the run
            for j in range(m):
                g[c, j] += b[j]
            for k in range(n_wheels):
                acc = 0.0
                for j in range(m):
                    acc += d_delta[k, j] * b[j]
                change = max(change, abs(acc))
        if change < tol:
            break
    return iterations, change


def _car_motion(c: int, g: np.ndarray, w0: np.ndarray, wv0: np.ndarray, r0p: np.ndarray,
                rv0: np.ndarray, offset: np.ndarray, slope_offset: np.ndarray, dw: np.ndarray,
                dr: np.ndarray, rvel: np.ndarray, a1: float, speed: float, w: np.ndarray,
                wv: np.ndarray, r: np.ndarray, rv: np.ndarray) -> None:
    """
    Fill car c's wheel motion w, wv and the rail's under its wheels r, rv (m) at forces g.

    The affine maps of :func:`contact_newton`: w = w0 + Dw g (velocity
    wv0 + a1 Dw g), r = r0p + offset - Dr g (velocity rv0 + a1 offset +
    V slope_offset - Rv g).
    """
    m = g.shape[1]
    for i in range(m):
        acc = 0.0
        for j in range(m):
            acc += dw[i, j] * g[c, j]
        w[i] = w0[c, i] + acc
        wv[i] = wv0[c, i] + a1 * acc
    for k in range(m // COMPONENTS):
        o = COMPONENTS * k
        for i in range(3):
            acc, acc_v = wheel_force_products(dr, rvel, g, c, k, i)
            rp = r0p[c, k, i] + offset[c, k, i]
            rvp = rv0[c, k, i] + a1 * offset[c, k, i] + speed * slope_offset[c, k, i]
            r[o + i] = rp - acc
            rv[o + i] = rvp - acc_v
        r[o + 3] = r0p[c, k, 3] + offset[c, k, 3]
        rv[o + 3] = rv0[c, k, 3] + a1 * offset[c, k, 3]


def _wheel_geometry(y: float, s: float, use_table: bool, lateral: np.ndarray,
                    radius_table: np.ndarray, angle_table: np.ndarray, rise: np.ndarray,
                    roll: np.ndarray, arm: float, conicity: float, cone_angle: float, r0: float,
                    step: float, radius: np.ndarray, angle: np.ndarray,
                    height: np.ndarray) -> None:
    """
    Fill a wheel's rolling radius, contact angle and rigid-contact height at y, y +/- step.

    From the profile table (``use_table``) or the equivalent cone; ``s`` is the
    wheel's side (+1 left).
    """
    col = 0 if s > 0 else 1
    sign = 1.0 if s > 0 else -1.0
    for p in range(3):
        yp = y if p == 0 else (y + step if p == 1 else y - step)
        if use_table:
            j0 = _interval(yp, lateral)
            radius[p] = _interp(yp, lateral, j0, radius_table[:, col])
            angle[p] = _interp(yp, lateral, j0, angle_table[:, col])
            height[p] = (_interp(yp, lateral, j0, rise)
                         + sign * arm * _interp(yp, lateral, j0, roll))
        else:
            radius[p] = r0 + sign * conicity * yp
            angle[p] = cone_angle
            height[p] = radius[p] - r0


def _sensitivities(c: int, k: int, dw: np.ndarray, dr: np.ndarray, rvel: np.ndarray,
                   ey: np.ndarray, a1: float, speed: float, cosg: float, height_slope: float,
                   d_delta: np.ndarray, d_yrel: np.ndarray, d_xi_x: np.ndarray,
                   d_xi_y: np.ndarray, d_xi_sp: np.ndarray) -> None:
    """Fill wheel k's derivatives of compression, lateral shift and creepages in g."""
    m = dw.shape[0]
    o = COMPONENTS * k
    for j in range(m):
        d_yrel[j] = ey[k, j]
        d_delta[k, j] = -dw[o + 2, j]
        d_xi_x[j] = a1 * dw[o, j]
        d_xi_y[j] = a1 * dw[o + 1, j]
        d_xi_sp[j] = a1 * dw[o + 3, j] * cosg / speed
    for j in range(3):
        d_yrel[o + j] += dr[c, k, 1, j]
        d_delta[k, o + j] -= dr[c, k, 2, j]
        d_xi_x[o + j] += rvel[c, k, 0, j]
        d_xi_y[o + j] += rvel[c, k, 1, j]
    for j in range(m):
        d_delta[k, j] += height_slope * d_yrel[j]
        d_xi_x[j] /= speed
        d_xi_y[j] = d_xi_y[j] / speed - dw[o + 3, j]


def _she_factor(lin_x: float, lin_y: float, fz: float,
                friction: float) -> tuple[float, float, float, float]:
    """
    Return the Shen-Hedrick-Elkins factor and its derivatives in Fx, Fy and N.

    The scalar form of :func:`ttb_sim.model.wheel_rail.creep.she_saturation` and
    :func:`~ttb_sim.model.wheel_rail.creep.she_factor_gradient` (0 out of contact).
    """
    f = math.hypot(lin_x, lin_y)
    limit = friction * fz
    eps = 0.0
    e_x = 0.0
    e_y = 0.0
    e_n = 0.0
    if limit > 0.0:
        beta = f / limit
        ratio = beta - beta * beta / 3.0 + beta ** 3 / 27.0 if beta <= 3.0 else 1.0
        eps = limit * ratio / f if f > 0.0 else 1.0
        if f > 0.0:
            slope = (-1.0 / 3.0 + 2.0 * beta / 27.0 if beta <= 3.0
                     else -1.0 / beta ** 2)
            per_force = slope / (f * limit)
            e_x = per_force * lin_x
            e_y = per_force * lin_y
            e_n = -slope * beta / fz
    return eps, e_x, e_y, e_n


def _wheel_equations(c: int, k: int, s: float, g: np.ndarray, w: np.ndarray, wv: np.ndarray,
                     r: np.ndarray, rv: np.ndarray, delta: float, radius: float, angle: float,
                     tan_slope: float, irr_dy: float, creep: np.ndarray, d_delta: np.ndarray,
                     d_yrel: np.ndarray, d_xi_x: np.ndarray, d_xi_y: np.ndarray,
                     d_xi_sp: np.ndarray, r0: float, g_hertz: float, g15: float,
                     friction: float, speed: float, a: np.ndarray, b: np.ndarray) -> float:
    """
    Fill wheel k's four rows of the Newton system (I - J) dg = target - g; return its SHE factor.

    Hertz's normal force on the compression ``delta``, Kalker's linear creep forces
    on the creepages saturated by Shen-Hedrick-Elkins, the lateral force's
    contact-angle part, and their derivatives in g.
    """
    m = g.shape[1]
    o = COMPONENTS * k
    cosg = math.cos(angle)
    sing = math.sin(angle)
    tang = math.tan(angle)
    positive = max(delta, 0.0)
    fz = (positive / g_hertz) ** 1.5
    kh = 1.5 * math.sqrt(positive) / g15
    xi_x = (wv[o] - rv[o]) / speed + 1.0 - radius / r0
    xi_y = (wv[o + 1] - rv[o + 1] - speed * irr_dy) / speed - w[o + 3]
    xi_sp = wv[o + 3] * cosg / speed - s * sing / r0
    c11, c22 = creep[0, c, k], creep[1, c, k]
    c23, c33 = creep[2, c, k], creep[3, c, k]
    lin_x = -c11 * xi_x
    lin_y = -(c22 * xi_y + c23 * xi_sp)
    lin_m = c23 * xi_y - c33 * xi_sp
    eps, e_x, e_y, e_n = _she_factor(lin_x, lin_y, fz, friction)
    for j in range(m):
        d_lin_x = -c11 * d_xi_x[j]
        d_lin_y = -c22 * d_xi_y[j] - c23 * d_xi_sp[j]
        d_lin_m = c23 * d_xi_y[j] - c33 * d_xi_sp[j]
        d_eps = e_x * d_lin_x + e_y * d_lin_y + e_n * kh * d_delta[k, j]
        a[o, j] = -(eps * d_lin_x + lin_x * d_eps)
        a[o + 1, j] = -(eps * d_lin_y + lin_y * d_eps
                        - s * tang * kh * d_delta[k, j]
                        - s * tan_slope * fz * d_yrel[j])
        a[o + 2, j] = -(kh * d_delta[k, j])
        a[o + 3, j] = -(eps * d_lin_m + lin_m * d_eps)
    a[o, o] += 1.0
    a[o + 1, o + 1] += 1.0
    a[o + 2, o + 2] += 1.0
    a[o + 3, o + 3] += 1.0
    b[o] = lin_x * eps - g[c, o]
    b[o + 1] = lin_y * eps - s * tang * fz - g[c, o + 1]
    b[o + 2] = fz - g[c, o + 2]
    b[o + 3] = lin_m * eps - g[c, o + 3]
    return eps


def _interp(y: float, grid: np.ndarray, j: int, column: np.ndarray) -> float:
    """Linear interpolation of ``column`` at y in the interval j of ``grid`` (np.interp)."""
    if j < 0:
        return column[0]
    if j >= grid.shape[0] - 1:
        return column[grid.shape[0] - 1]
    slope = (column[j + 1] - column[j]) / (grid[j + 1] - grid[j])
    return slope * (y - grid[j]) + column[j]


def _interval(y: float, grid: np.ndarray) -> int:
    """Return j with grid[j] <= y < grid[j + 1]; -1 below the grid, n - 1 at or above its end."""
    if y < grid[0]:
        return -1
    if y >= grid[grid.shape[0] - 1]:
        return grid.shape[0] - 1
    return int(np.searchsorted(grid, y, side='right')) - 1
