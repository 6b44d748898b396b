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
Compiled kernels (numba) of the quarter-car step on the girder Green's function.

:class:`~ttb_sim.sim.coupling.quarter_car.QuarterCarCoupling` takes them for
the solver variants other than ``reference`` when numba imports; they compute
the numbers of its numpy path (:meth:`QuarterCarCoupling.step` with the
Green's function) with the same equations, axle by axle instead of array by
array, so the two agree to rounding (``test/sim/test_quarter_car_kernels.py``).
A step then costs three kernel calls and the integrator's two sparse solves,
instead of some sixty small numpy operations.

The kernels, in the order of a step:

1. :func:`_centreline_profile`: the vertical irregularity under each wheel
   (the quintic Hermite interpolation of
   :meth:`ttb_sim.model.irregularity.TrackIrregularity.sample` with
   ``outside='zero'``, averaged over the two rails);
2. :func:`_wheel_terms`: each wheel's element, Hermite rows, the affine
   contact law ``R_i = w_i . u_{n+1} + b_i`` and the wheel loads added to the
   effective right-hand side;
3. :func:`_green_correction`: the m x m Woodbury system on the girder
   Green's function, its solution's wheel loads taken off the right-hand side;
4. :func:`_update_cars`: the sprung-mass state and the contact forces from the
   solved girder displacement.

They are compiled on first use (a few seconds, cached on disk where the package
directory is writable).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ttb_sim.fe.dense_kernels import solve_in_place
from ttb_sim.sim.coupling.profile_kernels import quintic
from ttb_sim.sim.integrators.interior_kernels import interior_finish, interior_load
from ttb_sim.sim.integrators.newmark_kernels import (effective_load, finish_into, history,
                                                     largest_magnitude, solve_ldl)
from ttb_sim.sim.kernel_registry import KernelTable

HELPERS = ('quintic', '_centreline_profile', '_wheel_terms', '_green_correction',
           '_update_cars', 'history', 'effective_load', 'solve_ldl', 'finish_into',
           'largest_magnitude', 'solve_in_place', 'interior_load', 'interior_finish')
"""Functions the kernels call: :func:`ttb_sim.fe.compiled.jit` compiles them first."""


def _centreline_profile(x: np.ndarray, x_start: float, dx: float, values: np.ndarray,
                        slopes: np.ndarray, curvatures: np.ndarray, slack: float,
                        r: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> None:
    """
    Write the centreline vertical irregularity r, dr/dx, d2r/dx2 at ``x`` into r, r1, r2.

    The mean of rails 0 and 1 of ``values``/``slopes``/``curvatures`` (4, N),
    zero outside the profile.
    """
    last = values.shape[1] - 1
    h = dx
    for q in range(x.shape[0]):
        s = (x[q] - x_start) / dx
        if s < -slack or s > last + slack:
            r[q] = 0.0
            r1[q] = 0.0
            r2[q] = 0.0
            continue
        i = int(min(max(np.floor(s), 0.0), last - 1))
        t = s - i
        value = 0.0
        slope = 0.0
        curvature = 0.0
        for rail in range(2):
            p0 = values[rail, i]
            m0 = h * slopes[rail, i]
            a2, a3, a4, a5 = quintic(p0, values[rail, i + 1], m0, h * slopes[rail, i + 1],
                                     h * h * curvatures[rail, i],
                                     h * h * curvatures[rail, i + 1])
            value += p0 + t * (m0 + t * (a2 + t * (a3 + t * (a4 + t * a5))))
            slope += (m0 + t * (2.0 * a2 + t * (3.0 * a3 + t * (4.0 * a4 + t * 5.0 * a5)))) / h
            curvature += (2.0 * a2 + t * (6.0 * a3 + t * (12.0 * a4 + t * 20.0 * a5))) / (h * h)
        r[q] = 0.5 * value
        r1[q] = 0.5 * slope
        r2[q] = 0.5 * curvature


def _wheel_terms(positions: np.ndarray, speed: float, element_length: float, n_elements: int,
                 length: float, w_dofs: np.ndarray, h_v: np.ndarray, h_a: np.ndarray,
                 a0: float, a1: float, has_profile: bool, r: np.ndarray, r1: np.ndarray,
                 r2: np.ndarray, ms: np.ndarray, mu: np.ndarray, k: np.ndarray, c: np.ndarray,
                 d: np.ndarray, q: np.ndarray, z: np.ndarray, v: np.ndarray, a: np.ndarray,
                 gravity: float, element: np.ndarray, dofs: np.ndarray, n0: np.ndarray,
                 w: np.ndarray, p: np.ndarray, b: np.ndarray, e: np.ndarray,
                 hs_v: np.ndarray, hs_a: np.ndarray, load: np.ndarray) -> None:
    """
    Fill the per-wheel terms of the coupled step and add the wheel loads to ``load``.

    ``h_v``/``h_a`` are the girder history terms on the free DOFs (a DOF index
    equal to their size is the constrained, always-zero slot); ``load`` is the
    effective right-hand side on the free DOFs, to which ``-n0_i b_i`` is added.
    """
    n_free = h_v.shape[0]
    el_len = element_length
    sign = (1.0, -1.0, 1.0, -1.0)
    g_v = np.empty(4)
    g_a = np.empty(4)
    for i in range(positions.shape[0]):
        x = positions[i]
        s = x / el_len
        el = int(min(max(np.floor(s), 0.0), n_elements - 1))
        xi = min(max(s - el, 0.0), 1.0)
        on = 1.0 if (x >= 0.0 and x <= length) else 0.0
        element[i] = el
        xi2 = xi * xi
        xi3 = xi2 * xi
        row0 = (1.0 - 3.0 * xi2 + 2.0 * xi3, (xi - 2.0 * xi2 + xi3) * el_len,
                3.0 * xi2 - 2.0 * xi3, (-xi2 + xi3) * el_len)
        row1 = ((-6.0 * xi + 6.0 * xi2) / el_len, 1.0 - 4.0 * xi + 3.0 * xi2,
                (6.0 * xi - 6.0 * xi2) / el_len, -2.0 * xi + 3.0 * xi2)
        row2 = ((-6.0 + 12.0 * xi) / el_len ** 2, (-4.0 + 6.0 * xi) / el_len,
                (6.0 - 12.0 * xi) / el_len ** 2, (-2.0 + 6.0 * xi) / el_len)
        c_v = 0.0
        c_a = 0.0
        ms_i, mu_i, k_i, c_i, d_i = ms[i], mu[i], k[i], c[i], d[i]
        hs_v[i] = -a1 * z[i] - v[i]
        hs_a[i] = -a0 * z[i] - 2.0 * a1 * v[i] - a[i]
        for j in range(4):
            dof = w_dofs[el, j]
            dofs[i, j] = dof
            m0 = row0[j] * sign[j] * on
            m1 = row1[j] * sign[j] * on
            m2 = row2[j] * sign[j] * on
            n0[i, j] = m0
            g_v[j] = a1 * m0 + speed * m1
            g_a[j] = a0 * m0 + 2.0 * speed * a1 * m1 + speed * speed * m2
            if dof < n_free:
                c_v += m0 * h_v[dof]
                c_a += m0 * h_a[dof] + 2.0 * speed * m1 * h_v[dof]
        c_z = 0.0
        if has_profile:
            c_z = r[i]
            c_v += speed * r1[i]
            c_a += speed * speed * r2[i]
        e_i = c_i * c_v + k_i * c_z - ms_i * hs_a[i] - c_i * hs_v[i]
        e[i] = e_i
        b_i = ((ms_i + mu_i) * gravity + mu_i * c_a + k_i * c_z + c_i * c_v
               - q[i] * e_i / d_i - c_i * hs_v[i])
        b[i] = b_i
        scale = ms_i * a0 / d_i
        for j in range(4):
            p_ij = c_i * g_v[j] + k_i * n0[i, j]
            p[i, j] = p_ij
            w[i, j] = mu_i * g_a[j] + scale * p_ij
            dof = dofs[i, j]
            if dof < n_free:
                load[dof] -= n0[i, j] * b_i


def _green_correction(x0: np.ndarray, green: np.ndarray, slot: np.ndarray, dofs: np.ndarray,
                      n0: np.ndarray, w: np.ndarray, load: np.ndarray) -> None:
    """
    Solve the Woodbury system on the girder Green's function; take its loads off ``load``.

    ``x0`` solves the effective system with the wheel loads of
    :func:`_wheel_terms`; afterwards ``load`` is the right-hand side of the
    coupled solution.
    """
    n_free = x0.shape[0]
    m = dofs.shape[0]
    s = np.zeros((m, m))
    t = np.zeros(m)
    for i in range(m):
        s[i, i] = 1.0
    for i in range(m):
        for ka in range(4):
            dof = dofs[i, ka]
            if dof < n_free:
                t[i] += w[i, ka] * x0[dof]
    for i in range(m):
        for j in range(m):
            acc = 0.0
            for ka in range(4):
                row = slot[dofs[i, ka]]
                for kb in range(4):
                    acc += w[i, ka] * green[row, slot[dofs[j, kb]]] * n0[j, kb]
            s[i, j] += acc
    if not solve_in_place(s, t):
        t[:] = np.nan   # a singular wheel system: the divergence check stops the run
    for j in range(m):
        for kb in range(4):
            dof = dofs[j, kb]
            if dof < n_free:
                load[dof] -= n0[j, kb] * t[j]


def _update_cars(u: np.ndarray, dofs: np.ndarray, w: np.ndarray, p: np.ndarray,
                 b: np.ndarray, e: np.ndarray, d: np.ndarray, hs_v: np.ndarray,
                 hs_a: np.ndarray, a0: float, a1: float, z: np.ndarray, v: np.ndarray,
                 a: np.ndarray, contact: np.ndarray) -> None:
    """Write the sprung-mass state and the contact forces from the girder displacement u."""
    n_free = u.shape[0]
    for i in range(dofs.shape[0]):
        wu = 0.0
        ww = 0.0
        for j in range(4):
            dof = dofs[i, j]
            if dof < n_free:
                wu += p[i, j] * u[dof]
                ww += w[i, j] * u[dof]
        z_i = (e[i] + wu) / d[i]
        z[i] = z_i
        v[i] = a1 * z_i + hs_v[i]
        a[i] = a0 * z_i + hs_a[i]
        contact[i] = ww + b[i]


def _advance_quarter_cars(head: float, speed: float, dt: float, steps: int,
                          offsets: np.ndarray, profile: tuple[Any, ...],
                          girder: tuple[Any, ...], cars: tuple[np.ndarray, ...],
                          integrator: tuple[np.ndarray, ...], a0: float, a1: float,
                          green: np.ndarray, slot: np.ndarray, state: tuple[np.ndarray, ...],
                          wheels: tuple[np.ndarray, ...], work: tuple[np.ndarray, ...],
                          interiors: tuple[np.ndarray, ...], gravity: float,
                          limit: float) -> tuple[float, int, float]:
    """
    Take up to ``steps`` coupled steps of girders and quarter cars, in place.

    The step of :meth:`QuarterCarCoupling._step_compiled` in one loop, the
    girder solves with the effective matrix's QDLDL factors
    (:func:`~ttb_sim.sim.integrators.newmark_kernels.solve_ldl`). Each step moves
    the head by ``speed * dt``; the loop stops after the first step whose largest
    girder or sprung-mass displacement is not finite or exceeds ``limit``.

    Parameters (tuples keep the list short)
    ---------------------------------------
    profile : (x_start, dx, values, slopes, curvatures, slack)
        The irregularity grid (:meth:`QuarterCarTrain._profile`); ``values`` with no
        columns for a smooth track.
    girder : (element length, elements, length, w_dofs)
    cars : (sprung mass, unsprung mass, stiffness, damping, d, q)
    integrator : (indptr, indices, data, lp, li, lx, dinv, order)
    state : (u, v, a, z, zv, za, contact) -- girder and sprung masses
    wheels : (positions, element, dofs, n0, w, p, b, e, hs_v, hs_a, r, r1, r2)
    work : (history [h_a | h_v], load, x0, solve work)
    interiors : (start, boundary, rho, sigma, p_hat, e_hat, d_m, d_c, eta, e, pre)
        Substructure interiors condensed out of the girder system
        (:meth:`~ttb_sim.sim.integrators.condensed.ModalInteriors.packed`, then their
        modal state and work vector); start = [0]: none, the whole system is in the
        integrator arrays.

    Returns
    -------
    (head, steps taken, largest displacement of the last step)

    """
    x_start, dx, values, slopes, curvatures, slack = profile
    h, n_el, length, w_dofs = girder
    ms, mu, k, c, d, q = cars
    indptr, indices, data, lp, li, lx, dinv, order = integrator
    u, v, a, z, zv, za, contact = state
    positions, element, dofs, n0, w, p, b, e, hs_v, hs_a, r, r1, r2 = wheels
    buffer, load, x0, scratch = work
    i_start, i_boundary, i_rho, i_sigma, i_p, i_e_hat, i_dm, i_dc, i_eta, i_e, i_pre = interiors
    n = u.shape[0]
    h_a = buffer[:n]
    h_v = buffer[n:]
    has_profile = values.shape[1] > 0
    peak = 0.0
    for step in range(steps):
        head += speed * dt
        for i in range(offsets.shape[0]):
            positions[i] = head - offsets[i]
        if has_profile:
            _centreline_profile(positions, x_start, dx, values, slopes, curvatures, slack,
                                r, r1, r2)
        history(u, v, a, a0, a1, h_v, h_a)
        load[:] = 0.0   # the coupling's other load is zero (as QuarterCarTrain.step)
        effective_load(indptr, indices, data, buffer, load, load)
        interior_load(i_start, i_boundary, i_rho, i_sigma, i_p, i_dm, i_dc, i_eta, i_e, i_pre,
                      h_a, h_v, load)
        _wheel_terms(positions, speed, h, n_el, length, w_dofs, h_v, h_a, a0, a1,
                     has_profile, r, r1, r2, ms, mu, k, c, d, q, z, zv, za, gravity, element,
                     dofs, n0, w, p, b, e, hs_v, hs_a, load)
        solve_ldl(lp, li, lx, dinv, order, load, scratch, x0)
        _green_correction(x0, green, slot, dofs, n0, w, load)
        solve_ldl(lp, li, lx, dinv, order, load, scratch, u)
        _update_cars(u, dofs, w, p, b, e, d, hs_v, hs_a, a0, a1, z, zv, za, contact)
        finish_into(u, a0, a1, h_v, h_a, v, a)
        interior_finish(i_start, i_boundary, i_sigma, i_e_hat, i_eta, i_e, i_pre, u, v, a)
        peak = largest_magnitude(z, largest_magnitude(u, 0.0))
        if not peak <= limit:
            return head, step + 1, peak
    return head, steps, peak


KERNELS = KernelTable({
    'centreline_profile': _centreline_profile, 'wheel_terms': _wheel_terms,
    'green_correction': _green_correction, 'update_cars': _update_cars,
    'advance_quarter_cars': _advance_quarter_cars})
"""The quarter cars' kernels."""


def available() -> bool:
    """Tell whether every quarter-car kernel is compiled (compiling them on first call)."""
    return all(KERNELS.compiled(name) is not None
               for name in ('centreline_profile', 'wheel_terms', 'green_correction',
                            'update_cars'))
