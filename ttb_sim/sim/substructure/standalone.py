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
A pile-soil substructure alone under its head load, stepped to frames.

:class:`SubstructureRun` is what ``ttb-sim run`` and the node step when a
scenario's ``load.type`` is not 'none' (``single_pile``, ``pile_harmonic``):
the group is ``pier01``, its piles and soil points fill the pile and soil
fields of each :class:`~ttb_sim.sim.frames.Frame`. It offers the same run
interface as :class:`~ttb_sim.sim.simulation.Simulation` (layout, dt, steps,
frames, cost estimate), so the bag writer and the node need not know which
model they step.

Solver: ``solver.variant`` as :mod:`ttb_sim.sim.variants` maps it.
``reference`` is the fully implicit Newmark method (every DOF in one
factorised system; a static load by a direct solve of each Newton iteration),
the simple validated path, refused before anything is built when its factor
would not fit in memory (:func:`reference_refusal`). Every other variant runs
the mixed scheme of :mod:`ttb_sim.sim.substructure.stepping` (explicit soil and boundary,
implicit piles, cap and interface; a static load by preconditioned conjugate
gradients), the pile block factorised by the variant's method.

Time step: ``solver.dt`` (0 = automatic, 1/40 of the load period) is the
largest step wanted; the stable step of the explicit soil of the mixed scheme
caps it, in the ``reference`` too, so that both schemes take the same steps
and differ only in how the soil is integrated. The step is then
shortened so that frames (``output.rate_hz``; 0 = one per wanted step) fall
on steps. A static load gives one frame at t = 0 with the static solution.
"""

from __future__ import annotations

import logging
import math
from typing import Any, Iterator, Literal

import numpy as np
import scipy.sparse as sp

from ttb_sim.config import Scenario
from ttb_sim.config.sensor_places import gauge_requests, GaugeRequest
from ttb_sim.errors import DivergenceError, ScenarioError
from ttb_sim.fe.factorization import resolve
from ttb_sim.model.foundation.observation import gauge_rows
from ttb_sim.model.foundation.records import FoundationError
from ttb_sim.model.foundation.soil_mesh import CAP, PILE, planned_nodes, SOIL
from ttb_sim.model.foundation.substructure import build, PileSoilModel
from ttb_sim.sim.cost import CostEstimate, STEP_BUDGET
from ttb_sim.sim.frames import Frame, Layout
from ttb_sim.sim.substructure.stable_step import implicit_dofs, mixed_stable_step
from ttb_sim.sim.substructure.state import initial_state, observe, State
from ttb_sim.sim.substructure.statics import static_solve
from ttb_sim.sim.substructure.stepping import PartitionedNewmark
from ttb_sim.sim.variants import blas_threads, solver_variant, VARIANTS

__all__ = ['SubstructureRun', 'AUTO_STEPS_PER_PERIOD', 'AUTO_PERIODS', 'reference_refusal',
           'IMPLICIT_MAX_DOFS']

log = logging.getLogger(__name__)

AUTO_STEPS_PER_PERIOD = 40
"""Steps per load period of the automatic ``solver.dt``."""
AUTO_PERIODS = 40
"""Load periods of the automatic ``solver.duration`` (2 s at [P]'s 20 Hz)."""
MICROSECONDS_PER_CELL_STEP = 1.0
"""Estimated cost of one brick for one step (measured 0.63 us of CPU on pile_harmonic)."""
MICROSECONDS_PER_CELL_STEP_IMPLICIT = 6.0
"""The same for the fully implicit reference (measured 4.8 us of CPU on single_pile, 47 520
DOFs, and on a 6 120-DOF coarse mesh: the factor's solve, twice per step with the interface
iterations)."""
MESSAGE_MS = 0.08
"""Cost of writing one message to the bag (ms), as :mod:`ttb_sim.sim.cost`."""
IMPLICIT_MAX_DOFS = 100_000
"""Most DOFs the fully implicit scheme factorises (an estimated 1 GiB factor)."""
FACTOR_MIB_PER_DOF43 = 2.3e-4
"""Memory of the implicit factor per DOF^(4/3) (MiB): the nested-dissection growth of a 3-D
mesh, fitted to the peak-memory growth measured while factorising coarse single_pile meshes
(177 MiB at 25 635 DOFs, 272 MiB at 35 916 DOFs: exponent 1.27)."""


def implicit_factor_mib(dofs: int) -> float:
    """Return the estimated memory (MiB) of the fully implicit factor of ``dofs`` DOFs."""
    return FACTOR_MIB_PER_DOF43 * float(dofs) ** (4.0 / 3.0)


def reference_refusal(scenario: Scenario) -> str | None:
    """
    Return why the scenario's variant cannot step its substructure, or None if it can.

    Only the fully implicit scheme (``reference``) has a limit: its factor grows as
    DOFs^(4/3), so above :data:`IMPLICIT_MAX_DOFS` (estimated from the planned mesh,
    before anything is built) it is refused.
    """
    variant = solver_variant(scenario.solver.variant)
    if not scenario.substructure_only or variant.pile_soil_scheme != 'implicit':
        return None
    dofs = 3 * planned_nodes(scenario.substructure('pier01'))
    if dofs <= IMPLICIT_MAX_DOFS:
        return None
    others = ', '.join(repr(n) for n, v in VARIANTS.items() if v.pile_soil_scheme != 'implicit')
    gib = implicit_factor_mib(dofs) / 1024.0
    return (f'solver.variant = {variant.name!r}: the fully implicit reference would factorise '
            f'about {dofs} pile-soil DOFs (factor about {gib:.2g} GiB); allowed up to '
            f'{IMPLICIT_MAX_DOFS} DOFs: use one of {others}, or coarsen soil.mesh.h')


class SubstructureRun:
    """
    The pile-soil substructure of a scenario, built and ready to step.

    Parameters
    ----------
    scenario : Scenario
        A scenario whose ``load.type`` is not 'none'.
    max_steps : float or None
        Step budget (None: no budget but the hard limit); a plan above it is
        refused before the model is built.

    Raises
    ------
    ScenarioError
        For a plan over the step budget.

    """

    def __init__(self, scenario: Scenario, max_steps: float | None = STEP_BUDGET) -> None:
        if not scenario.substructure_only:
            raise ScenarioError("load.type = 'none': the scenario is not a substructure run")
        refusal = reference_refusal(scenario)
        if refusal is not None:
            raise ScenarioError(refusal)
        self.variant = solver_variant(scenario.solver.variant)
        self.scenario = scenario
        self.load = scenario.load
        self.static = self.load.type == 'static'
        solver = scenario.solver
        frequency = self.load.frequency
        if self.static:
            self.duration = 0.0
            wanted = 0.0
        else:
            self.duration = solver.duration or AUTO_PERIODS / frequency
            wanted = solver.dt or 1.0 / (AUTO_STEPS_PER_PERIOD * frequency)
            steps = self.duration / wanted
            if max_steps is not None and not steps <= max_steps:
                raise ScenarioError(
                    f'solver.duration = {self.duration:.6g} s at a step of {wanted:.3g} s '
                    f'plans {steps:.3g} time steps, over the budget of {max_steps:.3g}: '
                    'raise solver.dt or shorten solver.duration, or pass --force')
        self.model: PileSoilModel = build(scenario.substructure('pier01'), self.load)
        self.force = self.model.load_vector(self.load)
        model = self.model
        gauges = gauge_requests(scenario.all_sensors)
        self.gauges = self._gauge_rows(gauges)
        """The pile strain gauges' rows over the model's DOFs (apply to u)."""
        self.layout = Layout(n_spans=0, n_supports=0, n_bodies=0,
                             piles=((1, model.n_piles),),
                             soil_points=len(model.soil_points.names), train=False,
                             soil_point_names=tuple(f'pier01/{name}'
                                                    for name in model.soil_points.names),
                             pile_gauges=len(gauges))
        self.scheme: Literal['mixed', 'implicit'] = (
            'implicit' if self.variant.pile_soil_scheme == 'implicit' else 'mixed')
        self.stable_step = math.inf
        self.integrator: PartitionedNewmark | None = None
        self.factorization = resolve(self.variant.pile_soil_factorization)
        """Factorisation method in use (after any fallback)."""
        if self.static:
            self.dt, self.n_steps, self.output_every = 0.0, 0, 1
            return
        self.stable_step = mixed_stable_step(model)
        # the largest step both wanted and stable, shortened so that frames fall on steps
        largest = min(wanted, self.stable_step)
        rate = scenario.output.rate_hz
        period = 1.0 / rate if rate > 0 else wanted
        self.output_every = max(1, math.ceil(period / largest - 1e-9))
        dt = period / self.output_every
        if rate <= 0:
            self.output_every = 1
        self.dt = dt
        self.n_steps = max(1, math.ceil(self.duration / dt - 1e-9))
        if max_steps is not None and self.n_steps > max_steps:
            raise ScenarioError(
                f'the soil needs steps of at most {self.stable_step:.3g} s (explicit '
                f'stability): solver.duration = {self.duration:.6g} s plans {self.n_steps} '
                f'steps, over the budget of {max_steps:.3g}; shorten solver.duration or '
                'coarsen soil.mesh.h, or pass --force')
        self.integrator = PartitionedNewmark(model, dt, self.scheme,
                                             factorization=self.factorization)
        log.info('pile-soil: %s scheme, dt = %.4g s (stable %.4g s), %d steps, %d DOFs',
                 self.scheme, dt, self.stable_step, self.n_steps, model.n_dofs)

    @property
    def n_free(self) -> int:
        """Free DOFs of the substructure."""
        return int(self.model.free.sum())

    @property
    def n_frames(self) -> int:
        """Frames the run will write (the initial one included)."""
        return 1 + self.n_steps // self.output_every

    def describe(self) -> dict[str, Any]:
        """
        Return the model's sizes and the stepping plan (for ``summary.json``).

        ``interface_solve`` holds the counts of the interface iterations so far
        (:meth:`PartitionedNewmark.report`: linear solves, (sub-)steps solved by
        the full Newton line search, steps cut into sub-steps and the halvings
        made), or None for a static load.
        """
        return {'pile_soil': dict(self.model.summary), 'scheme': self.scheme,
                'variant': self.variant.name, 'factorization': self.factorization,
                'stable_step': None if math.isinf(self.stable_step) else self.stable_step,
                'load': self.load.type,
                'interface_solve': None if self.integrator is None else self.integrator.report()}

    def plan(self, messages_per_frame: int) -> CostEstimate:
        """Return the cost estimate of the run (before it runs)."""
        cells = len(self.model.mesh.cells)
        per_brick = (MICROSECONDS_PER_CELL_STEP_IMPLICIT if self.scheme == 'implicit'
                     else MICROSECONDS_PER_CELL_STEP)
        per_step = per_brick * cells / 1000.0
        messages = self.n_frames * messages_per_frame
        wall = 0.3 + (self.n_steps * per_step + messages * MESSAGE_MS) / 1000.0
        if self.static:
            wall += 2e-5 * self.n_free  # conjugate gradients, measured order of magnitude
        return CostEstimate(steps=self.n_steps, dt=self.dt, duration=self.duration,
                            free_dofs=self.n_free, cars=0, frames=self.n_frames,
                            messages=messages, per_step_ms=per_step, wall_time=wall)

    def frames(self) -> Iterator[Frame]:
        """
        Yield one frame at t = 0 and then every ``output_every`` steps.

        Raises
        ------
        DivergenceError
            When a displacement is not finite or exceeds
            ``solver.divergence_limit`` (the frames before it were yielded).

        """
        # Vector operations of this size gain nothing from BLAS threads, which only spin
        # (measured: static single_pile 3x faster with one thread on a loaded machine).
        with blas_threads(1):
            if self.static:
                yield self._frame(0, static_solve(
                    self.model, self.force, direct=self.scheme == 'implicit',
                    factorization=self.factorization))
                return
            assert self.integrator is not None
            state = initial_state(self.model)
            yield self._frame(0, state)
            history = self.load.history
            previous = history(0.0)
            for step in range(1, self.n_steps + 1):
                factor = history(step * self.dt)
                state = self.integrator.step(state, self.force, factor, start_factor=previous)
                previous = factor
                if step % self.output_every == 0:
                    yield self._frame(step, state)
            counts = self.integrator.report()
            if counts['cut_steps'] or counts['line_searches']:
                log.warning('pile-soil: %d of %d steps cut into sub-steps (%d halvings), %d '
                            '(sub-)steps solved by the full Newton line search',
                            counts['cut_steps'], self.n_steps, counts['cuts'],
                            counts['line_searches'])

    def _gauge_rows(self, gauges: tuple[GaugeRequest, ...]) -> sp.csr_matrix:
        """Return the strain rows of the gauges (the group is pier01)."""
        for g in gauges:
            if g.pier != 1:
                raise ScenarioError(f'a strain gauge at pier{g.pier:02d}/pile{g.pile:02d}: a '
                                    'substructure alone is pier01')
        model = self.model
        try:
            return gauge_rows(model.pile_strain, model.pile_layer_depths,
                              [(g.pile - 1, g.depth) for g in gauges])
        except FoundationError as exc:
            raise ScenarioError(f'pile strain gauge: {exc}') from None

    def _frame(self, step: int, state: State) -> Frame:
        limit = self.scenario.solver.divergence_limit
        largest = float(np.max(np.abs(state.u), initial=0.0))
        if not largest <= limit:
            raise DivergenceError(f'pile-soil displacement {largest:.3g} m at t = '
                                  f'{state.time:.6g} s exceeds solver.divergence_limit = '
                                  f'{limit:g} m')
        obs = observe(self.model, state)
        points = np.hstack([self.model.soil_points.positions, obs.soil_displacement,
                            obs.soil_acceleration, obs.soil_velocity])
        empty = np.zeros((0, 3))
        return Frame(step=step, time=state.time, head_position=0.0, speed=0.0,
                     midspan=empty, bearings=np.zeros((0, 2, 3)),
                     body_acceleration=empty, body_angular_velocity=empty,
                     wheel_rail=np.zeros((0, 1, 2, 3)), observers=empty,
                     pile_displacement=obs.pile_displacement,
                     pile_acceleration=obs.pile_acceleration,
                     pile_rotation_rate=obs.pile_rotation_rate, soil_points=points,
                     pile_strain=_padded(self.gauges @ state.u))


def _padded(values: np.ndarray) -> np.ndarray:
    """Return values (n,) as rows (n, 3): the value, then two zeros (as the probes)."""
    out = np.zeros((len(values), 3))
    out[:, 0] = values
    return out


def substructure_dof_counts(run: SubstructureRun) -> dict[str, int]:
    """
    DOF counts of a pile-soil substructure run, per subsystem.

    Free DOFs of the nodes of soil, pile and cap bricks, of the interface
    elements and of the boundary springs and dashpots (a node shared by two
    subsystems counts in both); ``total`` is every free DOF and ``solved`` those
    the step (or the static solve) factorises: all of them in the implicit
    scheme, the piles, cap and interface in the mixed one.
    """
    model = run.model
    free = model.free

    def of_cells(kind: int) -> int:
        nodes = np.unique(model.mesh.cells[model.cell_kind == kind])
        dofs = (3 * nodes[:, None] + np.arange(3)).ravel()
        return int(np.count_nonzero(free[dofs]))

    interface = 0
    if model.interface is not None:
        touched = np.unique(model.interface.relative.indices)
        interface = int(np.count_nonzero(free[touched]))
    boundary = (model.boundary_stiffness.diagonal() != 0) | (model.boundary_damping.diagonal()
                                                             != 0)
    total = int(np.count_nonzero(free))
    solved = total if run.scheme == 'implicit' else int(np.count_nonzero(implicit_dofs(model)
                                                                         & free))
    return {'soil': of_cells(SOIL), 'piles': of_cells(PILE), 'cap': of_cells(CAP),
            'interface': interface, 'boundary': int(np.count_nonzero(boundary & free)),
            'total': total, 'solved': solved}
