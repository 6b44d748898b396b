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
The rail under the multibody cars' wheels, compiled (numba sources).

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
* :func:`rail_check`: the exact rail motion under the wheels after a track solve
  and its mismatch from the local model the contact iteration used.

Each function is written as plain loops for numba; run uncompiled it is correct
but slow. Their test oracle is the numpy step of ``test/sim/contact_oracle.py``,
which evaluates the same quantities with :mod:`ttb_sim.fe.beam` and the
irregularity's own sampler.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.fe.beam import interior_terms
from ttb_sim.sim.coupling.profile_kernels import quintic

COMPONENTS = 4
"""Contact force components per wheel: Fx, Fy, Fz, Mz."""
HELPERS = ('_hermite', '_head_rows', '_interior_block', '_local_compliance', 'interior_terms',
           'quintic', 'wheel_force_products')
"""Functions the kernels call: :func:`ttb_sim.fe.compiled.jit` compiles them first."""
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
            _interior_block(xi, el, section[e], arm, interior[c, k])
            for d in range(3):
                _hermite(xi, el, d, h[d])
            _head_rows(xi, el, arm, h, rows[c, k], slope[c, k])
            for j in range(12):
                dofs[c, k, j] = rail_dofs[e, j]
            _local_compliance(rows[c, k], slope[c, k], blocks[e], t, ts, dr[c, k], ds[c, k])
    return -1


def _interior_block(xi: float, el: float, section: np.ndarray, arm: float,
                    flex: np.ndarray) -> None:
    """Fill the 3 x 3 interior flexibility of an element at xi (:func:`interior_terms`)."""
    flex[:, :] = 0.0
    xx, xz, yy, zz = interior_terms(xi, el, section[0], section[1], section[2], section[3], arm)
    flex[0, 0] = xx
    flex[0, 2] = xz
    flex[2, 0] = xz
    flex[1, 1] = yy
    flex[2, 2] = zz


def _head_rows(xi: float, el: float, arm: float, h: np.ndarray, rows: np.ndarray,
               slope: np.ndarray) -> None:
    """
    Fill the rail head's rows (3, 12) over its element's DOFs and their x-derivatives.

    ``h`` holds the Hermite functions at xi and their first two derivatives
    (:func:`_hermite`); the head sits ``arm`` above the rail's axis.
    """
    w_sign = (1.0, -1.0, 1.0, -1.0)
    v_dofs = (1, 5, 7, 11)
    w_dofs = (2, 4, 8, 10)
    for order in range(2):
        out = rows if order == 0 else slope
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


def _local_compliance(rows: np.ndarray, slope: np.ndarray, block: np.ndarray, t: np.ndarray,
                      ts: np.ndarray, dr: np.ndarray, ds: np.ndarray) -> None:
    """Fill dr = rows B rows^T and ds = slope B rows^T (3 x 3); t, ts are work arrays."""
    for i in range(3):
        for jj in range(12):
            acc = 0.0
            acc_s = 0.0
            for j in range(12):
                acc += rows[i, j] * block[j, jj]
                acc_s += slope[i, j] * block[j, jj]
            t[i, jj] = acc
            ts[i, jj] = acc_s
    for i in range(3):
        for m in range(3):
            acc = 0.0
            acc_s = 0.0
            for jj in range(12):
                acc += t[i, jj] * rows[m, jj]
                acc_s += ts[i, jj] * rows[m, jj]
            dr[i, m] = acc
            ds[i, m] = acc_s


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


def wheel_force_products(a: np.ndarray, b: np.ndarray, g: np.ndarray, c: int, k: int,
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
                model, model_s = wheel_force_products(dr, ds, g, c, k, i)
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
