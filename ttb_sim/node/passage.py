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
Passage control: the simulation stepping behind the live node, paced and recorded.

:class:`PassageController` owns a :class:`~ttb_sim.sim.Runner` (a train
simulation, or a pile-soil substructure alone under its load),
steps it paced by the real-time factor, hands every frame to a recorder (a
:class:`~ttb_sim.node.runs.FrameSink`) and the frames due for live publishing
(``publish_rate_hz`` of simulation time, or a family's own) to the caller as a
:class:`Tick`, and handles speed changes, reset, pause, loop and divergence.
:meth:`PassageController.diagnostics` reports solver health as a
:class:`~ttb_sim.node.diagnostics.DiagnosticsReport` (plain data that the node copies
into ``/diagnostics``).

A runner that is a train passage (:class:`~ttb_sim.node.runs.TrainRun`: a live speed,
an exit position, a fundamental frequency) also takes speed changes, computes frames only at the
publishing rate without a bag, and ends its passage once the train has left; a
pile-soil substructure run steps its planned time.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import logging
import math
import threading
import time
from typing import Any, Callable, Iterator, Mapping

from ttb_sim.config import Scenario
from ttb_sim.errors import DivergenceError, ScenarioError, TtbSimError
from ttb_sim.io.sensor_stream import SensorSample, SensorStream
from ttb_sim.io.topics import topic_table
from ttb_sim.node.diagnostics import (DiagnosticsReport, frame_values, passage_level,
                                      SlidingWindow, StepMeter)
from ttb_sim.node.parameters import (DAMAGE_PARAMETER, IRREGULARITY_KEYS, normalize_value,
                                     parameter_table, PASSAGE_KEYS, SCENARIO_KEYS,
                                     scenario_with)
from ttb_sim.node.rates import (check_rate, FAMILIES, family_of, family_periods, frame_stride,
                                RATE_PARAMETERS, Schedule)
from ttb_sim.node.runs import FrameSink, TrainRun
from ttb_sim.node.sensing import LiveSensing
from ttb_sim.sim import Frame, Layout, make_runner, Runner

__all__ = ['PassageController', 'Tick']

log = logging.getLogger(__name__)

MARKER_PERIOD = 0.1
"""Wall-clock seconds between two marker updates of the moving train."""

MAX_LAG = 0.5
"""Wall-clock seconds the stepping may fall behind its pace before the pace is re-anchored."""

MAX_OWED = 2.0
"""Most wall-clock seconds of passage builds caught up (beyond MAX_LAG) before re-anchoring."""


@dataclass
class Tick:
    """
    The result of one :meth:`PassageController.advance`.

    Attributes
    ----------
    frames : list of Frame
        Frames due for live publishing (decimated to ``publish_rate_hz`` and the
        per-family rates), stamped with the node's continuous simulation time.
    due : list of frozenset of str
        For each frame of ``frames``, the topic families due in it
        (:mod:`ttb_sim.node.rates`).
    stepped : int
        Frames computed in this tick (all went to the recorder).
    sleep : float
        Wall-clock seconds until the next frame is due (0 = step again now).
    markers : bool
        True when the train markers should be refreshed.
    events : list of str
        Passage events of this tick ('ended', 'restarted', 'idle', 'diverged').
    samples : list of SensorSample
        What the virtual sensors recorded in this tick (published at once, not decimated).
    labels : bool
        True when the labels changed (a new passage, a speed change): publish them.

    """

    frames: list[Frame] = field(default_factory=list)
    due: list[frozenset[str]] = field(default_factory=list)
    stepped: int = 0
    sleep: float = 0.0
    markers: bool = False
    events: list[str] = field(default_factory=list)
    samples: list[SensorSample] = field(default_factory=list)
    labels: bool = False


class PassageController:
    """
    Step passages of a train over the bridge for the live node.

    Thread-safe: the node calls :meth:`advance` from its stepping timer and the
    other methods from service and parameter callbacks; one lock serialises
    them, and :meth:`advance` holds it for at most ``budget`` seconds.

    Parameters
    ----------
    scenario : Scenario
        The loaded scenario (its speed and irregularity are replaced by the
        parameter values for each passage).
    values : mapping
        Every node parameter's value (see :func:`initial_values`).
    recorder : FrameSink, optional
        Receives every frame (full output rate) until it is closed.
    clock : callable
        Monotonic wall clock in seconds, for pacing (injectable for tests).

    """

    def __init__(self, scenario: Scenario, values: Mapping[str, Any], *,
                 recorder: FrameSink | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.base = scenario
        self.table = parameter_table(scenario)
        self.values = dict(values)
        self.recorder = recorder
        self.recorded = 0
        self.bag_error = ''
        self._clock = clock
        self._lock = threading.RLock()
        self.state = 'running'
        self.divergence = ''
        self.passage = 0
        self.time_offset = 0.0
        self.last_frame: Frame | None = None
        self._ran_out_at: float | None = None
        """Node time at which the passage's planned steps ran out (None: they have not)."""
        self.sim: Runner
        self._train: TrainRun | None = None   # self.sim when it is a train passage
        self._frames: Iterator[Frame]
        self._anchor: tuple[float, float] | None = None
        self._owed = 0.0
        """Wall seconds of passage builds not yet caught up (they do not re-anchor the pace)."""
        self._exit_time: float | None = None
        self._families: tuple[str, ...] = ()
        self._schedule = Schedule(())
        self._last_markers = -math.inf
        self._meter = StepMeter(clock())
        self._sliding = SlidingWindow()
        self._run_started: float | None = None
        """Wall clock of the first step (the run's real-time factor counts from it)."""
        self.simulated = 0.0
        """Simulated seconds stepped over the node's life (all passages)."""
        self._base_every = 1
        self._sensing = LiveSensing()
        self._start_passage()
        ok, reason = self.check_rates(self.values)
        if not ok:
            raise ScenarioError(reason)

    # -- commands -----------------------------------------------------------------------

    def apply(self, name: str, value: Any) -> None:
        """
        Apply an already validated parameter value.

        Parameters
        ----------
        name : str
            Parameter name.
        value : Any
            New value (ints are accepted for double parameters).

        """
        with self._lock:
            param = self.table.get(name)
            if param is not None:
                value = normalize_value(param, value)
            self.values[name] = value
            if name == 'train.speed_kmh':
                if self._train is not None:
                    self._train.set_speed(value / 3.6)
                    self._sensing.relabel(self.passage_scenario())
                else:
                    log.info('train.speed_kmh has no effect on a substructure run')
            elif name == 'real_time_factor':   # the new pace counts from now
                self._anchor = (self._clock(), self._node_time)
                self._sliding.clear()
            elif name == 'publish_rate_hz':
                self._schedule.restart(self._node_time)
            elif name in RATE_PARAMETERS:
                self._schedule.restart(self._node_time, RATE_PARAMETERS[name])
            elif name == 'loop' and value and self.state == 'idle':
                self._restart()
            elif name in PASSAGE_KEYS:
                log.info('%s = %r applies from the next passage', name, value)

    def reset(self) -> str:
        """Restart the passage (also after a divergence); return a message."""
        with self._lock:
            was = self.state
            paused = was == 'paused'
            self._restart()
            if paused:
                self.state = 'paused'
            note = ' (not recorded: the bag was closed)' if self._recording_stopped() else ''
            return f'passage {self.passage} started (was {was}){note}'

    def set_paused(self, paused: bool) -> str:
        """Pause or resume stepping; return a message."""
        with self._lock:
            if self.state in ('idle', 'diverged', 'failed', 'stopped'):
                return f'nothing to {"pause" if paused else "resume"}: {self.state}'
            self.state = 'paused' if paused else 'running'
            self._anchor = None if paused else (self._clock(), self._node_time)
            self._sliding.clear()
            return f'{self.state} at t = {self._node_time:.3f} s'

    def close(self) -> None:
        """
        Stop stepping for good and close the recorder (idempotent).

        Call it on the thread that steps (the one that writes the recorder).
        """
        with self._lock:
            self.state = 'stopped'
            self._flush_sensors()
            self._close_recorder()

    # -- stepping -----------------------------------------------------------------------

    @property
    def _node_time(self) -> float:
        return self.last_frame.time if self.last_frame is not None else self.time_offset

    @property
    def node_time(self) -> float:
        """The node's simulation time (s): the latest frame's, continuous over passages."""
        return self._node_time

    @property
    def frame_period(self) -> float:
        """Simulation time between two frames (s)."""
        return self.sim.dt * self.sim.output_every

    @property
    def output_period(self) -> float:
        """Simulation time between two output frames (s): the bag's, the fastest live rate."""
        return self.sim.dt * self._base_every

    @property
    def families(self) -> tuple[str, ...]:
        """The topic families the model publishes (:data:`~ttb_sim.node.rates.FAMILIES`)."""
        return self._families

    def publish_periods(self) -> dict[str, float]:
        """Return each family's live publishing period (s of simulation time; 0: every frame)."""
        return family_periods(self.values, self.output_period, self._families)

    def check_rates(self, changes: Mapping[str, Any]) -> tuple[bool, str]:
        """
        Refuse a per-family rate above this model's output rate (names the limit).

        Also refuse next-passage values whose scenario would not build (a damage zone off
        its span, a temperature that makes a stiffness negative): the reason names them.
        """
        state = {k: v for k, v in changes.items() if k in PASSAGE_KEYS}
        if state:
            values = {**self.values, **state}
            keys = SCENARIO_KEYS + (DAMAGE_PARAMETER,)
            try:
                scenario_with(self.base, {k: values[k] for k in keys if k in values})
            except ScenarioError as exc:
                return False, str(exc)
        for name, value in changes.items():
            if name in RATE_PARAMETERS and isinstance(value, (int, float)):
                ok, reason = check_rate(name, float(value), self.output_period)
                if not ok:
                    return ok, reason
        return True, ''

    @property
    def layout(self) -> Layout:
        """Output sizes (the same for every passage of the scenario)."""
        return self.sim.layout

    def passage_scenario(self) -> Scenario:
        """Return the scenario of a new passage: the base with the current parameters."""
        keys = SCENARIO_KEYS + (DAMAGE_PARAMETER,)
        return scenario_with(self.base, {k: self.values[k] for k in keys if k in self.values})

    def advance(self, budget: float = 0.02, max_frames: int = 100000) -> Tick:
        """
        Step as far as the pace allows, within a wall-clock budget.

        Parameters
        ----------
        budget : float
            Wall-clock seconds this call may spend stepping.
        max_frames : int
            Upper bound of frames computed in this call.

        Returns
        -------
        Tick
            Frames to publish, pacing and events.

        """
        tick = Tick()
        with self._lock:
            if self.state != 'running':
                tick.sleep = 0.1
                return tick
            self._set_frame_stride()
            tick.labels = self._sensing.emit_labels(self.recorder, round(self._node_time * 1e9),
                                                    self._recording_failed)
            now = self._clock()
            if self._run_started is None:
                self._run_started = now
            rtf = float(self.values['real_time_factor'])
            if self._anchor is None:
                self._anchor = (now, self._node_time)
            wall0, sim0 = self._anchor
            target = math.inf if rtf == 0 else sim0 + rtf * (now - wall0)
            deadline = time.perf_counter() + budget
            started = time.perf_counter()
            started_cpu = time.thread_time()
            while (self.state == 'running' and tick.stepped < max_frames
                   and (self.last_frame is None
                        or self._node_time + self.frame_period <= target + 1e-12)):
                self._step_one(tick)
                if time.perf_counter() > deadline:
                    break
            self._flush_sensors(tick)   # every sample of this tick's frames goes out now
            self._meter.stepping(time.perf_counter() - started, time.thread_time() - started_cpu)
            if self.state == 'running' and rtf > 0:
                due = wall0 + (self._node_time + self.frame_period - sim0) / rtf
                lag = self._clock() - due   # now: a build in this tick counts
                if lag > MAX_LAG + self._owed:   # cannot keep the pace: re-anchor, no burst
                    self._anchor = (now, self._node_time)
                    self._owed = 0.0
                elif lag <= 0:
                    self._owed = 0.0   # the builds are caught up
                tick.sleep = max(0.0, due - self._clock())
            if tick.frames and now - self._last_markers >= MARKER_PERIOD:
                self._last_markers = now
                tick.markers = True
        return tick

    def _step_one(self, tick: Tick) -> None:
        try:
            raw = next(self._frames)
        except StopIteration:
            # The steps after the last frame were simulated too (fewer than a frame
            # interval; all of the passage when the publishing period exceeds it).
            self._ran_out_at = self.time_offset + self.sim.n_steps * self.sim.dt
            self._end_passage(tick)
            return
        except DivergenceError as exc:
            self.state = 'diverged'
            self.divergence = str(exc)
            tick.events.append('diverged')
            log.debug('simulation diverged: %s; stepping stopped, bag closed', exc)
            self._flush_sensors()
            self._close_recorder()
            return
        frame = replace(raw, time=self.time_offset + raw.time)
        self.last_frame = frame
        tick.stepped += 1
        self._meter.frame(self.sim.output_every, self.frame_period if raw.step else 0.0)
        self.simulated += self.frame_period if raw.step else 0.0
        self._record(frame)
        samples = self._sensing.push(frame)
        tick.samples.extend(samples)
        self._sensing.record(self.recorder, samples, self._recording_failed)
        due = self._schedule.due(frame.time, self.publish_periods())
        if due:
            tick.frames.append(frame)
            tick.due.append(due)
        if self._passage_over(raw):
            self._end_passage(tick)

    def _set_frame_stride(self) -> None:
        """
        Compute frames only at the publishing rate while no recorder needs every frame.

        A frame (bearing forces, outputs) costs about as much as a step; without a
        bag only the published ones are needed. The stride is the scenario's
        output interval times the whole number of them in one publishing period
        (1 when the period is not a whole multiple, or 0 Hz: every frame). It is
        changed between frames only, so frame times stay exact.
        """
        sim = self._train
        if sim is None:
            return
        stride = 1
        sensors = self._sensing.samples_every_frame
        if self.recorder is None and not sensors:
            stride = frame_stride(self.publish_periods(), self.output_period)
        sim.output_every = self._base_every * stride

    def _passage_over(self, raw: Frame) -> bool:
        """
        Tell whether the passage has ended at this frame.

        It ends when the planned steps run out (handled by StopIteration) or, when
        the scenario's duration is automatic, once the head has passed the exit
        position and the free-vibration tail (free_vibration_periods / f1) has
        elapsed since: so a speed change shortens or lengthens the passage.
        """
        train = self._train
        if self.base.solver.duration > 0 or train is None:
            return False
        if raw.head_position < train.exit_position:
            return False
        if self._exit_time is None:
            self._exit_time = raw.time
        tail = (self.base.solver.free_vibration_periods
                / train.structure.fundamental_frequency)
        return raw.time - self._exit_time >= tail - 1e-12

    def _end_passage(self, tick: Tick) -> None:
        tick.events.append('ended')
        if self.values['loop']:
            self._restart()
            tick.events.append('restarted')
        else:
            self.state = 'idle'
            tick.events.append('idle')
            log.debug('passage %d ended; idle (set loop:=true or call ~/reset)', self.passage)

    def _restart(self) -> None:
        """
        Start the next passage, its time continuing the node's from where it stopped.

        After a passage whose planned steps ran out, one step after its last step
        (which may lie past the latest frame); after a reset, or a passage ended at a
        frame, one frame interval after that frame.
        """
        if self._ran_out_at is not None:
            self.time_offset = self._ran_out_at + self.sim.dt
        elif self.last_frame is not None:
            self.time_offset = self.last_frame.time + self.frame_period
        self._ran_out_at = None
        self.last_frame = None
        started = self._clock()
        try:
            self._start_passage()
        except TtbSimError as exc:   # e.g. an irregularity file that does not parse
            self.state = 'failed'
            self.divergence = f'cannot start passage {self.passage + 1}: {exc}'
            log.error(self.divergence)
        # The build's wall time is caught up, not lost: it does not count as lag (a build
        # slower than MAX_LAG on a loaded machine re-anchored the pace at every loop: RTF
        # 0.82 over 48 s of live_train at load 3.4).
        self._owed = min(MAX_OWED, self._owed + max(0.0, self._clock() - started))

    def _start_passage(self) -> None:
        """Build a new simulation from the current parameters and start stepping it."""
        scenario = self.passage_scenario()
        self.sim = make_runner(scenario)
        self._train = self.sim if isinstance(self.sim, TrainRun) else None
        self._base_every = self.sim.output_every
        if not self._families:   # the same layout for every passage of the scenario
            present = {family_of(t.name) for t in topic_table(self.sim.layout)}
            self._families = tuple(f for f in FAMILIES if f in present) or ('',)
            self._schedule = Schedule(self._families, self.time_offset)
        self._sensing.start(scenario, self.sim.layout, self.sim.dt, self._base_every)
        self._frames = self.sim.frames()
        self._exit_time = None
        self.passage += 1
        self.state = 'running'
        self.divergence = ''
        # The pace anchor is kept: simulation time runs on across passages, so the time
        # spent building this passage's model is caught up instead of lost (a re-anchor at
        # every loop cost the default 2-5 % of real time); a long gap re-anchors (MAX_LAG
        # beyond the build time owed).
        self._schedule.restart(self.time_offset)
        log.debug('passage %d: %s at %.1f km/h, dt = %.3g s', self.passage, scenario.name,
                  scenario.train.speed_kmh, self.sim.dt)

    # -- sensors and labels -------------------------------------------------------------

    @property
    def sensing(self) -> SensorStream | None:
        """The virtual sensors and the labels (None until the first passage starts)."""
        return self._sensing.stream

    def _flush_sensors(self, tick: Tick | None = None) -> None:
        """Record (and hand to the tick) the samples of the frames the sensors still keep."""
        samples = self._sensing.flush()
        if tick is not None:
            tick.samples.extend(samples)
        self._sensing.record(self.recorder, samples, self._recording_failed)

    # -- recording ----------------------------------------------------------------------

    def _record(self, frame: Frame) -> None:
        if self.recorder is None:
            return
        try:
            self.recorder.write(frame)
            self.recorded += 1
        except Exception as exc:  # noqa: B902 - any writer failure stops recording only
            self._recording_failed(exc)

    def _recording_failed(self, exc: Exception) -> None:
        self.bag_error = f'bag write failed: {exc}'
        log.error('%s; recording stopped', self.bag_error)
        self._close_recorder()

    def _recording_stopped(self) -> bool:
        return self.values.get('bag.enabled', False) and self.recorder is None

    def _close_recorder(self) -> None:
        if self.recorder is not None:
            recorder, self.recorder = self.recorder, None
            try:
                recorder.close()
            except Exception as exc:  # noqa: B902 - report, never raise while closing
                self.bag_error = f'bag close failed: {exc}'
                log.error(self.bag_error)

    # -- diagnostics --------------------------------------------------------------------

    def diagnostics(self) -> DiagnosticsReport:
        """
        Report solver health since the previous call.

        Returns
        -------
        DiagnosticsReport
            Measured real-time factor, step time, contact iterations, divergence
            state and the latest frame's values.

        """
        with self._lock:
            window = self._meter.window(self._clock())
            over = self._sliding.add(window)
            target = float(self.values['real_time_factor'])
            values = [
                ('state', self.state),
                ('passage', str(self.passage)),
                ('simulation time (s)', f'{self._node_time:.6f}'),
                ('real-time factor', f'{over.real_time_factor:.3g}'),
                ('real-time factor window (s)', f'{over.wall:.1f}'),
                ('real-time factor target (0 = max)', f'{target:g}'),
                ('real-time factor since start', f'{self.run_real_time_factor():.3g}'),
                ('step time (ms)', f'{window.step_ms:.4f}'),
                ('stepping CPU time per simulated second (s)',
                 f'{window.cpu / window.simulated:.3f}' if window.simulated > 0 else '0'),
                ('solver dt (s)', f'{self.sim.dt:.6g}'),
                ('contact iterations', '0'),  # the wheel-girder coupling is solved directly
                ('divergence', self.divergence or 'none'),
                ('irregularity (from next passage)', ', '.join(
                    f'{k.split(".", 1)[1]}={self.values[k]!r}' for k in IRREGULARITY_KEYS)),
                ('bag', self._bag_state()),
                ('bag frames', str(self.recorded)),
            ]
            if self.last_frame is not None:
                values.extend(frame_values(self.last_frame))
            level, message = passage_level(self.state, self.divergence, self.bag_error,
                                           self.passage, target, over)
            return DiagnosticsReport(level, message, tuple(values))

    def run_real_time_factor(self) -> float:
        """Return simulated over wall-clock seconds since the first step (0 before it)."""
        if self._run_started is None:
            return 0.0
        wall = self._clock() - self._run_started
        return self.simulated / wall if wall > 0 else 0.0

    def _bag_state(self) -> str:
        if not self.values.get('bag.enabled', False):
            return 'disabled'
        if self.recorder is not None:
            return 'recording'
        return 'closed' + (f' ({self.bag_error})' if self.bag_error else '')
