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
The static start of the multibody cars on the track, and the numpy rail under the wheels.

:func:`static_equilibrium` puts train and track in static equilibrium under
gravity (the vertical problem: Newton on the car DOFs and the wheel loads, with
the exact static track flexibility under the wheels). It evaluates the rail
under the wheels, the irregularity and the contact geometry with the package's
vectorised functions (:func:`rail_under_wheels`, :func:`irregularity_under_wheels`,
:func:`wheel_geometry`), which are also the test oracle's.
"""

from __future__ import annotations

import logging
from typing import TYPE_CHECKING

import numpy as np

from ttb_sim.errors import DivergenceError
from ttb_sim.fe.beam import interior_compliance
from ttb_sim.fe.factorization import factorize
from ttb_sim.model.vehicle.dofs import dofs as car_dofs
import ttb_sim.model.wheel_rail as ct
from ttb_sim.sim.coupling.girder_load import point_rows_and_slopes
from ttb_sim.sim.coupling.train_track.rail_kernels import COMPONENTS

if TYPE_CHECKING:
    from ttb_sim.sim.coupling.train_track.multibody import TrainTrackCoupling

log = logging.getLogger(__name__)

STATIC_ITERATIONS = 60
"""Newton iterations allowed for the static equilibrium."""


def rail_under_wheels(c: TrainTrackCoupling, x: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """
    Return rail-head rows R, R' (n_cars, 8, 3, 12), ext-free DOFs, B blocks and C_i.

    C_i (n_cars, 8, 3, 3) is the interior flexibility of the rail element under
    each wheel (:func:`ttb_sim.fe.beam.interior_compliance`): the rail head
    under a wheel moves by R u - C_i F for the force F the wheel puts on it.
    """
    shape = x.shape
    xi = np.zeros(shape)
    length = np.zeros(shape)
    dofs = np.zeros(shape + (12,), dtype=int)
    blocks = np.zeros(shape + (12, 12))
    interior = np.zeros(shape + (3, 3))
    for r, side in enumerate((1.0, -1.0)):
        sel = c.side == side
        rail = c.rails[r]
        element, xi[sel], inside = rail.locate(x[sel])
        if not np.all(inside):
            raise DivergenceError('a wheel ran off the modelled track at x = '
                                  f'{x[sel][~inside][0]:.2f} m; the run is longer than '
                                  'the track (check solver.duration)')
        length[sel] = rail.length[element]
        dofs[sel] = c.rail_dofs[r][element]
        blocks[sel] = c.compliance.blocks[r][element]
        sec = c.rail_sections[r][element]
        interior[sel] = interior_compliance(xi[sel], length[sel], sec[:, 0], sec[:, 1],
                                            sec[:, 2], sec[:, 3], float(c.head_arm[2]))
    # Rows and slopes of both rails in one evaluation (elementwise, so the same numbers).
    rows, slope = point_rows_and_slopes(xi.ravel(), length.ravel(), c.head_arm)
    return (rows.reshape(shape + (3, 12)), slope.reshape(shape + (3, 12)), dofs, blocks,
            interior)


def irregularity_under_wheels(c: TrainTrackCoupling, x: np.ndarray
                              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return vertical and lateral rail irregularity and lateral slope under each wheel."""
    z = np.zeros_like(x)
    y = np.zeros_like(x)
    dy = np.zeros_like(x)
    if c.irregularity is None:
        return z, y, dy
    s = c.irregularity.sample(x, outside='zero')
    left = c.side > 0
    z = np.where(left, s.value[0], s.value[1])
    y = np.where(left, s.value[2], s.value[3])
    dy = np.where(left, s.slope[2], s.slope[3])
    return z, y, dy


def wheel_geometry(c: TrainTrackCoupling, lateral: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return rolling radius, contact angle and rigid-contact height of each wheel.

    The height (m, up) is where the wheel's contact point would sit on rigid
    rails at this relative shift (:meth:`ContactGeometryTable.wheel_height`);
    with the conicity model it is r - r0 (knife-edge rails).
    """
    if c.table is not None:
        g = c.table.wheelset_geometry(lateral)
        h = c.table.wheel_height(lateral, c.params.contact_semi_distance)
    else:
        g = ct.simplified_geometry(lateral, c.contact.conicity, c.r0)
        h = g.rolling_radius - c.r0
    left = c.side > 0
    radius = np.where(left, g.rolling_radius[..., 0], g.rolling_radius[..., 1])
    angle = np.where(left, g.contact_angle[..., 0], g.contact_angle[..., 1])
    height = np.where(left, h[..., 0], h[..., 1])
    return radius, angle, height


def static_equilibrium(c: TrainTrackCoupling, head: float) -> None:
    """
    Put train and track of ``c`` in static equilibrium under gravity at a head position.

    Vertical problem only (the train is symmetric and the track straight):
    Newton on the car DOFs and the wheel loads, with the exact static track
    flexibility under the wheels (one static factorisation, one solve per wheel).
    The wheelsets stand centred on the track; vertical irregularity and the
    rigid-contact height change caused by lateral irregularity are included.
    """
    n = c.n_cars
    x = head + c.contact_x
    rows, _, dofs, _, interior = rail_under_wheels(c, x)
    irr_z, irr_y, _ = irregularity_under_wheels(c, x)
    # The wheelsets start centred on the track (y = 0): with lateral irregularity
    # the rails are shifted under them, which raises or lowers each wheel's
    # rigid-contact height; the static loads and attitude take that in.
    irr_z = irr_z + wheel_geometry(c, -irr_y)[2]
    zcol, flex = _static_flexibility(c, rows, dofs, interior)
    sub = _vertical_dofs()
    hz = c.h.reshape(8, COMPONENTS, 42)[:, 2][:, sub]      # (8, n_sub)
    q, load = _vertical_newton(c, sub, hz, flex, irr_z)
    c.q[:, sub] = q
    c.qv[:] = 0.0
    c.qa[:] = 0.0
    c.u = -(zcol[:c.n_free] @ load)
    c.v[:] = 0.0
    c.a[:] = 0.0
    c.force[:] = 0.0
    c.rail_offset[:] = 0.0
    c.slope_offset[:] = 0.0
    c.force[..., 2] = load.reshape(n, 8)
    c.interior_deflection = -interior[..., 2] * c.force[..., 2:3]
    c.interior_velocity = np.zeros((n, 8, 3))
    w = np.einsum('ks,cs->ck', hz, q)
    c.compression = (-(flex @ load) + irr_z.ravel() - w.ravel()).reshape(n, 8)
    c.saturation[:] = 1.0
    log.info('static equilibrium: wheel loads %.1f .. %.1f kN', load.min() / 1e3,
             load.max() / 1e3)


def _static_flexibility(c: TrainTrackCoupling, rows: np.ndarray, dofs: np.ndarray,
                        interior: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the static track's response to unit wheel loads and its flexibility there.

    ``zcol`` (n_free + 1, 8 n) holds the track's displacement under each unit
    vertical wheel load (the ground slot last), ``flex`` (8 n, 8 n) the vertical
    rail-head motion under every wheel per load (r_z = -flex P), the interior
    flexibility of the element under each wheel on its diagonal.
    """
    n_free = c.n_free
    m = 8 * c.n_cars
    lu = factorize(c.static_stiffness, method=c.nm.method)
    rhs = np.zeros((n_free + 1, m))
    flat = dofs.reshape(m, 12)
    rz = rows[..., 2, :].reshape(m, 12)
    rhs[flat, np.arange(m)[:, None]] = rz
    zcol = np.vstack([lu.solve(rhs[:n_free]), np.zeros((1, m))])
    flex = np.einsum('ik,ikj->ij', rz, zcol[flat])     # r_z = -flex @ P
    flex[np.diag_indices(m)] += interior[..., 2, 2].ravel()
    return zcol, flex


def _vertical_dofs() -> np.ndarray:
    """
    Return a car's DOFs of the vertical subproblem, sorted.

    z, roll, pitch of body and bogies; z, roll of the wheelsets (their pitch is
    the free spin).
    """
    return np.sort(np.concatenate([car_dofs(range(3), ['z', 'roll', 'pitch']),
                                   car_dofs(range(3, 7), ['z', 'roll'])]))


def _vertical_newton(c: TrainTrackCoupling, sub: np.ndarray, hz: np.ndarray, flex: np.ndarray,
                     irr_z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the cars' vertical DOFs (n, n_sub) and the wheel loads (8 n).

    Residuals K q - hz^T P - g = 0 and P - f(delta) = 0, solved by Newton. Below
    d_min, a quarter of the static compression, the Hertz law is continued by
    its tangent, so that Newton starts from an unloaded train; the converged
    state lies on the Hertz law itself.
    """
    n = c.n_cars
    m = 8 * n
    k_sub = c.stiffness[np.ix_(sub, sub)]
    g_sub = c.gravity[sub]
    n_sub = sub.size
    q = np.zeros((n, n_sub))
    load = np.full(m, c.p0)
    d_min = 0.25 * float(ct.static_compression(c.p0, c.g_hertz))
    f_min = float(ct.normal_force(d_min, c.g_hertz))
    k_min = float(ct.normal_force_derivative(d_min, c.g_hertz))
    for _ in range(STATIC_ITERATIONS):
        w = np.einsum('ks,cs->ck', hz, q).ravel()
        delta = -flex @ load + irr_z.ravel() - w
        low = delta < d_min
        f = np.where(low, f_min + k_min * (delta - d_min),
                     ct.normal_force(np.maximum(delta, d_min), c.g_hertz))
        kh = np.where(low, k_min,
                      ct.normal_force_derivative(np.maximum(delta, d_min), c.g_hertz))
        r1 = (q @ k_sub.T) - np.einsum('ks,ck->cs', hz, load.reshape(n, 8)) - g_sub
        r2 = load - f
        jac = _static_jacobian(k_sub, hz, kh, flex, n)
        step = np.linalg.solve(jac, -np.concatenate([r1.ravel(), r2]))
        dq = step[:n * n_sub].reshape(n, n_sub)
        dload = step[n * n_sub:]
        q += dq
        load += dload
        # Converged when both the loads and the compressions have settled (on a
        # symmetric car the loads are right from the start; the compressions not).
        d_delta = -flex @ dload - np.einsum('ks,cs->ck', hz, dq).ravel()
        if (np.max(np.abs(dload)) < 1e-6 * c.p0
                and np.max(np.abs(d_delta)) < 1e-6 * d_min):
            return q, load
    raise DivergenceError('static equilibrium of the train on the track did not '
                          f'converge in {STATIC_ITERATIONS} Newton iterations')


def _static_jacobian(k_sub: np.ndarray, hz: np.ndarray, kh: np.ndarray, flex: np.ndarray,
                     n: int) -> np.ndarray:
    """Return the Jacobian of the static residuals in (q of every car, wheel loads)."""
    n_sub = k_sub.shape[0]
    m = 8 * n
    size = n * n_sub + m
    jac = np.zeros((size, size))
    for car in range(n):
        s = slice(car * n_sub, (car + 1) * n_sub)
        jac[s, s] = k_sub
        jac[s, n * n_sub + 8 * car:n * n_sub + 8 * car + 8] = -hz.T
        rows_c = slice(n * n_sub + 8 * car, n * n_sub + 8 * car + 8)
        jac[rows_c, s] = kh[8 * car:8 * car + 8, None] * hz
    jac[n * n_sub:, n * n_sub:] = np.eye(m) + kh[:, None] * flex
    return jac
