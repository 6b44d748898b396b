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
Vehicle-bridge interaction solved monolithically inside each Newmark step.

Quarter cars couple to the girder through the deflection w(x_i, t) under each
wheel. With the Newmark relations, the wheel displacement, velocity
(w_t + V w_x) and acceleration (w_tt + 2 V w_xt + V^2 w_xx) at the end of a step
are affine in the unknown girder displacement u_{n+1}, and so is each contact
force: R_i = w_i . u_{n+1} + b_i. The coupled effective matrix is therefore the
constant, once-factorised bridge matrix plus a rank-m update (m = number of
axles), solved exactly with the Woodbury identity: one multi-right-hand-side
substitution and an m x m dense solve per step. No lag, no iteration.

When the girder has at most :data:`DENSE_GIRDER_LIMIT` vertical DOFs, the block
of the inverse effective matrix among them (its Green's function on the girder)
is computed once, so a step needs two single-right-hand-side solves and a small
gather instead of the m + 1 right-hand sides: the same equations, in another order
of operations (equal to rounding). With a lean integrator (every solver variant but
``reference``) and numba installed, that step runs in the compiled kernels of
:mod:`ttb_sim.sim.coupling.quarter_car.wheel_kernels`, again equal to rounding; the ``reference``
variant keeps the numpy path, bit for bit.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

from ttb_sim.model.bridge import GirderLine
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.irregularity import GRID_SLACK, TrackIrregularity
from ttb_sim.model.structure import Structure
from ttb_sim.model.vehicle.train import QuarterCars
from ttb_sim.sim.coupling.base import (FreeDofState, girder_green, girder_wheel_load,
                                       VehicleOutputs)
from ttb_sim.sim.coupling.quarter_car import wheel_kernels
from ttb_sim.sim.coupling.quarter_car.condensed_girders import CondensedGirders, NO_INTERIORS
from ttb_sim.sim.integrators.protocol import Integrator

DENSE_GIRDER_LIMIT = 3000
"""Largest number of girder vertical DOFs whose inverse block is kept (72 MB at the limit)."""


class QuarterCarCoupling:
    """
    State and coupled step of quarter cars running on the girders.

    The vehicle state (sprung-mass displacement, velocity, acceleration, measured
    from static equilibrium) lives here; the girder state is passed in.

    ``compiled`` chooses the compiled kernels of the Green's-function step: None
    (the default) takes them when the integrator is lean and numba imports,
    False never, True whenever numba imports.
    """

    def __init__(self, cars: QuarterCars, girder: GirderLine, integrator: Integrator,
                 n_free: int, compiled: bool | None = None) -> None:
        self.cars = cars
        self.girder = girder
        self.nm = integrator
        self.n_free = n_free
        n = cars.axles.count
        self.z = np.zeros(n)
        self.v = np.zeros(n)
        self.a = np.zeros(n)
        self.contact = cars.static_load.copy()
        ms, k, c = cars.sprung_mass, cars.stiffness, cars.damping
        self._d = ms * integrator.a0 + c * integrator.a1 + k
        self._q = k + c * integrator.a1
        # Work arrays of the per-step solve, allocated once: right-hand sides
        # [load | one unit wheel load per axle] and their solutions, each with the
        # always-zero slot that stands for the constrained DOFs.
        self._cols = np.repeat(np.arange(1, n + 1), 4)
        self._rhs = np.zeros((n_free + 1, n + 1))
        self._sol = np.zeros((n_free + 1, n + 1))
        self._green: np.ndarray | None = None
        self._slot = np.zeros(0, dtype=np.intp)
        girder_dofs = np.unique(girder.w_dofs)
        girder_dofs = girder_dofs[girder_dofs < n_free]
        if 0 < girder_dofs.size <= DENSE_GIRDER_LIMIT:
            self._green, self._slot = girder_green(integrator, n_free, girder_dofs)
        if compiled is None:
            compiled = bool(getattr(integrator, 'lean', False))
        self.compiled = (compiled and self._green is not None
                         and wheel_kernels.available())
        """True when :meth:`step` runs the compiled kernels."""
        self.element = np.zeros(n, dtype=np.intp)
        """Element under each wheel at the latest compiled step."""
        self.n0 = np.zeros((n, 4))
        """Hermite rows of the deflection under each wheel at the latest compiled step."""
        self._kernels: tuple[Callable[..., Any], ...] = ()
        self.positions: np.ndarray | None = None
        """Axle positions of the latest compiled step (None: none yet)."""
        if self.compiled:
            self._dofs = np.zeros((n, 4), dtype=girder.w_dofs.dtype)
            self._w, self._p = np.zeros((n, 4)), np.zeros((n, 4))
            self._b, self._e = np.zeros(n), np.zeros(n)
            self._hs_v, self._hs_a = np.zeros(n), np.zeros(n)
            found = (wheel_kernels.KERNELS.compiled(name) for name in (
                'wheel_terms', 'green_correction', 'update_cars'))
            self._kernels = tuple(k for k in found if k is not None)

    def step(self, u: np.ndarray, v: np.ndarray, a: np.ndarray, force: np.ndarray,
             positions: np.ndarray, speed: float,
             profile: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Advance girder and vehicles together by one step.

        Parameters
        ----------
        u, v, a : arrays
            Girder state (free DOFs) at t_n.
        force : array
            Other loads on the free DOFs at t_{n+1}.
        positions : array
            Axle positions along the track at t_{n+1} (m).
        speed : float
            Train speed during the step (m/s).
        profile : (r, dr/dx, d2r/dx2), optional
            Vertical track irregularity under each wheel at t_{n+1} (m, z up).

        Returns
        -------
        (u, v, a) of the girder at t_{n+1}; the vehicle state and
        :attr:`contact` (force of the girder on each wheel, N, up) are updated.

        """
        if self.compiled:
            return self._step_compiled(u, v, a, force, positions, speed, profile)
        nm, cars, n_free = self.nm, self.cars, self.n_free
        a0, a1 = nm.a0, nm.a1
        h_v, h_a = nm.history(u, v, a)
        element, (n0, n1, n2) = self.girder.rows(positions, (0, 1, 2))
        dofs = self.girder.w_dofs[element]
        hv_e = np.append(h_v, 0.0)[dofs]
        ha_e = np.append(h_a, 0.0)[dofs]

        # Wheel kinematics at t_{n+1}: value = g . u_{n+1} + c, with the irregularity r
        # moving under the wheel: r, V r', V^2 r''.
        g_v = a1 * n0 + speed * n1
        g_a = a0 * n0 + 2.0 * speed * a1 * n1 + speed**2 * n2
        c_z = np.zeros(n0.shape[0])
        c_v = np.einsum('ij,ij->i', n0, hv_e)
        c_a = np.einsum('ij,ij->i', n0, ha_e) + 2.0 * speed * np.einsum('ij,ij->i', n1, hv_e)
        if profile is not None:
            c_z = c_z + profile[0]
            c_v = c_v + speed * profile[1]
            c_a = c_a + speed**2 * profile[2]

        ms, mu, k, c = cars.sprung_mass, cars.unsprung_mass, cars.stiffness, cars.damping
        hs_v = -a1 * self.z - self.v
        hs_a = -a0 * self.z - 2.0 * a1 * self.v - self.a
        d, q = self._d, self._q
        p = c[:, None] * g_v + k[:, None] * n0
        e = c * c_v + k * c_z - ms * hs_a - c * hs_v
        w = mu[:, None] * g_a + (ms * a0 / d)[:, None] * p
        b = (ms + mu) * GRAVITY + mu * c_a + k * c_z + c * c_v - q * e / d - c * hs_v

        m = n0.shape[0]
        if self._green is not None:
            return self._step_green(u, force, h_v, h_a, dofs, n0, w, b, p, e, hs_v, hs_a)
        rhs, sol = self._rhs, self._sol
        rhs.fill(0.0)
        flat = dofs.ravel()
        rhs[:, 0] = np.bincount(flat, weights=-(n0 * b[:, None]).ravel(), minlength=n_free + 1)
        # Each unit-load column holds one axle's four distinct DOFs; only the discarded
        # zero slot can repeat, so plain assignment is exact.
        rhs[flat, self._cols] = n0.ravel()
        rhs[:n_free, 0] += nm.effective_load(force, h_v, h_a)
        sol[:n_free] = nm.solve(rhs[:n_free])
        x0, z = sol[:, 0], sol[:, 1:]
        s = np.eye(m) + np.einsum('ik,ikj->ij', w, z[dofs])
        t = np.einsum('ik,ik->i', w, x0[dofs])
        u_ext = x0 - z @ np.linalg.solve(s, t)
        return self._finish(u_ext, dofs, w, b, p, e, hs_v, hs_a, h_v, h_a)

    def _finish(self, u_ext: np.ndarray, dofs: np.ndarray, w: np.ndarray, b: np.ndarray,
                p: np.ndarray, e: np.ndarray, hs_v: np.ndarray, hs_a: np.ndarray,
                h_v: np.ndarray, h_a: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Update the cars and contact forces from the girder state ``u_ext`` (zero slot last)."""
        nm = self.nm
        wu = np.einsum('ik,ik->i', p, u_ext[dofs])
        self.z = (e + wu) / self._d
        self.v = nm.a1 * self.z + hs_v
        self.a = nm.a0 * self.z + hs_a
        self.contact = np.einsum('ik,ik->i', w, u_ext[dofs]) + b
        u_new = u_ext[:self.n_free]
        v_new, a_new = nm.finish(u_new, h_v, h_a)
        return u_new, v_new, a_new

    def _step_green(self, u: np.ndarray, force: np.ndarray, h_v: np.ndarray, h_a: np.ndarray,
                    dofs: np.ndarray, n0: np.ndarray, w: np.ndarray, b: np.ndarray,
                    p: np.ndarray, e: np.ndarray, hs_v: np.ndarray,
                    hs_a: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Finish :meth:`step` with the girder Green's function (two single solves)."""
        nm, n_free, green = self.nm, self.n_free, self._green
        assert green is not None
        m = n0.shape[0]
        flat = dofs.ravel()
        base = nm.effective_load(force, h_v, h_a)
        load = np.bincount(flat, weights=-(n0 * b[:, None]).ravel(), minlength=n_free + 1)
        base = base + load[:n_free]
        x0 = np.append(nm.solve(base), 0.0)
        slots = self._slot[flat]
        block = green[slots][:, slots].reshape(m, 4, m, 4)
        left = np.einsum('ia,iajb->ijb', w, block)
        s = np.eye(m) + np.einsum('ijb,jb->ij', left, n0)
        t = np.einsum('ik,ik->i', w, x0[dofs])
        y = np.linalg.solve(s, t)
        unit = np.bincount(flat, weights=(n0 * y[:, None]).ravel(), minlength=n_free + 1)
        u_ext = np.append(nm.solve(base - unit[:n_free]), 0.0)
        return self._finish(u_ext, dofs, w, b, p, e, hs_v, hs_a, h_v, h_a)

    def _step_compiled(self, u: np.ndarray, v: np.ndarray, a: np.ndarray, force: np.ndarray,
                       positions: np.ndarray, speed: float,
                       profile: tuple[np.ndarray, np.ndarray, np.ndarray] | None,
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`step` with the Green's function, in the compiled kernels."""
        nm, cars = self.nm, self.cars
        wheel_terms, green_correction, update_cars = self._kernels
        h_v, h_a = nm.history(u, v, a)
        load = nm.effective_load(force, h_v, h_a)   # a new vector, ours to change
        r, r1, r2 = profile if profile is not None else (self._b, self._b, self._b)
        dofs, n0, w, p, b, e = self._dofs, self.n0, self._w, self._p, self._b, self._e
        wheel_terms(positions, float(speed), self.girder.element_length,
                    self.girder.n_spans * self.girder.elements_per_span, self.girder.length,
                    self.girder.w_dofs, h_v, h_a, nm.a0, nm.a1, profile is not None,
                    r, r1, r2, cars.sprung_mass, cars.unsprung_mass, cars.stiffness,
                    cars.damping, self._d, self._q, self.z, self.v, self.a, GRAVITY,
                    self.element, dofs, n0, w, p, b, e, self._hs_v, self._hs_a, load)
        x0 = np.asarray(nm.solve(load))
        green_correction(x0, self._green, self._slot, dofs, n0, w, load)
        u_new = np.asarray(nm.solve(load))
        update_cars(u_new, dofs, w, p, b, e, self._d, self._hs_v, self._hs_a, nm.a0, nm.a1,
                    self.z, self.v, self.a, self.contact)
        self.positions = positions
        v_new, a_new = nm.finish(u_new, h_v, h_a)
        return u_new, v_new, a_new


class QuarterCarTrain(FreeDofState):
    """
    Quarter cars on the girders as a :class:`~ttb_sim.sim.coupling.base.Coupling`.

    Owns the girder state and steps it with :class:`QuarterCarCoupling`, the
    wheels following the centreline vertical irregularity (r, V r', V^2 r'').

    Parameters
    ----------
    cars : QuarterCars
        One quarter car per axle.
    structure : Structure
        The assembled bridge.
    integrator : Integrator
        The structure's integrator.
    irregularity : TrackIrregularity or None
        The track irregularity (None: smooth).

    """

    def __init__(self, cars: QuarterCars, structure: Structure, integrator: Integrator,
                 irregularity: TrackIrregularity | None) -> None:
        self.cars = cars
        self.structure = structure
        self.nm = integrator
        self.irregularity = irregularity
        self.kernel = QuarterCarCoupling(cars, structure.girder, integrator, structure.n_free)
        self.n_axles = cars.axles_per_car
        """Axles per published car (:attr:`QuarterCars.axles_per_car`)."""
        self.n_bodies = cars.axles.count // cars.axles_per_car
        """Published cars: each the mean of its quarter cars' sprung masses."""
        n_free = structure.n_free
        self.u = np.zeros(n_free)
        self.v = np.zeros(n_free)
        self.a = np.zeros(n_free)
        self._zero = np.zeros(n_free)
        n = cars.axles.count
        self._r = (np.zeros(n), np.zeros(n), np.zeros(n))
        self._profile_kernel = (wheel_kernels.KERNELS.compiled('centreline_profile')
                                if self.kernel.compiled and irregularity is not None else None)
        self._fused: tuple[Any, ...] | None = None
        """(kernel, integrator arrays) of the compiled loop, () without it; None: not looked."""
        self._work: tuple[np.ndarray, ...] = ()
        self._arguments: tuple[tuple[Any, ...], tuple[Any, ...]] | tuple[()] = ()
        self._held: tuple[np.ndarray, ...] = ()
        """The state vectors the loop's arguments were made for (a new one: made again)."""
        self._condensed: CondensedGirders | None = None
        """The compiled loop's system with the piled piers' interiors condensed, or None."""

    def _profile(self, positions: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Return the centreline vertical irregularity r, r', r'' under the wheels."""
        if self.irregularity is None:
            return None
        if self._profile_kernel is not None:
            irr = self.irregularity
            self._profile_kernel(positions, irr.x_start, irr.dx, irr.values, irr.slopes,
                                 irr.curvatures, GRID_SLACK, *self._r)
            return self._r
        s = self.irregularity.sample(positions, outside='zero')
        return (0.5 * (s.value[0] + s.value[1]), 0.5 * (s.slope[0] + s.slope[1]),
                0.5 * (s.curvature[0] + s.curvature[1]))

    def start(self, head: float) -> None:
        """Start at rest, the static wheel loads on the girders."""
        st = self.structure
        load = girder_wheel_load(st.girder, st.n_full, head - self.cars.axles.offsets,
                                 self.cars.static_load)
        self.a = self.nm.initial_acceleration(self.u, self.v, load[st.free])

    def step(self, head: float, speed: float) -> None:
        """Advance girders and quarter cars together by one step."""
        positions = head - self.cars.axles.offsets
        self.u, self.v, self.a = self.kernel.step(self.u, self.v, self.a, self._zero,
                                                  positions, speed, self._profile(positions))

    @property
    def solved_dofs(self) -> int:
        """The girder-system DOFs a step solves: fewer with the piers' interiors condensed."""
        return self._condensed.size if self._condensed is not None else self.structure.n_free

    def fused(self) -> bool:
        """Tell whether :meth:`advance` runs the compiled loop (else it steps one by one)."""
        if self._fused is None:
            kernel = wheel_kernels.KERNELS.compiled('advance_quarter_cars')
            ok = kernel is not None and self.kernel.compiled
            self._condensed = CondensedGirders.of(self) if ok else None
            nm = self._condensed.nm if self._condensed is not None else self.nm
            arrays = nm.fused_arrays()
            self._fused = (kernel, arrays) if ok and arrays is not None else ()
        return bool(self._fused)

    def advance(self, head: float, speed: float, dt: float, steps: int,
                limit: float) -> tuple[float, int, float]:
        """
        Take up to ``steps`` coupled steps at ``speed`` from the head at ``head`` (compiled).

        Returns (head, steps taken, largest girder or sprung-mass displacement of the
        last step); fewer steps than asked when one exceeded ``limit`` or was not finite.
        """
        assert self.fused(), 'advance() needs the compiled loop: check fused() first'
        assert self._fused is not None
        kernel = self._fused[0]
        state = (self.u, self.v, self.a)
        if not self._arguments or any(held is not now for held, now in zip(self._held, state)):
            self._arguments = self._loop_arguments()   # first call, or a new state (start)
            self._held = state
        before, after = self._arguments
        out = kernel(float(head), float(speed), float(dt), int(steps), *before, *after,
                     GRAVITY, float(limit))
        if self._condensed is not None:
            self._condensed.expand(state)
        if out[1] > 0:   # the rows of the last step are those of these positions
            self.kernel.positions = self._work[3].copy()
        return out

    def _loop_arguments(self) -> tuple[tuple[Any, ...], tuple[Any, ...]]:
        """Return the compiled loop's constant arguments (arrays it reads or writes in place)."""
        k, cars, girder, n = self.kernel, self.cars, self.structure.girder, self.structure.n_free
        assert self._fused is not None
        condensed = self._condensed
        w_dofs, green, slot, nm = girder.w_dofs, k._green, k._slot, self.nm
        state: tuple[np.ndarray, ...] = (self.u, self.v, self.a)
        interiors = NO_INTERIORS
        if condensed is not None:
            state = condensed.start(state)
            w_dofs, green, slot = condensed.w_dofs, condensed.green, condensed.slot
            nm, interiors = condensed.nm, condensed.arguments
            n = condensed.size
        self._work = (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(cars.axles.count))
        irr = self.irregularity
        empty = np.zeros((4, 0))
        profile = ((float(irr.x_start), float(irr.dx), irr.values, irr.slopes, irr.curvatures,
                    GRID_SLACK) if irr is not None else (0.0, 1.0, empty, empty, empty, 0.0))
        before = (cars.axles.offsets.astype(np.float64), profile,
                  (float(girder.element_length), girder.n_spans * girder.elements_per_span,
                   float(girder.length), w_dofs),
                  (cars.sprung_mass, cars.unsprung_mass, cars.stiffness, cars.damping,
                   k._d, k._q), self._fused[1], nm.a0, nm.a1, green, slot)
        after = ((*state, k.z, k.v, k.a, k.contact),
                 (self._work[3], k.element, k._dofs, k.n0, k._w, k._p, k._b, k._e, k._hs_v,
                  k._hs_a, *self._r), (nm.history_buffer, *self._work[:3]), interiors)
        return before, after

    def structure_load(self, head: float) -> np.ndarray:
        """Return the wheel contact forces (the static loads at the start) on all DOFs."""
        st, kernel = self.structure, self.kernel
        positions = head - self.cars.axles.offsets
        if kernel.positions is not None and np.array_equal(kernel.positions, positions):
            # The rows of the latest compiled step are those of these positions.
            return np.bincount(st.girder.w_dofs_full[kernel.element].ravel(),
                               weights=(-kernel.contact[:, None] * kernel.n0).ravel(),
                               minlength=st.n_full)
        return girder_wheel_load(st.girder, st.n_full, head - self.cars.axles.offsets,
                                 self.kernel.contact)

    def monitored(self) -> tuple[np.ndarray, ...]:
        """Return the girder and sprung-mass displacements."""
        return self.u, self.kernel.z

    def vehicle_outputs(self) -> VehicleOutputs:
        """
        Return each car's body acceleration and its wheels' contact forces.

        A car's body acceleration is the mean vertical acceleration of its
        quarter cars' sprung masses (the bounce of a rigid body resting on them
        with equal shares; a quarter car has no pitch or roll, so the angular
        velocity is zero). Each wheel's contact force is split equally between
        the left and right rails.
        """
        n_b, n_a = self.n_bodies, self.n_axles
        acc = np.zeros((n_b, 3))
        acc[:, 2] = self.kernel.a.reshape(n_b, n_a).mean(axis=1)
        wheel_rail = np.zeros((n_b, n_a, 2, 3))
        wheel_rail[:, :, :, 2] = 0.5 * self.kernel.contact.reshape(n_b, n_a)[:, :, None]
        return VehicleOutputs(acc, np.zeros((n_b, 3)), wheel_rail)
