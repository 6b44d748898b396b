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
from typing import Any, Iterator

import numpy as np

from ttb_sim.config import Scenario
from ttb_sim.config.sensor_places import gauge_requests, probe_requests
from ttb_sim.errors import DivergenceError, ModelError, ScenarioError
from ttb_sim.fe.compiled import parallel_threads, pending
from ttb_sim.model.bearings import bearing_forces
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.vehicle.train import MultibodyCars
from ttb_sim.sim.build import (build_coupling, build_structure, build_vehicle, observer_rows,
                               probe_rows, vehicle_track_setup)
from ttb_sim.sim.cost import CostEstimate, estimate_cost, STEP_BUDGET
from ttb_sim.sim.coupling import FusedCoupling
from ttb_sim.sim.frames import Frame, Layout
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.substructure.piled_piers import (InterfaceCheck, pile_coordinates,
                                                  PiledFoundations, PileGauges, PileOutputs,
                                                  RigidDisplacement)
from ttb_sim.sim.variants import blas_threads, resolve_threads, solver_variant

log = logging.getLogger(__name__)

STEPS_PER_PERIOD = 200
"""Automatic time step: steps per fundamental (or vehicle) period."""
STEPS_PER_ELEMENT = 10
"""Automatic time step: steps for an axle to cross one girder element."""
HARD_STEP_LIMIT = 1e12
"""Most time steps any run may plan, even with no budget (a step count must stay countable)."""


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


class Simulation:
    """
    One simulated passage of a train over the bridge.

    Parameters
    ----------
    scenario : Scenario
        A validated scenario.
    max_steps : float or None
        Step budget: a plan of more time steps is refused before the
        integrator is built (None: no budget, as ``ttb-sim run --force``).

    Raises
    ------
    ScenarioError
        If the planned steps exceed ``max_steps`` (or cannot be counted at
        all), naming solver.dt and solver.duration.

    """

    def __init__(self, scenario: Scenario, max_steps: float | None = STEP_BUDGET) -> None:
        self.scenario = scenario
        self.structure = build_structure(scenario)
        self.vehicle = build_vehicle(scenario)
        self._speed = scenario.train.speed
        st = self.structure
        self.observers = observer_rows(scenario, st)
        self.probes = probe_rows(probe_requests(scenario.all_sensors), st)
        limits, self.irregularity = vehicle_track_setup(scenario, st, self.vehicle)
        element, vf, max_step = limits.element_length, limits.vehicle_frequency, limits.max_step
        spacing = self.irregularity.dx if self.irregularity is not None else None
        self.auto_dt = auto_time_step(st.fundamental_frequency, element, self.speed, vf,
                                      spacing, max_step)
        dt = scenario.solver.dt or self.auto_dt
        self.duration = scenario.solver.duration or self.auto_duration()
        self._check_plan(dt, max_steps)
        rate = scenario.output.rate_hz
        if rate > 0:
            period = 1.0 / rate
            self.output_every = max(1, math.ceil(period / dt - 1e-9))
            dt = period / self.output_every
        else:
            self.output_every = 1
        self.dt = dt
        self.n_steps = max(1, math.ceil(self.duration / dt - 1e-9))
        names = tuple(o.name for o in scenario.output.points)
        self.variant = solver_variant(scenario.solver.variant)
        self.threads = resolve_threads(scenario.solver.threads, self.variant)
        """The threads of the parallel kernels (``solver.threads``), chosen once."""
        with blas_threads(self.variant.blas_threads):
            self.integrator = Newmark(st.mass, st.damping, st.stiffness, dt,
                                      method=self.variant.factorization,
                                      lean=self.variant.lean,
                                      fused=self.variant.fused)
            self.coupling = build_coupling(scenario, st, self.vehicle, self.integrator,
                                           self.irregularity, lean=self.variant.lean,
                                           reduced=self.variant.reduced,
                                           rail_steps=self.variant.rail_steps(scenario))
        self.foundations = PiledFoundations(st, dt,
                                            scenario.solver.substructure_steps)
        self.rigid = RigidDisplacement(st)
        b, pr = scenario.bridge, scenario.piers
        self.interface = InterfaceCheck(st, GRAVITY * (b.mass_per_length * b.span_length
                                                       + pr.mass_per_length * pr.height))
        self.gauges = PileGauges.of(st, [(g.pier, g.pile, g.depth)
                                         for g in gauge_requests(scenario.all_sensors)])
        """The pile strain gauges the sensors read (through the reduction basis)."""
        self.pile_outputs = PileOutputs(st, self.foundations, self.gauges)
        self.layout = Layout(n_spans=scenario.bridge.n_spans, n_supports=st.n_supports,
                             n_bodies=self.coupling.n_bodies, n_axles=self.coupling.n_axles,
                             observers=names,
                             piles=tuple((p.support + 1, p.operator.n_piles) for p in st.piled),
                             soil_points=sum(len(p.operator.soil_point_names)
                                             for p in st.piled),
                             piers=tuple(k + 1 for k in st.pier_supports),
                             soil_point_names=tuple(f'pier{p.support + 1:02d}/{name}'
                                                    for p in st.piled
                                                    for name in p.operator.soil_point_names),
                             probes=len(self.probes.states), pile_gauges=self.gauges.count)
        self._no_load = np.zeros(0)
        self._state = np.zeros((3, 0))
        self.compiled_loop = False
        """True once :meth:`frames` steps in the coupling's compiled loop (``realtime``)."""
        log.info('model: %d free DOFs, %d axles, dt = %.3g s, %d steps', st.n_free,
                 self.vehicle.axles.count, dt, self.n_steps)

    def _check_plan(self, dt: float, max_steps: float | None) -> None:
        """Refuse a plan over the step budget; warn about a step above the accuracy rule."""
        solver = self.scenario.solver
        steps = self.duration / dt
        dt_text = (f'solver.dt = {dt:.3g} s' if solver.dt
                   else f'dt = {dt:.3g} s (automatic)')
        duration_text = (f'solver.duration = {self.duration:.6g} s' if solver.duration
                         else f'solver.duration = 0 (automatic: {self.duration:.6g} s)')
        limit = HARD_STEP_LIMIT if max_steps is None else min(max_steps, HARD_STEP_LIMIT)
        if not steps <= limit:
            hint = '' if max_steps is None or max_steps >= HARD_STEP_LIMIT else (
                ', or pass --force to run it anyway')
            raise ScenarioError(
                f'{duration_text} at {dt_text} plans {steps:.3g} time steps, over the '
                f'budget of {limit:.3g}: raise solver.dt, set a shorter solver.duration'
                f'{hint}')
        period = 1.0 / self.structure.fundamental_frequency
        accurate = period / STEPS_PER_PERIOD
        if solver.dt and solver.dt > accurate * (1.0 + 1e-9):
            log.warning('solver.dt = %.3g s exceeds the accuracy rule T1/%d = %.3g s (T1 = '
                        '%.3g s, first bending period of a span): the Newmark period error '
                        'grows as dt^2 (0.008 %% at T1/200, %.2g %% here); the automatic '
                        'step would be %.3g s', solver.dt, STEPS_PER_PERIOD, accurate, period,
                        0.008 * (solver.dt / accurate) ** 2, self.auto_dt)

    @property
    def speed(self) -> float:
        """Current train speed in m/s; every step reads it."""
        return self._speed

    def set_speed(self, speed: float) -> None:
        """
        Change the train speed from the next step on (the node's live speed change).

        Raises
        ------
        ModelError
            If ``speed`` is not a finite positive number (m/s).

        """
        if not (isinstance(speed, (int, float)) and math.isfinite(speed) and speed > 0.0):
            raise ModelError(f'train speed = {speed!r} m/s is invalid; allowed: finite and > 0')
        self._speed = float(speed)

    @property
    def exit_position(self) -> float:
        """Head position (m) at which the last axle leaves the bridge."""
        return self.structure.girder.length + self.vehicle.axles.train_length

    @property
    def n_frames(self) -> int:
        """Number of frames :meth:`frames` yields."""
        return self.n_steps // self.output_every + 1

    @property
    def n_free(self) -> int:
        """Free DOFs of the structure."""
        return self.structure.n_free

    def plan(self, messages_per_frame: int) -> CostEstimate:
        """Return the cost estimate of the run (before it runs)."""
        return estimate_cost(steps=self.n_steps, dt=self.dt, free_dofs=self.n_free,
                             cars=self.vehicle.n_cars if isinstance(self.vehicle, MultibodyCars)
                             else 0,
                             frames=self.n_frames, messages_per_frame=messages_per_frame,
                             variant=self.scenario.solver.variant,
                             threads=self.threads.describe(), compiling=pending())

    def describe(self) -> dict[str, Any]:
        """Return stepping details for ``summary.json`` (the solver section has the rest)."""
        about: dict[str, Any] = {'variant': self.scenario.solver.variant,
                                 'compiled_loop': self.compiled_loop}
        st = self.structure
        if st.piled:
            solver = self.scenario.solver
            blocks = sum(p.operator.size for p in st.piled if p.block is not None)
            about['coupling'] = {'scheme': solver.coupling,
                                 'substructure_steps': solver.substructure_steps,
                                 'substructure_dt': self.dt * solver.substructure_steps}
            about['dofs'] = {'train_track_bridge': st.n_free - blocks,
                             'piled_piers': {f'pier{p.support + 1:02d}': {
                                 'coordinates': p.operator.size, **p.operator.summary}
                                 for p in st.piled}}
            about['rigid_displacement'] = self.rigid.summary()
            about['interface_mobilisation'] = self.interface.summary()
        return about

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
        with blas_threads(self.variant.blas_threads), parallel_threads(self.threads.count):
            yield from self._frames()

    def _frames(self) -> Iterator[Frame]:
        cp, dt = self.coupling, self.dt
        head = self.scenario.train.start_position
        fd = self.foundations if self.foundations.active else None
        cp.start(head)
        loop = (cp if fd is None and self.variant.fused and isinstance(cp, FusedCoupling)
                and cp.fused() else None)
        self.compiled_loop = loop is not None
        if loop is not None:   # compile (or load from numba's cache) before the first frame
            loop.advance(head, self.speed, dt, 0, self.scenario.solver.divergence_limit)
        yield self._frame(0, head)
        if loop is not None:
            yield from self._fused_frames(loop, head)
            return
        for step in range(1, self.n_steps + 1):
            head += self.speed * dt
            if fd is not None:
                fd.before_step(cp.load_bridge)
            cp.step(head, self.speed)
            if fd is not None:
                fd.after_step(cp.bridge_state)
                self._check_state(step, *cp.monitored(), *(s.u for s in fd.current()))
            else:
                self._check_state(step, *cp.monitored())
            if step % self.output_every == 0:
                yield self._frame(step, head)

    def _fused_frames(self, cp: FusedCoupling, head: float) -> Iterator[Frame]:
        """
        Step frame to frame in the coupling's compiled loop (``realtime``, :class:`FusedCoupling`).

        The same steps as the loop of :meth:`_frames`: the speed is read once per
        frame interval (a caller changes it between frames), the divergence check
        runs at every step inside the loop.
        """
        limit = self.scenario.solver.divergence_limit
        step = 0
        while step < self.n_steps:
            ask = min(self.output_every - step % self.output_every, self.n_steps - step)
            head, taken, peak = cp.advance(head, self.speed, self.dt, ask, limit)
            step += taken
            if taken < ask or not (math.isfinite(peak) and peak <= limit):
                self._diverged(step, peak)
            if step % self.output_every == 0:
                yield self._frame(step, head)

    def _diverged(self, step: int, peak: float) -> None:
        """Raise the DivergenceError of a state whose largest displacement is ``peak``."""
        limit = self.scenario.solver.divergence_limit
        raise DivergenceError(
            f'solution diverged at t = {step * self.dt:.6g} s (step {step}): largest '
            f'displacement {peak:.3g} m exceeds solver.divergence_limit = {limit:g} m '
            'or is not finite; try a smaller solver.dt')

    def _check_state(self, step: int, *displacements: np.ndarray) -> None:
        """Raise DivergenceError if any displacement is not finite or exceeds the limit."""
        limit = self.scenario.solver.divergence_limit
        peak = max((float(np.max(np.abs(d))) for d in displacements if d.size), default=0.0)
        if not math.isfinite(peak) or peak > limit:
            self._diverged(step, peak)

    def _observe(self, ue: np.ndarray) -> np.ndarray:
        dofs, rows = self.observers
        return np.einsum('oij,oj->oi', rows, ue[dofs])

    def _extended(self, state: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
        """
        Return the structure state with the always-zero slot appended (as ``np.append``).

        Written into one work array that the next frame overwrites: a frame keeps
        only values gathered from it.
        """
        n = state[0].shape[0]
        if self._state.shape[1] != n + 1:
            self._state = np.zeros((len(state), n + 1))
        for row, values in zip(self._state, state):
            row[:n] = values
        return tuple(self._state)

    def _frame(self, step: int, head: float) -> Frame:
        st, cp = self.structure, self.coupling
        ue, ve, ae = self._extended(cp.structure_state())
        vehicle = cp.vehicle_outputs()
        tops = self.foundations.top_states() if self.foundations.active else None
        pier_tops, pier_acc = ue[st.pier_top_dofs], ae[st.pier_top_dofs]
        if tops is not None:   # partitioned piled piers: their tops are not structure DOFs
            moving = np.asarray(st.pier_supports)
            outside = st.pier_top_dofs == st.n_free
            pier_tops = np.where(outside, tops[0][moving, :3], pier_tops)
            pier_acc = np.where(outside, tops[2][moving, :3], pier_acc)
        piles = self.pile_outputs(ue, ve, ae)
        if piles:
            self.rigid.update(ue[st.midspan_dofs], piles['pile_displacement'])
            self.interface.update(pile_coordinates(st, self.foundations, ue))
        # The applied load enters only the reactions of rigid supports.
        load = cp.structure_load(head) if st.bearings is None else self._no_load
        moved = None if tops is None else tops[:2]
        return Frame(step=step, time=step * self.dt, head_position=head, speed=self.speed,
                     midspan=ue[st.midspan_dofs],
                     bearings=bearing_forces(st, ue, ve, ae, load, moved),
                     body_acceleration=vehicle.body_acceleration,
                     body_angular_velocity=vehicle.body_angular_velocity,
                     wheel_rail=vehicle.wheel_rail, observers=self._observe(ue),
                     pier_tops=pier_tops, probes=self.probes.values(self._state),
                     pier_top_acceleration=pier_acc, **piles)
