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
The test oracle of the multibody contact step: the step in numpy, with two track solves.

:func:`numpy_step` is the step as the package took it before its compiled
kernels (:mod:`ttb_sim.sim.coupling.train_track.contact_step`): every wheel at
once with numpy arrays, the contact laws from the vectorised functions of
:mod:`ttb_sim.model.wheel_rail` (Hertz, Kalker's creep, Shen-Hedrick-Elkins),
the rail under the wheels from :mod:`ttb_sim.fe.beam`, the track solved for
the predictor and again for the contact loads. It is independent of the
kernels' loops, so the two agree only where both are right: the tests hold the
compiled step to it. :func:`use_numpy_step` makes a coupling take it.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.errors import DivergenceError
import ttb_sim.model.wheel_rail as ct
from ttb_sim.sim.coupling.train_track.contact_step import COMPONENTS, GEOMETRY_STEP
from ttb_sim.sim.coupling.train_track.equilibrium import (irregularity_under_wheels,
                                                          rail_under_wheels, wheel_geometry)
from ttb_sim.sim.coupling.train_track.multibody import TrainTrackCoupling
from ttb_sim.sim.coupling.train_track.rail_compliance import gather


def use_numpy_step(coupling: TrainTrackCoupling) -> None:
    """Make ``coupling`` take :func:`numpy_step` instead of its compiled step."""
    coupling.step = lambda head, speed: numpy_step(coupling, head, speed)  # type: ignore


def numpy_step(self: TrainTrackCoupling, head: float, speed: float) -> None:
    """Take the coupled step of ``self`` with numpy, as the package took it before its kernels."""
    self.update_speed(speed)
    nm, n = self.nm, self.n_cars
    n_free = self.n_free
    x = head + self.contact_x
    rows, slope, dofs, blocks, interior = rail_under_wheels(self, x)
    irr_z, irr_y, irr_dy = irregularity_under_wheels(self, x)

    # Predictors (no contact force).
    h_v, h_a = nm.history(self.u, self.v, self.a)
    u_star = nm.solve(nm.effective_load(np.zeros(n_free), h_v, h_a))
    u_dofs = gather(u_star, dofs)
    r_star = np.einsum('cwij,cwj->cwi', rows, u_dofs)
    rs_star = np.einsum('cwij,cwj->cwi', slope, u_dofs)
    r_hist = np.einsum('cwij,cwj->cwi', rows, gather(h_v, dofs))
    a0, a1 = nm.a0, nm.a1
    qh_v = -a1 * self.q - self.qv
    qh_a = -a0 * self.q - 2.0 * a1 * self.qv - self.qa
    rhs_t = self.gravity - qh_a @ self.mass.T - qh_v @ self.train_damping.T
    q_star = rhs_t @ self.a_inv.T
    w_star = (q_star @ self.h.T).reshape(n, 8, COMPONENTS)
    w_hist = (qh_v @ self.h.T).reshape(n, 8, COMPONENTS)

    # Local rail compliance: r = r* - Dr g_xyz, r' = r'* - Ds g_xyz; the rail head
    # under a wheel also deflects within its element (Dr includes that, C_i).
    dr = np.einsum('cwij,cwjk,cwlk->cwil', rows, blocks, rows) + interior
    ds = np.einsum('cwij,cwjk,cwlk->cwil', slope, blocks, rows)

    # Creep coefficients scaled with the previous step's normal load.
    normal = np.maximum(self.force[..., 2], 0.0)
    f11, f22, f23, f33 = ct.scale_creep_coefficients(self.creep0, self.p0, normal)
    side = self.side

    # Affine maps of the end-of-step quantities in g (per car, 32 unknowns).
    m = 8 * COMPONENTS
    eye = np.eye(m)
    dwm = np.broadcast_to(self.dw, (n, m, m))                # wheel: w = w* + Dw g
    rail_disp = np.zeros((n, m, m))                          # rail: r = r* - Rm g
    rail_vel = np.zeros((n, m, m))
    idx = np.arange(8) * COMPONENTS
    for i in range(3):
        for j in range(3):
            rail_disp[:, idx + i, idx + j] = dr[..., i, j]
            rail_vel[:, idx + i, idx + j] = a1 * dr[..., i, j] + speed * ds[..., i, j]
    w0 = w_star.reshape(n, m)
    wv0 = a1 * w0 + w_hist.reshape(n, m)
    r0p = np.zeros((n, 8, COMPONENTS))
    r0p[..., :3] = r_star
    rv0 = np.zeros((n, 8, COMPONENTS))
    # The interior deflection's velocity continues by the trapezoidal rule.
    rv0[..., :3] = (a1 * r_star + r_hist + speed * rs_star
                    - a1 * self.interior_deflection - self.interior_velocity)
    # Start from the last step's correction of the local rail model: it is what the
    # local blocks leave out (coupling of wheels through slab and girder) and
    # changes little from step to step, so one exact solve usually suffices.
    offset = self.rail_offset.copy()
    # Sensitivities of compression and creepages to g (constant within the step).

    def part(mat: np.ndarray, k: int) -> np.ndarray:
        return mat.reshape(n, 8, COMPONENTS, m)[:, :, k]

    def value(vec: np.ndarray, k: int) -> np.ndarray:
        return vec.reshape(n, 8, COMPONENTS)[..., k]

    # Wheelset lateral displacement: y = y* + Ey g (for the contact geometry).
    y_star = q_star[:, self.wheelset_y]
    d_yrel = self.ey[None] + part(rail_disp, 1)
    d_delta0 = -part(rail_disp, 2) - part(dwm, 2)
    d_xi_x = (a1 * part(dwm, 0) + part(rail_vel, 0)) / speed
    d_xi_y = (a1 * part(dwm, 1) + part(rail_vel, 1)) / speed - part(dwm, 3)
    g = self.force.reshape(n, m).copy()
    total_iter = 0
    change = math.inf
    for _outer in range(self.max_iter):
        rp = (r0p + offset).reshape(n, m)
        rvp = (rv0 + a1 * offset).reshape(n, m)
        for _ in range(self.max_iter):
            total_iter += 1
            w = w0 + np.einsum('cij,cj->ci', dwm, g)
            wv = wv0 + a1 * np.einsum('cij,cj->ci', dwm, g)
            r = rp - np.einsum('cij,cj->ci', rail_disp, g)
            rv = rvp - np.einsum('cij,cj->ci', rail_vel, g)
            # Contact geometry at the end-of-step lateral position.
            y_rel = y_star + np.einsum('wj,cj->cw', self.ey, g) - value(r, 1) - irr_y
            # Geometry at y and y +/- GEOMETRY_STEP in one (elementwise) evaluation.
            radii, angles, heights = wheel_geometry(
                self, np.stack([y_rel, y_rel + GEOMETRY_STEP, y_rel - GEOMETRY_STEP]))
            radius, angle, angle_hi, angle_lo = radii[0], angles[0], angles[1], angles[2]
            height, height_hi, height_lo = heights
            height_slope = (height_hi - height_lo) / (2 * GEOMETRY_STEP)
            tan_slope = (np.tan(angle_hi) - np.tan(angle_lo)) / (2 * GEOMETRY_STEP)
            cosg, sing, tan_g = np.cos(angle), np.sin(angle), np.tan(angle)
            d_delta = d_delta0 + height_slope[..., None] * d_yrel
            d_xi_sp = a1 * part(dwm, 3) * cosg[..., None] / speed
            delta = value(r, 2) + irr_z - value(w, 2) + height
            fz = ct.normal_force(delta, self.g_hertz)
            kh = ct.normal_force_derivative(delta, self.g_hertz)
            xi_x = (value(wv, 0) - value(rv, 0)) / speed + 1.0 - radius / self.r0
            xi_y = (value(wv, 1) - value(rv, 1) - speed * irr_dy) / speed - value(w, 3)
            xi_sp = value(wv, 3) * cosg / speed - side * sing / self.r0
            # Kalker's linear creep forces, saturated (Shen-Hedrick-Elkins) at this
            # iterate; the Jacobian includes the derivative of the factor.
            lin_x = -f11 * xi_x
            lin_y = -(f22 * xi_y + f23 * xi_sp)
            lin_m = f23 * xi_y - f33 * xi_sp
            fx, fy, mz, eps = ct.she_saturation(lin_x, lin_y, lin_m, fz, self.friction)
            d_lin_x = -f11[..., None] * d_xi_x
            d_lin_y = -f22[..., None] * d_xi_y - f23[..., None] * d_xi_sp
            d_lin_m = f23[..., None] * d_xi_y - f33[..., None] * d_xi_sp
            e_x, e_y, e_n = ct.she_factor_gradient(lin_x, lin_y, fz, self.friction)
            d_eps = (e_x[..., None] * d_lin_x + e_y[..., None] * d_lin_y
                     + (e_n * kh)[..., None] * d_delta)
            creep_x = eps[..., None] * d_lin_x + lin_x[..., None] * d_eps
            creep_y = eps[..., None] * d_lin_y + lin_y[..., None] * d_eps
            creep_m = eps[..., None] * d_lin_m + lin_m[..., None] * d_eps
            fy = fy - side * tan_g * fz
            target = np.stack([fx, fy, fz, mz], axis=-1).reshape(n, m)
            jac_f = np.stack([creep_x,
                              creep_y - (side * tan_g * kh)[..., None] * d_delta
                              - (side * tan_slope * fz)[..., None] * d_yrel,
                              kh[..., None] * d_delta, creep_m], axis=2).reshape(n, m, m)
            dg = np.linalg.solve(eye - jac_f, (target - g)[..., None])[..., 0]
            g = g + dg
            change = float(np.max(np.abs(np.einsum('cwj,cj->cw', d_delta, dg))))
            if change < self.tol:
                break
        else:
            raise DivergenceError(f'contact iteration did not converge in {self.max_iter} '
                                  f'iterations (last change {change:.3g} m)')
        # Exact track response to these forces.
        gx = g.reshape(n, 8, COMPONENTS)[..., :3]
        load = np.zeros(n_free + 1)
        np.add.at(load, dofs.ravel(), -np.einsum('cwij,cwi->cwj', rows, gx).ravel())
        u_new = u_star + nm.solve(load[:n_free])
        r_exact = (np.einsum('cwij,cwj->cwi', rows, gather(u_new, dofs))
                   - np.einsum('cwij,cwj->cwi', interior, gx))
        r_model = rp.reshape(n, 8, COMPONENTS)[..., :3] - np.einsum(
            'cwij,cwj->cwi', dr, gx)
        mismatch = r_exact - r_model
        if np.max(np.abs(mismatch[..., 2])) <= self.tol:
            break
        offset[..., :3] += mismatch
    else:
        raise DivergenceError('rail displacement under the wheels did not converge to '
                              f'contact.tolerance = {self.tol:g} m')

    self.check_flange(y_rel)
    self.rail_offset = offset
    self.rail_offset[..., :3] += mismatch
    # Accept the step.
    g3 = g.reshape(n, 8, COMPONENTS)
    q_new = q_star + (g @ self.h) @ self.a_inv.T
    self.qv = a1 * q_new + qh_v
    self.qa = a0 * q_new + qh_a
    self.q = q_new
    self.v, self.a = nm.finish(u_new, h_v, h_a)
    self.u = u_new
    self.force = g3
    self.accept_interior(interior, g3, a1)
    self.compression = delta
    self.rail_y = r_exact[..., 1]
    self.saturation = eps
    self.iterations = total_iter
    self.solves = _outer + 2
