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
The stepping core: scenario -> assembled model -> Newmark steps -> frames.

:class:`Simulation` owns the model and the state and yields :class:`Frame`
objects at the output rate; it knows nothing about bags, ROS or plots.
"""

from __future__ import annotations

import logging
import math
from typing import Iterator

import numpy as np

from ttb_sim.config import parse_observers, Scenario
from ttb_sim.errors import DivergenceError
from ttb_sim.model.bridge import bearing_forces
from ttb_sim.model.irregularity import TrackIrregularity
from ttb_sim.model.vehicle.train import MovingForces, MultibodyCars, QuarterCars
from ttb_sim.sim.build import build_irregularity, build_structure, build_vehicle, observer_rows
from ttb_sim.sim.coupling.quarter_car import QuarterCarCoupling
from ttb_sim.sim.coupling.train_track import TrainTrackCoupling
from ttb_sim.sim.frames import Frame, Layout
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.lean import MovingLoad
from ttb_sim.sim.variants import blas_threads, solver_variant

log = logging.getLogger(__name__)

STEPS_PER_PERIOD = 200
"""Automatic time step: steps per fundamental (or vehicle) period."""
STEPS_PER_ELEMENT = 10
"""Automatic time step: steps for an axle to cross one girder element."""


def nice_step(dt: float) -> float:
    """Round a time step down to 1, 2 or 5 times a power of ten."""
    exponent = math.floor(math.log10(dt))
    for mantissa in (5.0, 2.0, 1.0):
        candidate = mantissa * 10.0**exponent
        if candidate <= dt * (1 + 1e-12):
            return candidate
    return 10.0**exponent  # pragma: no cover - unreachable


def auto_time_step(fundamental_frequency: float, element_length: float, speed: float,
                   vehicle_frequency: float | None = None,
                   profile_spacing: float | None = None,
                   max_step: float | None = None) -> float:
    """
    Pick the default time step.

    The rule: the smallest of T1/200 (T1 = first vertical bending period of a
    span), the time an axle takes to cross one tenth of a girder element,
    Tv/200 for a sprung vehicle (Tv = bounce period) and, on an irregular
    track, the time to cross one grid cell of the profile, and ``max_step``
    (wheel-rail contact); rounded down to 1, 2 or 5 x 10^k s. Newmark's period
    error at T/200 is 0.008 %.
    """
    candidates = [1.0 / (STEPS_PER_PERIOD * fundamental_frequency),
                  element_length / (STEPS_PER_ELEMENT * speed)]
    if vehicle_frequency:
        candidates.append(1.0 / (STEPS_PER_PERIOD * vehicle_frequency))
    if profile_spacing:
        candidates.append(profile_spacing / speed)
    if max_step:
        candidates.append(max_step)
    return nice_step(min(candidates))


CONTACT_STEP = 1e-4
"""Largest automatic time step with wheel-rail contact (s), the step of [P]."""


class Simulation:
    """
    One simulated passage of a train over the bridge.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.

    """

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario
        self.structure = build_structure(scenario)
        self.vehicle = build_vehicle(scenario)
        self.speed = scenario.train.speed
        st = self.structure
        vf = None
        self.irregularity: TrackIrregularity | None = None
        element = st.girder.element_length
        max_step = None
        if isinstance(self.vehicle, QuarterCars):
            vf = float(self.vehicle.natural_frequency().max())
            self.irregularity = build_irregularity(scenario, self.vehicle.axles.train_length,
                                                   st.girder.length)
        elif isinstance(self.vehicle, MultibodyCars):
            track = st.track
            max_step = CONTACT_STEP
            element = float(track.rails[0].length.min())
            self.irregularity = build_irregularity(scenario, self.vehicle.length,
                                                   st.girder.length,
                                                   (track.x_start, track.x_end))
        spacing = self.irregularity.dx if self.irregularity is not None else None
        dt = scenario.solver.dt or auto_time_step(st.fundamental_frequency, element,
                                                  self.speed, vf, spacing, max_step)
        rate = scenario.output.rate_hz
        if rate > 0:
            period = 1.0 / rate
            self.output_every = max(1, math.ceil(period / dt - 1e-9))
            dt = period / self.output_every
        else:
            self.output_every = 1
        self.dt = dt
        self.duration = scenario.solver.duration or self.auto_duration()
        self.n_steps = max(1, math.ceil(self.duration / dt - 1e-9))
        self.observers = observer_rows(scenario, st)
        names = tuple(o.name for o in parse_observers(scenario.output.observers))
        if isinstance(self.vehicle, MultibodyCars):
            n_bodies, n_axles = self.vehicle.n_cars, 4
        elif isinstance(self.vehicle, QuarterCars):
            n_bodies, n_axles = self.vehicle.axles.count, 1
        else:
            n_bodies, n_axles = 0, 1
        self.layout = Layout(n_spans=scenario.bridge.n_spans, n_supports=st.n_supports,
                             n_bodies=n_bodies, n_axles=n_axles, observers=names)
        self.variant = solver_variant(scenario.solver.variant)
        with blas_threads(self.variant.blas_threads):
            self.integrator = Newmark(st.mass, st.damping, st.stiffness, dt,
                                      method=self.variant.factorization,
                                      lean=self.variant.lean)
            self.coupling = (QuarterCarCoupling(self.vehicle, st.girder, self.integrator,
                                                st.n_free)
                             if isinstance(self.vehicle, QuarterCars) else None)
            self.train_track = (TrainTrackCoupling(scenario, st, self.integrator,
                                                   self.irregularity)
                                if isinstance(self.vehicle, MultibodyCars) else None)
        log.info('model: %d free DOFs, %d axles, dt = %.3g s, %d steps', st.n_free,
                 self.vehicle.axles.count, dt, self.n_steps)

    @property
    def exit_position(self) -> float:
        """Head position (m) at which the last axle leaves the bridge."""
        return self.structure.girder.length + self.vehicle.axles.train_length

    @property
    def n_frames(self) -> int:
        """Number of frames :meth:`frames` yields."""
        return self.n_steps // self.output_every + 1

    def auto_duration(self) -> float:
        """Return the time for the last axle to leave the bridge plus free vibration (s)."""
        travel = self.exit_position - self.scenario.train.start_position
        free = self.scenario.solver.free_vibration_periods / self.structure.fundamental_frequency
        return max(travel, 0.0) / self.speed + free

    def frames(self) -> Iterator[Frame]:
        """
        Step the model and yield a frame at t = 0 and at every output tick.

        :attr:`speed` is read at every step, so a caller may change it while
        iterating (the ROS node does); the number of steps stays as planned.
        The BLAS threads are limited as the solver variant says while the
        generator runs.

        Raises
        ------
        DivergenceError
            When the state becomes non-finite or exceeds solver.divergence_limit;
            every frame before the failure has already been yielded.

        """
        with blas_threads(self.variant.blas_threads):
            yield from self._frames()

    def _frames(self) -> Iterator[Frame]:
        if self.train_track is not None:
            yield from self._car_frames()
            return
        st, nm = self.structure, self.integrator
        n_free, dt = st.n_free, self.dt
        offsets = self.vehicle.axles.offsets
        u = np.zeros(n_free)
        v = np.zeros(n_free)
        head = self.scenario.train.start_position
        load_full = self._moving_load(head - offsets)
        a = nm.initial_acceleration(u, v, load_full[st.free])
        yield self._frame(0, head, u, v, a, load_full)
        zero = np.zeros(n_free)
        lean_load = (MovingLoad(st.girder, self.vehicle.loads, n_free, st.n_full)
                     if self.variant.lean and isinstance(self.vehicle, MovingForces) else None)
        for step in range(1, self.n_steps + 1):
            head += self.speed * dt
            positions = head - offsets
            if lean_load is not None:
                u, v, a = nm.step(u, v, a, lean_load(positions))
                if step % self.output_every == 0:
                    load_full = lean_load.full(positions)
            elif self.coupling is None:
                load_full = self._moving_load(positions)
                u, v, a = nm.step(u, v, a, load_full[st.free])
            else:
                u, v, a = self.coupling.step(u, v, a, zero, positions, self.speed,
                                             self._profile(positions))
            self._check_state(step, u, *(() if self.coupling is None else (self.coupling.z,)))
            if step % self.output_every == 0:
                if self.coupling is not None:
                    load_full = self._wheel_load(positions, self.coupling.contact)
                yield self._frame(step, head, u, v, a, load_full)

    def _check_state(self, step: int, *displacements: np.ndarray) -> None:
        """Raise DivergenceError if any displacement is not finite or exceeds the limit."""
        limit = self.scenario.solver.divergence_limit
        peak = max((float(np.max(np.abs(d))) for d in displacements if d.size), default=0.0)
        if not math.isfinite(peak) or peak > limit:
            raise DivergenceError(
                f'solution diverged at t = {step * self.dt:.6g} s (step {step}): largest '
                f'displacement {peak:.3g} m exceeds solver.divergence_limit = {limit:g} m '
                'or is not finite; try a smaller solver.dt')

    def _car_frames(self) -> Iterator[Frame]:
        """Step multibody cars on the slab track (see :mod:`ttb_sim.sim.coupling.train_track`)."""
        tt, dt = self.train_track, self.dt
        head = self.scenario.train.start_position
        tt.equilibrium(head)
        yield self._car_frame(0, head)
        for step in range(1, self.n_steps + 1):
            head += self.speed * dt
            tt.step(head, self.speed)
            self._check_state(step, tt.u, tt.q)
            if step % self.output_every == 0:
                yield self._car_frame(step, head)

    def _car_frame(self, step: int, head: float) -> Frame:
        tt, st = self.train_track, self.structure
        ue, ve, ae = (np.append(x, 0.0) for x in (tt.u, tt.v, tt.a))
        n = tt.n_cars
        return Frame(step=step, time=step * self.dt, head_position=head, speed=self.speed,
                     midspan=ue[st.midspan_dofs],
                     bearings=bearing_forces(st, ue, ve, ae, np.zeros(st.n_full)),
                     body_acceleration=tt.qa[:, 0:3].copy(),
                     body_angular_velocity=tt.qv[:, 3:6].copy(),
                     wheel_rail=tt.force[..., :3].reshape(n, 4, 2, 3).copy(),
                     observers=self._observe(ue))

    def _observe(self, ue: np.ndarray) -> np.ndarray:
        dofs, rows = self.observers
        return np.einsum('oij,oj->oi', rows, ue[dofs])

    def _profile(self, positions: np.ndarray) -> tuple[np.ndarray, ...] | None:
        """Return the centreline vertical irregularity r, r', r'' under the wheels."""
        if self.irregularity is None:
            return None
        s = self.irregularity.sample(positions, outside='zero')
        return tuple(0.5 * (q[0] + q[1]) for q in (s.value, s.slope, s.curvature))

    def _moving_load(self, positions: np.ndarray) -> np.ndarray:
        if isinstance(self.vehicle, MovingForces):
            return self._wheel_load(positions, self.vehicle.loads)
        if isinstance(self.vehicle, QuarterCars):
            return self._wheel_load(positions, self.vehicle.static_load)
        return np.zeros(self.structure.n_full)  # pragma: no cover

    def _wheel_load(self, positions: np.ndarray, forces: np.ndarray) -> np.ndarray:
        """Return the full-DOF load of downward wheel forces at the given positions."""
        girder = self.structure.girder
        element, (n0,) = girder.rows(positions)
        return np.bincount(girder.w_dofs_full[element].ravel(),
                           weights=(-forces[:, None] * n0).ravel(),
                           minlength=self.structure.n_full)

    def _frame(self, step: int, head: float, u: np.ndarray, v: np.ndarray, a: np.ndarray,
               load_full: np.ndarray) -> Frame:
        st = self.structure
        ue, ve, ae = (np.append(x, 0.0) for x in (u, v, a))
        n_b = self.layout.n_bodies
        acc = np.zeros((n_b, 3))
        wheel_rail = np.zeros((n_b, 1, 2, 3))
        if self.coupling is not None:
            acc[:, 2] = self.coupling.a
            wheel_rail[:, 0, :, 2] = 0.5 * self.coupling.contact[:, None]
        return Frame(step=step, time=step * self.dt, head_position=head, speed=self.speed,
                     midspan=ue[st.midspan_dofs],
                     bearings=bearing_forces(st, ue, ve, ae, load_full),
                     body_acceleration=acc, body_angular_velocity=np.zeros((n_b, 3)),
                     wheel_rail=wheel_rail, observers=self._observe(ue))
