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
The coupled step of the multibody cars and the track, compiled.

One :class:`ContactStep` takes every step of a :class:`TrainTrackCoupling` and
owns the work arrays of its kernels (:mod:`rail_kernels`, :mod:`contact_kernels`).
At the end of a step train and track are affine in the contact forces
g = (Fx, Fy, Fz, Mz) of every wheel (module docstring of :mod:`multibody`); the
step

1. finds the rail element under each wheel, its rows and the local rail
   compliance there, and the irregularity under the wheels;
2. takes the predictors (no contact force) of track and train;
3. sets the contact iteration's constants (creep coefficients at the last
   step's loads, the rail's motion and velocity without contact force);
4. iterates the contact laws on the local rail model (Newton), solves the track
   exactly with those forces and compares the rail's motion under every wheel
   with the local model; a mismatch above ``contact.tolerance`` joins the
   model's offsets and the iteration is repeated;
5. accepts the step.

With the local K^-1 columns (the lean variants, ``influence_hops``) the track is
solved once per pass: the predictor's rail motion under the wheels comes from
those columns, its small error joins the offsets (and a slope offset), and the
one solve is of the whole right-hand side, predictor and contact loads
together; every component of the rail's motion is checked. Without them (the
``reference``) the track is solved for the predictor and again for the contact
loads, and the vertical motion is checked. The test oracle of the whole step is
the numpy step of ``test/sim/contact_oracle.py``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
import logging
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from ttb_sim.errors import DivergenceError
from ttb_sim.model.irregularity import GRID_SLACK
from ttb_sim.sim.coupling.train_track import contact_kernels, rail_kernels
from ttb_sim.sim.kernel_registry import KernelTable

if TYPE_CHECKING:
    from ttb_sim.sim.coupling.train_track.multibody import TrainTrackCoupling

log = logging.getLogger(__name__)

COMPONENTS = rail_kernels.COMPONENTS
"""Contact force components per wheel: Fx, Fy, Fz (on the wheel), Mz (spin moment)."""
GEOMETRY_STEP = 1e-6
"""Lateral step (m) of the central difference of the contact geometry."""

KERNELS = KernelTable({
    'rail_rows': rail_kernels.rail_rows, 'rail_values': rail_kernels.rail_values,
    'rail_load': rail_kernels.rail_load, 'rail_predictor': rail_kernels.rail_predictor,
    'rail_irregularity': rail_kernels.rail_irregularity, 'rail_check': rail_kernels.rail_check,
    'contact_setup': contact_kernels.contact_setup,
    'contact_newton': contact_kernels.contact_newton}, parallel=frozenset({'rail_predictor'}))
"""The kernels of the step; the rail predictor runs its cars on numba's threads."""


@dataclass(frozen=True)
class ContactKernels:
    """The kernels of the contact step, compiled or (without numba) their plain sources."""

    rail_rows: Callable[..., Any]
    rail_values: Callable[..., Any]
    rail_load: Callable[..., Any]
    contact_newton: Callable[..., Any]
    rail_predictor: Callable[..., Any]
    rail_irregularity: Callable[..., Any]
    contact_setup: Callable[..., Any]
    rail_check: Callable[..., Any]

    @classmethod
    def load(cls, irregular: bool = True, single: bool = True) -> ContactKernels:
        """
        Return the kernels compiled, or their plain-Python sources.

        The sources compute the same numbers, about a thousand times slower: they
        run only where numba is not installed (or is switched off,
        :data:`ttb_sim.sim.kernel_registry.ENABLED`), which is logged. A smooth
        track (``irregular`` False) never samples the irregularity: its kernel
        is not made, so it is neither compiled nor announced as to compile; nor is
        the rail predictor of the single-solve step for the two-solve ``reference``
        (``single`` False).
        """
        names = [f.name for f in fields(cls)]
        unused = {'rail_irregularity'} if not irregular else set()
        if not single:
            unused.add('rail_predictor')
        found = [KERNELS.source(name) if name in unused else KERNELS.compiled(name)
                 for name in names]
        compiled = [kernel for kernel in found if kernel is not None]
        if len(compiled) < len(names):
            log.warning('numba is not available: the multibody contact step runs its '
                        'kernels as plain Python (the same results, far slower)')
            return cls(*(KERNELS.source(name) for name in names))
        return cls(*compiled)


@dataclass
class RailUnderWheels:
    """The rail under every wheel at one step, shape (n_cars, 8, ...)."""

    rows: np.ndarray
    """(n, 8, 3, 12) rows of the rail head's x, y, z motion over its element's DOFs."""
    slope: np.ndarray
    """(n, 8, 3, 12) their x-derivatives."""
    dofs: np.ndarray
    """(n, 8, 12) extended free DOFs of those elements."""
    element: np.ndarray
    """(n, 8) the rail element under each wheel."""
    dr: np.ndarray
    """(n, 8, 3, 3) local compliance of the rail head, rows B rows^T."""
    ds: np.ndarray
    """(n, 8, 3, 3) slope B rows^T."""
    interior: np.ndarray
    """(n, 8, 3, 3) interior flexibility of the element under each wheel."""
    irr_z: np.ndarray
    """(n, 8) vertical irregularity (m)."""
    irr_y: np.ndarray
    """(n, 8) lateral irregularity (m)."""
    irr_dy: np.ndarray
    """(n, 8) slope of the lateral irregularity (-)."""


@dataclass
class Predictor:
    """Track and train at the end of the step without contact force."""

    h_v: np.ndarray
    h_a: np.ndarray
    rhs: np.ndarray
    """The track's effective load without contact force."""
    u_star: np.ndarray
    """The track's motion without contact force (the single-solve step: ``rhs``)."""
    r_star: np.ndarray
    rs_star: np.ndarray
    r_hist: np.ndarray
    qh_v: np.ndarray
    qh_a: np.ndarray
    q_star: np.ndarray
    w0: np.ndarray
    wv0: np.ndarray


@dataclass
class Solution:
    """The contact forces of a step and the track's exact response to them."""

    g: np.ndarray
    """(n, 32) contact forces."""
    u_new: np.ndarray
    offset: np.ndarray
    slope_offset: np.ndarray
    mismatch: np.ndarray
    slope_mismatch: np.ndarray
    r_exact: np.ndarray
    y_rel: np.ndarray
    delta: np.ndarray
    eps: np.ndarray
    iterations: int
    passes: int


class ContactStep:
    """
    The compiled coupled step of a :class:`TrainTrackCoupling` (module docstring).

    Parameters
    ----------
    kernels : ContactKernels
        The kernels it calls.

    """

    def __init__(self, kernels: ContactKernels) -> None:
        self.kernels = kernels
        self._work: dict[str, np.ndarray] = {}

    def __call__(self, c: TrainTrackCoupling, head: float, speed: float) -> None:
        """Advance train, track and bridge of ``c`` to the head position ``head``."""
        c.update_speed(speed)
        rail = self.rail_under_wheels(c, head + c.contact_x)
        single = bool(c.compliance.influence)
        pred = self.predictors(c, rail, single)
        constants = self.contact_constants(c, rail, pred, speed)
        sol = self.solve(c, rail, pred, constants, speed, single)
        c.check_flange(sol.y_rel)
        c.accept_compiled(pred, rail, sol)
        c.solves = sol.passes + (0 if single else 1)

    def buffer(self, name: str, shape: tuple[int, ...], dtype: Any = float) -> np.ndarray:
        """Return a work array, reallocated when its shape changes."""
        buf = self._work.get(name)
        if buf is None or buf.shape != shape:
            buf = self._work[name] = np.zeros(shape, dtype=dtype)
        return buf

    def rail_under_wheels(self, c: TrainTrackCoupling, x: np.ndarray) -> RailUnderWheels:
        """Return the rail under the wheels at ``x`` (n, 8) and the irregularity there."""
        k, n = self.kernels, c.n_cars
        b = self.buffer
        rail = RailUnderWheels(
            b('rows', (n, 8, 3, 12)), b('slope', (n, 8, 3, 12)), b('dofs', (n, 8, 12), np.intp),
            b('element', (n, 8), np.intp), b('dr', (n, 8, 3, 3)), b('ds', (n, 8, 3, 3)),
            b('interior', (n, 8, 3, 3)), np.zeros((n, 8)), np.zeros((n, 8)), np.zeros((n, 8)))
        left, right = c.rails
        off = k.rail_rows(x, c.side, left.start, left.length, c.rail_dofs[0],
                          c.compliance.blocks[0], c.rail_sections[0], right.start,
                          right.length, c.rail_dofs[1], c.compliance.blocks[1],
                          c.rail_sections[1], float(c.head_arm[2]), rail.rows, rail.slope,
                          rail.dofs, rail.dr, rail.ds, rail.interior, rail.element)
        if off >= 0:
            raise DivergenceError('a wheel ran off the modelled track at x = '
                                  f'{x.flat[off]:.2f} m; the run is longer than '
                                  'the track (check solver.duration)')
        irr = c.irregularity
        if irr is not None:
            k.rail_irregularity(x, c.side, float(irr.x_start), float(irr.dx), irr.values,
                                irr.slopes, irr.curvatures, GRID_SLACK, rail.irr_z, rail.irr_y,
                                rail.irr_dy)
        return rail

    def predictors(self, c: TrainTrackCoupling, rail: RailUnderWheels,
                   single: bool) -> Predictor:
        """Return track and train at the end of the step without contact force."""
        k, nm, n = self.kernels, c.nm, c.n_cars
        zero = c.zero_load()
        h_v, h_a = nm.history(c.u, c.v, c.a)
        rhs = nm.effective_load(zero, h_v, h_a)
        r_star = self.buffer('r_star', (n, 8, 3))
        rs_star = self.buffer('rs_star', (n, 8, 3))
        r_hist = self.buffer('r_hist', (n, 8, 3))
        if single:
            infl_l, infl_r = c.compliance.influence
            k.rail_predictor(rail.element, c.side, *infl_l, *infl_r, rail.rows, rail.slope, rhs,
                             r_star, rs_star)
            u_star = rhs
        else:
            u_star = nm.solve(rhs)
            k.rail_values(rail.rows, u_star, rail.dofs, r_star)
            k.rail_values(rail.slope, u_star, rail.dofs, rs_star)
        k.rail_values(rail.rows, h_v, rail.dofs, r_hist)
        a0, a1 = nm.a0, nm.a1
        qh_v = -a1 * c.q - c.qv
        qh_a = -a0 * c.q - 2.0 * a1 * c.qv - c.qa
        rhs_t = c.gravity - qh_a @ c.mass.T - qh_v @ c.train_damping.T
        q_star = rhs_t @ c.a_inv.T
        w0 = q_star @ c.h.T
        wv0 = a1 * w0 + qh_v @ c.h.T
        return Predictor(h_v, h_a, rhs, u_star, r_star, rs_star, r_hist, qh_v, qh_a, q_star, w0,
                         wv0)

    def contact_constants(self, c: TrainTrackCoupling, rail: RailUnderWheels, pred: Predictor,
                          speed: float) -> dict[str, np.ndarray]:
        """
        Return the contact iteration's constants of the step (:func:`contact_setup`).

        The iteration's rail model includes the interior flexibility (``dr_model``);
        the check of the solved track compares the nodes' part (the interior one is
        the same in both).
        """
        n = c.n_cars
        b = self.buffer
        out = {'creep': b('creep', (4, n, 8)), 'r0p': b('r0p', (n, 8, COMPONENTS)),
               'rv0': b('rv0', (n, 8, COMPONENTS)), 'rvel': b('rvel', (n, 8, 3, 3)),
               'y_star': b('y_star', (n, 8)), 'dr_model': b('dr_model', (n, 8, 3, 3))}
        np.add(rail.dr, rail.interior, out=out['dr_model'])
        self.kernels.contact_setup(
            c.force, c.creep0_array, float(c.p0), pred.r_star, pred.rs_star, pred.r_hist,
            c.interior_deflection, c.interior_velocity, out['dr_model'], rail.ds, c.nm.a1,
            float(speed), pred.q_star, c.wheelset_y, out['creep'], out['r0p'], out['rv0'],
            out['rvel'], out['y_star'])
        return out

    def solve(self, c: TrainTrackCoupling, rail: RailUnderWheels, pred: Predictor,
              constants: dict[str, np.ndarray], speed: float, single: bool) -> Solution:
        """Iterate the contact forces and the track's exact response (module docstring)."""
        k, nm, n, n_free = self.kernels, c.nm, c.n_cars, c.n_free
        b = self.buffer
        sol = Solution(c.force.reshape(n, 8 * COMPONENTS).copy(), pred.u_star,
                       c.rail_offset.copy(), c.slope_offset.copy(), b('mismatch', (n, 8, 3)),
                       b('slope_mismatch', (n, 8, 3)), b('r_exact', (n, 8, 3)),
                       np.empty((n, 8)), np.empty((n, 8)), np.empty((n, 8)), 0, 0)
        load = b('load', (n_free + 1,))
        for _outer in range(c.max_iter):
            iterations, change = self.newton(c, rail, pred, constants, sol, speed)
            sol.iterations += iterations
            if not change < c.tol:
                raise DivergenceError(f'contact iteration did not converge in {c.max_iter} '
                                      f'iterations (last change {change:.3g} m)')
            # Exact track response to these forces.
            k.rail_load(rail.rows, sol.g, rail.dofs, load)
            if single:
                sol.u_new = nm.solve(pred.rhs + load[:n_free])
            else:
                sol.u_new = pred.u_star + nm.solve(load[:n_free])
            # The single-solve step checks every component: its predictor is local too.
            worst = k.rail_check(rail.rows, rail.slope, sol.u_new, rail.dofs, constants['r0p'],
                                 sol.offset, rail.dr, rail.ds, sol.g, pred.rs_star,
                                 sol.slope_offset, single, sol.r_exact, sol.mismatch,
                                 sol.slope_mismatch)
            if worst <= c.tol:
                sol.passes = _outer + 1
                return sol
            sol.offset[..., :3] += sol.mismatch
            sol.slope_offset += sol.slope_mismatch
        raise DivergenceError('rail displacement under the wheels did not converge to '
                              f'contact.tolerance = {c.tol:g} m')

    def newton(self, c: TrainTrackCoupling, rail: RailUnderWheels, pred: Predictor,
               constants: dict[str, np.ndarray], sol: Solution,
               speed: float) -> tuple[int, float]:
        """Iterate the contact laws on the local rail model (:func:`contact_newton`)."""
        lateral, radius_table, angle_table, rise, roll = c.geometry_columns
        return self.kernels.contact_newton(
            sol.g, pred.w0, pred.wv0, constants['r0p'], constants['rv0'], sol.offset,
            sol.slope_offset, c.dw, constants['dr_model'], constants['rvel'], c.ey,
            constants['y_star'], rail.irr_y, rail.irr_z, rail.irr_dy, c.side,
            constants['creep'], lateral, radius_table, angle_table, rise, roll,
            float(c.params.contact_semi_distance), float(c.contact.conicity), float(c.r0),
            c.g_hertz, float(c.friction), c.nm.a1, float(speed), GEOMETRY_STEP, float(c.tol),
            int(c.max_iter), sol.y_rel, sol.delta, sol.eps)
