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
Sources of the compiled contact step of the multibody train (numba kernels).

:class:`ttb_sim.sim.coupling.train_track.TrainTrackCoupling` takes these, through
:func:`ttb_sim.sim.kernels.compiled`, in the lean solver variants when numba is
installed; its numpy step (the ``reference`` path, and the lean path without
numba) computes the same quantities with the same formulas, so the two agree to
round-off (tested). Each function is written as plain loops for numba; run
uncompiled they are correct but slow.

* :func:`rail_rows`: the element of each rail under each wheel, the rail-head
  rows and slopes (cubic Hermite beam, the rail head above the axis), the
  local compliance of the rail under the wheel (rows B rows^T, B the element's
  block of the inverse effective track matrix) and the element's interior
  flexibility under the wheel (:func:`ttb_sim.fe.beam.interior_compliance`).
* :func:`rail_values`: rail-head motion under the wheels from a track vector.
* :func:`rail_predictor`: the same of K^-1 rhs from the local columns of K^-1
  (the single-solve step).
* :func:`rail_load`: the track load of the wheel forces.
* :func:`rail_irregularity`: the rail irregularity under the wheels.
* :func:`contact_setup`: the step's constants of the contact iteration (the creep
  coefficients at the last step's loads, the rail's motion and velocity without
  contact force, the wheelsets' lateral predictor).
* :func:`rail_check`: the exact rail motion under the wheels after a track solve
  and its mismatch from the local model the contact iteration used.
* :func:`contact_newton`: the Newton iteration of the contact laws of every
  car (Hertz, contact geometry, Kalker's creep saturated by Shen-Hedrick-Elkins)
  on the local track model; per car 32 unknowns and one dense 32 x 32 solve
  (Gaussian elimination with partial pivoting) per iteration.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.fe.beam import interior_terms
from ttb_sim.model.wheel_rail.creep import CREEP_LOAD_EXPONENTS

COMPONENTS = 4
"""Contact force components per wheel: Fx, Fy, Fz, Mz."""
HELPERS = ('_hermite', 'interior_terms', '_interp', '_interval', '_solve_in_place',
           '_wheel_force_products', 'quintic')
"""Functions the kernels call: :func:`ttb_sim.sim.kernels.compiled` compiles them first."""
prange = range
"""The cars' loop of :func:`rail_predictor`; numba's ``prange`` once it is compiled
(:func:`ttb_sim.fe.compiled.jit`, ``parallel``). Each car's arithmetic is the same on
any thread."""


def _hermite(xi: float, length: float, derivative: int, out: np.ndarray) -> None:
    """Cubic Hermite functions (w1, w1', w2, w2') or their x-derivatives at xi."""
    xi2 = xi * xi
    xi3 = xi2 * xi
    if derivative == 0:
        out[0] = 1 - 3 * xi2 + 2 * xi3
        out[1] = (xi - 2 * xi2 + xi3) * length
        out[2] = 3 * xi2 - 2 * xi3
        out[3] = (-xi2 + xi3) * length
    elif derivative == 1:
        scale = 1.0 / length
        out[0] = (-6 * xi + 6 * xi2) * scale
        out[1] = (1 - 4 * xi + 3 * xi2) * length * scale
        out[2] = (6 * xi - 6 * xi2) * scale
        out[3] = (-2 * xi + 3 * xi2) * length * scale
    else:
        scale = 1.0 / (length * length)
        out[0] = (-6 + 12 * xi) * scale
        out[1] = (-4 + 6 * xi) * length * scale
        out[2] = (6 - 12 * xi) * scale
        out[3] = (-2 + 6 * xi) * length * scale


def rail_rows(x: np.ndarray, side: np.ndarray, start_l: np.ndarray, length_l: np.ndarray,
              dofs_l: np.ndarray, blocks_l: np.ndarray, section_l: np.ndarray,
              start_r: np.ndarray, length_r: np.ndarray, dofs_r: np.ndarray,
              blocks_r: np.ndarray, section_r: np.ndarray, arm: float,
              rows: np.ndarray, slope: np.ndarray, dofs: np.ndarray, dr: np.ndarray,
              ds: np.ndarray, interior: np.ndarray, element: np.ndarray) -> int:
    """
    Fill the rail-head rows under every wheel and the local rail compliance.

    Parameters
    ----------
    x, side : numpy.ndarray
        (n, 8) wheel positions along the track (m) and sides (+1 left rail, -1 right).
    start_l, length_l, dofs_l, blocks_l, section_l : numpy.ndarray
        Left rail: element starts and lengths (m), extended free DOFs (n_el, 12),
        compliance blocks (n_el, 12, 12), sections (n_el, 4: EA, GJ, EI_y, EI_z).
    start_r, length_r, dofs_r, blocks_r, section_r : numpy.ndarray
        The same for the right rail.
    arm : float
        Height of the rail head above the rail axis (m).
    rows, slope : numpy.ndarray
        Out, (n, 8, 3, 12): rows of the x, y, z motion of the rail head under each
        wheel over its element's 12 DOFs, and their x-derivatives.
    dofs : numpy.ndarray
        Out, (n, 8, 12) extended free DOFs of those elements.
    dr, ds : numpy.ndarray
        Out, (n, 8, 3, 3): rows B rows^T and slope B rows^T.
    interior : numpy.ndarray
        Out, (n, 8, 3, 3): the element's interior flexibility under the wheel.
    element : numpy.ndarray
        Out, (n, 8) the rail element under each wheel.

    Returns
    -------
    int
        -1, or the flat index of the first wheel that is off its rail.

    """
    n_cars, n_wheels = x.shape
    h = np.empty((3, 4))
    t = np.empty((3, 12))
    ts = np.empty((3, 12))
    w_sign = (1.0, -1.0, 1.0, -1.0)
    v_dofs = (1, 5, 7, 11)
    w_dofs = (2, 4, 8, 10)
    for c in range(n_cars):
        for k in range(n_wheels):
            if side[c, k] > 0:
                start, length, rail_dofs, blocks = start_l, length_l, dofs_l, blocks_l
                section = section_l
            else:
                start, length, rail_dofs, blocks = start_r, length_r, dofs_r, blocks_r
                section = section_r
            xx = x[c, k]
            e = np.searchsorted(start, xx, side='right') - 1
            e = min(max(e, 0), start.shape[0] - 1)
            local = xx - start[e]
            el = length[e]
            if not (local >= 0.0 and local <= el * (1 + 1e-12)):
                return c * n_wheels + k
            xi = min(max(local / el, 0.0), 1.0)
            element[c, k] = e
            flex = interior[c, k]
            flex[:, :] = 0.0
            xx, xz, yy, zz = interior_terms(xi, el, section[e, 0], section[e, 1],
                                            section[e, 2], section[e, 3], arm)
            flex[0, 0] = xx
            flex[0, 2] = xz
            flex[2, 0] = xz
            flex[1, 1] = yy
            flex[2, 2] = zz
            for d in range(3):
                _hermite(xi, el, d, h[d])
            for order in range(2):
                out = rows[c, k] if order == 0 else slope[c, k]
                out[:, :] = 0.0
                if order == 0:
                    lin0, lin1 = 1.0 - xi, xi
                else:
                    lin0, lin1 = -1.0 / el, 1.0 / el
                out[0, 0] = lin0
                out[0, 6] = lin1
                out[1, 3] = -lin0 * arm
                out[1, 9] = -lin1 * arm
                for j in range(4):
                    out[0, w_dofs[j]] = -(h[order + 1, j] * w_sign[j]) * arm
                    out[1, v_dofs[j]] = h[order, j]
                    out[2, w_dofs[j]] = h[order, j] * w_sign[j]
            for j in range(12):
                dofs[c, k, j] = rail_dofs[e, j]
            block = blocks[e]
            for i in range(3):
                for jj in range(12):
                    acc = 0.0
                    acc_s = 0.0
                    for j in range(12):
                        acc += rows[c, k, i, j] * block[j, jj]
                        acc_s += slope[c, k, i, j] * block[j, jj]
                    t[i, jj] = acc
                    ts[i, jj] = acc_s
            for i in range(3):
                for m in range(3):
                    acc = 0.0
                    acc_s = 0.0
                    for jj in range(12):
                        acc += t[i, jj] * rows[c, k, m, jj]
                        acc_s += ts[i, jj] * rows[c, k, m, jj]
                    dr[c, k, i, m] = acc
                    ds[c, k, i, m] = acc_s
    return -1


def rail_values(rows: np.ndarray, u: np.ndarray, dofs: np.ndarray, out: np.ndarray) -> None:
    """Fill out (n, 8, 3) with rows @ u at the extended free DOFs (the ground slot reads 0)."""
    n_cars, n_wheels = dofs.shape[0], dofs.shape[1]
    size = u.shape[0]
    for c in range(n_cars):
        for k in range(n_wheels):
            for i in range(3):
                acc = 0.0
                for j in range(12):
                    d = dofs[c, k, j]
                    if d < size:
                        acc += rows[c, k, i, j] * u[d]
                out[c, k, i] = acc


def rail_load(rows: np.ndarray, g: np.ndarray, dofs: np.ndarray, out: np.ndarray) -> None:
    """
    Fill out (n_free + 1,) with the track load of the wheel forces g (n, 32).

    The rails carry -rows^T (Fx, Fy, Fz) of every wheel (the force of the wheel
    on the rail); the last entry is the ground slot.
    """
    out[:] = 0.0
    n_cars, n_wheels = dofs.shape[0], dofs.shape[1]
    for c in range(n_cars):
        for k in range(n_wheels):
            for j in range(12):
                acc = 0.0
                for i in range(3):
                    acc += rows[c, k, i, j] * g[c, COMPONENTS * k + i]
                out[dofs[c, k, j]] -= acc


def rail_predictor(element: np.ndarray, side: np.ndarray, start_l: np.ndarray,
                   dofs_l: np.ndarray, values_l: np.ndarray, start_r: np.ndarray,
                   dofs_r: np.ndarray, values_r: np.ndarray, rows: np.ndarray,
                   slope: np.ndarray, rhs: np.ndarray, r_out: np.ndarray,
                   rs_out: np.ndarray) -> None:
    """
    Fill the rail-head motion and slope under the wheels of K^-1 rhs, from local columns.

    Compiled ``parallel``: the cars on two threads (measured alone on paper_ttbi's
    window: 121 -> 69 us; the cars of the contact Newton iteration were measured too
    and gained nothing).

    Parameters
    ----------
    element, side : numpy.ndarray
        (n, 8) rail element under each wheel and the wheel's side (+1 left rail).
    start_l, dofs_l, values_l, start_r, dofs_r, values_r : numpy.ndarray
        Per rail: node i's K^-1 columns (its 6 DOFs) are ``values[start[i]:start[i + 1]]``
        ((nnz, 6)) on the free DOFs ``dofs[start[i]:start[i + 1]]``.
    rows, slope : numpy.ndarray
        (n, 8, 3, 12) rail-head rows and slopes.
    rhs : numpy.ndarray
        (n_free,) the right-hand side.
    r_out, rs_out : numpy.ndarray
        Out, (n, 8, 3).

    """
    n_cars, n_wheels = element.shape
    for c in prange(n_cars):
        zb = np.empty(12)
        for k in range(n_wheels):
            if side[c, k] > 0:
                start, dofs, values = start_l, dofs_l, values_l
            else:
                start, dofs, values = start_r, dofs_r, values_r
            e = element[c, k]
            for a in range(2):
                node = e + a
                for d in range(6):
                    zb[6 * a + d] = 0.0
                for t in range(start[node], start[node + 1]):
                    value = rhs[dofs[t]]
                    for d in range(6):
                        zb[6 * a + d] += values[t, d] * value
            for i in range(3):
                acc = 0.0
                acc_s = 0.0
                for j in range(12):
                    acc += rows[c, k, i, j] * zb[j]
                    acc_s += slope[c, k, i, j] * zb[j]
                r_out[c, k, i] = acc
                rs_out[c, k, i] = acc_s


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


def _wheel_force_products(a: np.ndarray, b: np.ndarray, g: np.ndarray, c: int, k: int,
                          i: int) -> tuple[float, float]:
    """Return row i of wheel k's 3 x 3 blocks a and b (car c) times its (Fx, Fy, Fz) in g."""
    o = COMPONENTS * k
    acc_a = 0.0
    acc_b = 0.0
    for j in range(3):
        acc_a += a[c, k, i, j] * g[c, o + j]
        acc_b += b[c, k, i, j] * g[c, o + j]
    return acc_a, acc_b


def rail_check(rows: np.ndarray, slope: np.ndarray, u: np.ndarray, dofs: np.ndarray,
               r0p: np.ndarray, offset: np.ndarray, dr: np.ndarray, ds: np.ndarray,
               g: np.ndarray, rs_star: np.ndarray, slope_offset: np.ndarray, single: bool,
               r_exact: np.ndarray, mismatch: np.ndarray,
               slope_mismatch: np.ndarray) -> float:
    """
    Compare the exact rail motion under the wheels with the contact iteration's local model.

    The model is r = r0p + offset - dr g (and, for the single-solve step, the slope
    rs_star + slope_offset - ds g).

    Parameters
    ----------
    rows, slope : numpy.ndarray
        (n, 8, 3, 12) rail-head rows and slopes.
    u : numpy.ndarray
        (n_free,) the track's end-of-step displacement.
    dofs : numpy.ndarray
        (n, 8, 12) the extended free DOFs of the rows (n_free: the ground slot).
    r0p, offset : numpy.ndarray
        (n, 8, 4) rail-head motion without contact force and the offset of the model.
    dr, ds : numpy.ndarray
        (n, 8, 3, 3) local rail compliance of the motion and the slope.
    g : numpy.ndarray
        (n, 32) the contact forces.
    rs_star, slope_offset : numpy.ndarray
        (n, 8, 3) the predictor's rail slope and the slope model's offset.
    single : bool
        The single-solve step: its slope mismatch is filled and every component
        counts; otherwise the slope mismatch is zero and only the vertical counts.
    r_exact, mismatch, slope_mismatch : numpy.ndarray
        Out, (n, 8, 3): exact rail-head motion, its mismatch from the model and the
        slope's.

    Returns
    -------
    float
        The largest mismatch that counts (m); infinite when one is not a number.

    """
    n_cars, n_wheels = dofs.shape[0], dofs.shape[1]
    size = u.shape[0]
    worst = 0.0
    for c in range(n_cars):
        for k in range(n_wheels):
            for i in range(3):
                acc = 0.0
                acc_s = 0.0
                for j in range(12):
                    d = dofs[c, k, j]
                    if d < size:
                        acc += rows[c, k, i, j] * u[d]
                        acc_s += slope[c, k, i, j] * u[d]
                model, model_s = _wheel_force_products(dr, ds, g, c, k, i)
                r_exact[c, k, i] = acc
                miss = acc - ((r0p[c, k, i] + offset[c, k, i]) - model)
                mismatch[c, k, i] = miss
                if single:
                    slope_mismatch[c, k, i] = acc_s - (
                        (rs_star[c, k, i] + slope_offset[c, k, i]) - model_s)
                else:
                    slope_mismatch[c, k, i] = 0.0
                if single or i == 2:
                    size_miss = abs(miss)
                    if not size_miss <= worst:
                        worst = size_miss if size_miss == size_miss else math.inf
    return worst


def rail_irregularity(x: np.ndarray, side: np.ndarray, x_start: float, dx: float,
                      values: np.ndarray, slopes: np.ndarray, curvatures: np.ndarray,
                      slack: float, z: np.ndarray, y: np.ndarray, dy: np.ndarray) -> None:
    """
    Fill the vertical and lateral irregularity and lateral slope of each wheel's rail.

    The quintic Hermite interpolation of :meth:`TrackIrregularity.sample` on the
    grid (x_start, dx) of ``values``, ``slopes``, ``curvatures`` ((4, N): z_left,
    z_right, y_left, y_right); zero outside the grid (beyond ``slack`` grid steps).
    """
    last = values.shape[1] - 1
    n_cars, n_wheels = x.shape
    for c in range(n_cars):
        for k in range(n_wheels):
            s = (x[c, k] - x_start) / dx
            if not (s >= -slack and s <= last + slack):
                z[c, k] = 0.0
                y[c, k] = 0.0
                dy[c, k] = 0.0
                continue
            i = int(min(max(math.floor(s), 0), last - 1))
            t = s - i
            left = side[c, k] > 0
            for q in range(2):
                row = (0 if left else 1) if q == 0 else (2 if left else 3)
                p0 = values[row, i]
                m0 = dx * slopes[row, i]
                a2, a3, a4, a5 = quintic(p0, values[row, i + 1], m0, dx * slopes[row, i + 1],
                                         dx * dx * curvatures[row, i],
                                         dx * dx * curvatures[row, i + 1])
                value = p0 + t * (m0 + t * (a2 + t * (a3 + t * (a4 + t * a5))))
                if q == 0:
                    z[c, k] = value
                else:
                    y[c, k] = value
                    dy[c, k] = (m0 + t * (2.0 * a2 + t * (3.0 * a3 + t * (
                        4.0 * a4 + t * 5.0 * a5)))) / dx


def quintic(p0: float, p1: float, m0: float, m1: float, c0: float,
            c1: float) -> tuple[float, float, float, float]:
    """
    Return (a2, a3, a4, a5) of the quintic Hermite on [0, 1] through value p, slope m, curvature c.

    p(t) = p0 + m0 t + a2 t^2 + ... + a5 t^5, the arithmetic of
    :meth:`ttb_sim.model.irregularity.profile.TrackIrregularity.sample`.
    """
    a2 = 0.5 * c0
    d0 = p1 - (p0 + m0 + a2)
    d1 = m1 - (m0 + c0)
    d2 = c1 - c0
    return (a2, 10.0 * d0 - 4.0 * d1 + 0.5 * d2, -15.0 * d0 + 7.0 * d1 - d2,
            6.0 * d0 - 3.0 * d1 + 0.5 * d2)


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
            for i in range(m):
                acc = 0.0
                for j in range(m):
                    acc += dw[i, j] * g[c, j]
                w[i] = w0[c, i] + acc
                wv[i] = wv0[c, i] + a1 * acc
            for k in range(n_wheels):
                o = COMPONENTS * k
                for i in range(3):
                    acc, acc_v = _wheel_force_products(dr, rvel, g, c, k, i)
                    rp = r0p[c, k, i] + offset[c, k, i]
                    rvp = rv0[c, k, i] + a1 * offset[c, k, i] + speed * slope_offset[c, k, i]
                    r[o + i] = rp - acc
                    rv[o + i] = rvp - acc_v
                r[o + 3] = r0p[c, k, 3] + offset[c, k, 3]
                rv[o + 3] = rv0[c, k, 3] + a1 * offset[c, k, 3]
            for k in range(n_wheels):
                o = COMPONENTS * k
                s = side[c, k]
                acc = 0.0
                for j in range(m):
                    acc += ey[k, j] * g[c, j]
                y = y_star[c, k] + acc - r[o + 1] - irr_y[c, k]
                y_rel[c, k] = y
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
                height_slope = (height[1] - height[2]) / (2 * step)
                tan_slope = (math.tan(angle[1]) - math.tan(angle[2])) / (2 * step)
                cosg = math.cos(angle[0])
                sing = math.sin(angle[0])
                tang = math.tan(angle[0])
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
                delta = r[o + 2] + irr_z[c, k] - w[o + 2] + height[0]
                compression[c, k] = delta
                positive = max(delta, 0.0)
                fz = (positive / g_hertz) ** 1.5
                kh = 1.5 * math.sqrt(positive) / g15
                xi_x = (wv[o] - rv[o]) / speed + 1.0 - radius[0] / r0
                xi_y = (wv[o + 1] - rv[o + 1] - speed * irr_dy[c, k]) / speed - w[o + 3]
                xi_sp = wv[o + 3] * cosg / speed - s * sing / r0
                c11, c22 = creep[0, c, k], creep[1, c, k]
                c23, c33 = creep[2, c, k], creep[3, c, k]
                lin_x = -c11 * xi_x
                lin_y = -(c22 * xi_y + c23 * xi_sp)
                lin_m = c23 * xi_y - c33 * xi_sp
                # Shen-Hedrick-Elkins saturation and the gradient of its factor.
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
                saturation[c, k] = eps
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
            _solve_in_place(a, b)
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


def _solve_in_place(a: np.ndarray, b: np.ndarray) -> None:
    """Overwrite b with a^-1 b (Gaussian elimination, partial pivoting); a is destroyed."""
    n = b.shape[0]
    for col in range(n):
        pivot = col
        best = abs(a[col, col])
        for i in range(col + 1, n):
            if abs(a[i, col]) > best:
                best = abs(a[i, col])
                pivot = i
        if pivot != col:
            for j in range(col, n):
                tmp = a[col, j]
                a[col, j] = a[pivot, j]
                a[pivot, j] = tmp
            tmp = b[col]
            b[col] = b[pivot]
            b[pivot] = tmp
        inv = 1.0 / a[col, col]
        for i in range(col + 1, n):
            factor = a[i, col] * inv
            if factor != 0.0:
                for j in range(col + 1, n):
                    a[i, j] -= factor * a[col, j]
                b[i] -= factor * b[col]
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= a[i, j] * b[j]
        b[i] = acc / a[i, i]
