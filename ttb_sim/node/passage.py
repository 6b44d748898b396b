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
The ROS-free logic of the simulator node.

Everything the node decides lives here, so that it is tested where ROS 2 is
absent; :mod:`ttb_sim.simulator_node` only copies values into rclpy objects.

- :func:`parameter_table` derives the node's parameters from the scenario
  schema (:func:`ttb_sim.scenario.key_spec`), adding a few node-only ones.
- :func:`validate_parameter` checks one proposed value and returns
  ``(ok, reason)``; the reason names the parameter, the value and what is allowed.
- :class:`PassageController` owns a :class:`~ttb_sim.sim.simulation.Simulation`,
  steps it paced by the real-time factor, hands every frame to a recorder and
  the frames due for live publishing (``publish_rate_hz`` of simulation time)
  to the caller, and handles speed changes, reset, pause, loop and divergence.
- :func:`model_markers` / :func:`train_markers` describe the RViz markers as
  plain data.

Irregularity parameters (``irregularity.*``) are validated and stored when set;
they apply from the next passage (a loop restart or a reset), because the track
irregularity of a passage is generated when the passage starts. The speed
(``train.speed_kmh``) applies at the next solver step.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
import logging
import math
from pathlib import Path
import threading
import time
from typing import Any, Callable, Iterator, Mapping, Protocol

from ttb_sim.errors import DivergenceError, ScenarioError, TtbSimError
from ttb_sim.io.bag import STORAGES
from ttb_sim.io.topics import FRAME_ID
from ttb_sim.scenario import apply_overrides, from_mapping, key_spec, Scenario, Spec
from ttb_sim.sim.frames import Frame, Layout
from ttb_sim.sim.simulation import Simulation

log = logging.getLogger(__name__)

DEFAULT_SCENARIO = 'moving_force_beam'
"""Scenario loaded when the ``scenario`` parameter is not given."""

SCENARIO_KEYS = ('train.speed_kmh', 'irregularity.spectrum', 'irregularity.seed',
                 'irregularity.file', 'irregularity.scale')
"""Node parameters that are scenario keys (same name, unit, range and description)."""

IRREGULARITY_KEYS = tuple(k for k in SCENARIO_KEYS if k.startswith('irregularity.'))

MARKER_PERIOD = 0.1
"""Wall-clock seconds between two marker updates of the moving train."""

MAX_LAG = 0.5
"""Wall-clock seconds the stepping may fall behind its pace before the pace is re-anchored."""


# --------------------------------------------------------------------------------------
# Parameter table
# --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class NodeParameter:
    """
    One parameter of the node, as declared to ROS.

    Attributes
    ----------
    name : str
        Parameter name (dotted, as in the scenario schema).
    kind : str
        ROS parameter type: 'bool', 'integer', 'double' or 'string'.
    default : Any
        Declared default value.
    spec : Spec
        Unit, range or choices and description (shared with the scenario schema).
    read_only : bool
        True for structural parameters, fixed for the life of the node.
    applies : str
        When a change takes effect: 'immediately', 'next passage' or 'restart'.
    scenario_key : str or None
        The scenario key this parameter sets, if any.

    """

    name: str
    kind: str
    default: Any
    spec: Spec
    read_only: bool = False
    applies: str = 'immediately'
    scenario_key: str | None = None

    @property
    def accepts_integer(self) -> bool:
        """Tell whether an integer value is accepted (double parameters: ``350`` = 350.0)."""
        return self.kind == 'double'

    @property
    def unit(self) -> str:
        """Unit of the value ('-' when dimensionless)."""
        return self.spec.unit

    def allowed(self) -> str:
        """Describe the allowed values in words."""
        if self.kind == 'bool':
            return 'true or false'
        if self.kind == 'string' and self.spec.choices is None:
            return 'any string'
        return self.spec.allowed()

    def description(self) -> str:
        """Return the description shown by ``ros2 param describe`` (with unit and range)."""
        unit = self.unit if self.unit not in ('', '-') else 'dimensionless'
        if self.kind in ('bool', 'string'):
            unit_text = ''
        else:
            unit_text = f' Unit: {unit}.'
        when = {'immediately': 'Changes apply immediately.',
                'next passage': 'Changes apply from the next passage (loop restart or '
                                '~/reset).',
                'restart': 'Read-only: set it when starting the node.'}[self.applies]
        return f'{self.spec.description}{unit_text} Allowed: {self.allowed()}. {when}'


_NODE_ONLY: dict[str, tuple[str, Any, Spec, bool]] = {
    'scenario': ('string', DEFAULT_SCENARIO, Spec(
        '-', 'Scenario to simulate: a YAML path or a built-in name (ttb-sim scenarios).'),
        True),
    'publish_rate_hz': ('double', 50.0, Spec(
        'Hz', 'Rate of live messages in simulation time; 0 publishes every frame (the bag '
        'always gets every frame).', low=0.0, high=10000.0), False),
    'real_time_factor': ('double', 1.0, Spec(
        '-', 'Simulated seconds per wall-clock second; 0 = as fast as possible.',
        low=0.0, high=1000.0), False),
    'loop': ('bool', False, Spec(
        '-', 'Start a new passage when the train has left (otherwise the node idles).'),
        False),
    'publish_clock': ('bool', True, Spec(
        '-', 'Publish simulation time on /clock.'), False),
    'bag.enabled': ('bool', False, Spec(
        '-', 'Record every topic at the full output rate to a rosbag2.'), True),
    'bag.path': ('string', '', Spec(
        '-', "Bag directory to create (must not exist); '' = runs/<scenario>-<time>."), True),
    'bag.storage': ('string', 'mcap', Spec(
        '-', 'rosbag2 storage plugin.', choices=tuple(STORAGES)), True),
}

_KIND_OF = {float: 'double', int: 'integer', str: 'string', bool: 'bool'}


def _scenario_value(scenario: Scenario, key: str) -> Any:
    value: Any = scenario
    for part in key.split('.'):
        value = getattr(value, part)
    return value


def parameter_table(scenario: Scenario | None = None) -> dict[str, NodeParameter]:
    """
    Return the node's parameters, in declaration order.

    Parameters
    ----------
    scenario : Scenario, optional
        The loaded scenario; the scenario-key parameters default to its values
        (the schema defaults when omitted).

    Returns
    -------
    dict
        Parameter name -> :class:`NodeParameter`.

    """
    table: dict[str, NodeParameter] = {}
    kind, default, spec, read_only = _NODE_ONLY['scenario']
    table['scenario'] = NodeParameter('scenario', kind, default, spec, read_only, 'restart')
    for key in SCENARIO_KEYS:
        typ, schema_default, spec = key_spec(key)
        value = schema_default if scenario is None else _scenario_value(scenario, key)
        applies = 'next passage' if key in IRREGULARITY_KEYS else 'immediately'
        table[key] = NodeParameter(key, _KIND_OF[typ], value, spec, not spec.dynamic,
                                   applies if spec.dynamic else 'restart', key)
    for name, (kind, default, spec, read_only) in _NODE_ONLY.items():
        if name != 'scenario':
            table[name] = NodeParameter(name, kind, default, spec, read_only,
                                        'restart' if read_only else 'immediately')
    return table


def validate_parameter(param: NodeParameter, value: Any, *,
                       initial: bool = False) -> tuple[bool, str]:
    """
    Check one proposed parameter value.

    Parameters
    ----------
    param : NodeParameter
        The parameter's declaration.
    value : Any
        Proposed value (as rclpy delivers it: bool, int, float, str or None).
    initial : bool
        True when checking the value given at start-up, where read-only
        parameters may be set.

    Returns
    -------
    tuple of (bool, str)
        ``(True, '')`` when acceptable, else ``(False, reason)``; the reason
        names the parameter, the value and the allowed values.

    """
    name, allowed = param.name, param.allowed()
    if param.read_only and not initial:
        return False, (f'{name} is read-only (allowed {allowed}); set it when starting the '
                       f'node, e.g. --ros-args -p {name}:=...')
    if param.kind == 'bool':
        if not isinstance(value, bool):
            return False, f'{name} = {value!r}: expected a bool, allowed {allowed}'
        return True, ''
    if param.kind == 'string':
        if not isinstance(value, str):
            return False, f'{name} = {value!r}: expected a string, allowed {allowed}'
        if param.spec.choices is not None and value not in param.spec.choices:
            return False, f'{name} = {value!r} is not allowed: allowed {allowed}'
        if name == 'irregularity.file' and value and not Path(value).is_file():
            return False, (f'{name} = {value!r}: no such file (allowed: a readable CSV '
                           "path, or '' to synthesise from the spectrum)")
        return True, ''
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        kind = 'an integer' if param.kind == 'integer' else 'a number'
        return False, f'{name} = {value!r}: expected {kind}, allowed {allowed}'
    if param.kind == 'integer' and isinstance(value, float) and not value.is_integer():
        return False, f'{name} = {value!r}: expected an integer, allowed {allowed}'
    if not math.isfinite(value):
        return False, f'{name} = {value!r}: expected a finite number, allowed {allowed}'
    if not param.spec.contains(value):
        return False, f'{name} = {value!r} is out of range: allowed {allowed}'
    return True, ''


def validate_changes(table: Mapping[str, NodeParameter],
                     changes: Mapping[str, Any]) -> tuple[bool, str]:
    """
    Check a set of changes at once (all or nothing, as rclpy sets them).

    Parameters
    ----------
    table : mapping
        The parameter table.
    changes : mapping
        Parameter name -> proposed value.

    Returns
    -------
    tuple of (bool, str)
        The first refusal, or ``(True, '')``.

    """
    for name, value in changes.items():
        param = table.get(name)
        if param is None:
            return False, f'unknown parameter {name!r}; known: {", ".join(table)}'
        ok, reason = validate_parameter(param, value)
        if not ok:
            return ok, reason
    return True, ''


def normalize_value(param: NodeParameter, value: Any) -> Any:
    """Return a validated value in the parameter's own type (an int 350 -> 350.0)."""
    if param.kind == 'double':
        return float(value)
    if param.kind == 'integer':
        return int(value)
    return value


def initial_values(table: Mapping[str, NodeParameter],
                   given: Mapping[str, Any]) -> dict[str, Any]:
    """
    Merge start-up values with the defaults, validating each.

    Parameters
    ----------
    table : mapping
        The parameter table.
    given : mapping
        Values set at start-up (parameter overrides); missing names take defaults.

    Returns
    -------
    dict
        Every parameter's value, normalised to its type.

    Raises
    ------
    ScenarioError
        On the first invalid value (the message names the parameter and range).

    """
    values: dict[str, Any] = {}
    for name, param in table.items():
        value = given.get(name, param.default)
        ok, reason = validate_parameter(param, value, initial=True)
        if not ok:
            raise ScenarioError(reason)
        values[name] = normalize_value(param, value)
    return values


def scenario_with(scenario: Scenario, values: Mapping[str, Any]) -> Scenario:
    """
    Return a copy of a scenario with dotted keys replaced (validated again).

    Raises
    ------
    ScenarioError
        If a key is unknown or the combination is invalid.

    """
    data = scenario.to_dict()
    apply_overrides(data, list(values.items()))
    return from_mapping(data)


# --------------------------------------------------------------------------------------
# Passage controller
# --------------------------------------------------------------------------------------

class FrameSink(Protocol):
    """What the controller hands every frame to (a :class:`~ttb_sim.io.bag.BagRecorder`)."""

    def write(self, frame: Frame) -> None:
        """Record one frame."""

    def close(self) -> None:
        """Finish recording (idempotent)."""


@dataclass
class Tick:
    """
    The result of one :meth:`PassageController.advance`.

    Attributes
    ----------
    frames : list of Frame
        Frames due for live publishing (decimated to ``publish_rate_hz``),
        stamped with the node's continuous simulation time.
    stepped : int
        Frames computed in this tick (all went to the recorder).
    sleep : float
        Wall-clock seconds until the next frame is due (0 = step again now).
    markers : bool
        True when the train markers should be refreshed.
    events : list of str
        Passage events of this tick ('ended', 'restarted', 'idle', 'diverged').

    """

    frames: list[Frame] = field(default_factory=list)
    stepped: int = 0
    sleep: float = 0.0
    markers: bool = False
    events: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class DiagnosticsReport:
    """
    Solver health for ``/diagnostics``, as plain data.

    Attributes
    ----------
    level : int
        0 OK, 1 WARN, 2 ERROR (the ``diagnostic_msgs/msg/DiagnosticStatus`` levels).
    message : str
        One line summary.
    values : tuple of (str, str)
        Key/value pairs; keys carry their unit.

    """

    level: int
    message: str
    values: tuple[tuple[str, str], ...]

    def as_dict(self) -> dict[str, str]:
        """Return the key/value pairs as a dict."""
        return dict(self.values)


OK, WARN, ERROR = 0, 1, 2


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
        self.sim: Simulation
        self._frames: Iterator[Frame]
        self._anchor: tuple[float, float] | None = None
        self._exit_time: float | None = None
        self._next_publish = 0.0
        self._last_markers = -math.inf
        self._window = (clock(), 0.0, 0, 0.0)   # wall, sim time, steps, stepping seconds
        self._sim_total = 0.0
        self._steps_total = 0
        self._stepping_total = 0.0
        self._start_passage()

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
                self.sim.speed = value / 3.6
            elif name == 'real_time_factor':   # the new pace counts from now
                self._anchor = (self._clock(), self._node_time)
            elif name == 'publish_rate_hz':
                self._next_publish = self._node_time
            elif name == 'loop' and value and self.state == 'idle':
                self._restart()
            elif name in IRREGULARITY_KEYS:
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
            return f'{self.state} at t = {self._node_time:.3f} s'

    def close(self) -> None:
        """Stop stepping for good and close the recorder (idempotent)."""
        with self._lock:
            self.state = 'stopped'
            self._close_recorder()

    # -- stepping -----------------------------------------------------------------------

    @property
    def _node_time(self) -> float:
        return self.last_frame.time if self.last_frame is not None else self.time_offset

    @property
    def frame_period(self) -> float:
        """Simulation time between two frames (s)."""
        return self.sim.dt * self.sim.output_every

    @property
    def layout(self) -> Layout:
        """Output sizes (the same for every passage of the scenario)."""
        return self.sim.layout

    def passage_scenario(self) -> Scenario:
        """Return the scenario of a new passage: the base with the current parameters."""
        return scenario_with(self.base, {k: self.values[k] for k in SCENARIO_KEYS})

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
            now = self._clock()
            rtf = float(self.values['real_time_factor'])
            if self._anchor is None:
                self._anchor = (now, self._node_time)
            wall0, sim0 = self._anchor
            target = math.inf if rtf == 0 else sim0 + rtf * (now - wall0)
            deadline = time.perf_counter() + budget
            started = time.perf_counter()
            while (self.state == 'running' and tick.stepped < max_frames
                   and (self.last_frame is None
                        or self._node_time + self.frame_period <= target + 1e-12)):
                self._step_one(tick)
                if time.perf_counter() > deadline:
                    break
            self._stepping_total += time.perf_counter() - started
            if self.state == 'running' and rtf > 0:
                due = wall0 + (self._node_time + self.frame_period - sim0) / rtf
                lag = now - due
                if lag > MAX_LAG:   # cannot keep the pace: re-anchor, no catch-up burst
                    self._anchor = (now, self._node_time)
                tick.sleep = max(0.0, due - self._clock())
            if tick.frames and now - self._last_markers >= MARKER_PERIOD:
                self._last_markers = now
                tick.markers = True
        return tick

    def _step_one(self, tick: Tick) -> None:
        try:
            raw = next(self._frames)
        except StopIteration:
            self._end_passage(tick)
            return
        except DivergenceError as exc:
            self.state = 'diverged'
            self.divergence = str(exc)
            tick.events.append('diverged')
            log.error('simulation diverged: %s; stepping stopped, bag closed', exc)
            self._close_recorder()
            return
        frame = replace(raw, time=self.time_offset + raw.time)
        self.last_frame = frame
        tick.stepped += 1
        self._steps_total += self.sim.output_every
        self._sim_total += self.frame_period if raw.step else 0.0
        self._record(frame)
        period = self._publish_period()
        if frame.time >= self._next_publish - 1e-9:
            tick.frames.append(frame)
            self._next_publish += period
            if self._next_publish <= frame.time - 1e-9:  # the rate was raised: restart
                self._next_publish = frame.time + period
        if self._passage_over(raw):
            self._end_passage(tick)

    def _publish_period(self) -> float:
        rate = float(self.values['publish_rate_hz'])
        return 1.0 / rate if rate > 0 else 0.0

    def _passage_over(self, raw: Frame) -> bool:
        """
        Tell whether the passage has ended at this frame.

        It ends when the planned steps run out (handled by StopIteration) or, when
        the scenario's duration is automatic, once the head has passed the exit
        position and the free-vibration tail (free_vibration_periods / f1) has
        elapsed since: so a speed change shortens or lengthens the passage.
        """
        if self.base.solver.duration > 0:
            return False
        if raw.head_position < self.sim.exit_position:
            return False
        if self._exit_time is None:
            self._exit_time = raw.time
        tail = (self.base.solver.free_vibration_periods
                / self.sim.structure.fundamental_frequency)
        return raw.time - self._exit_time >= tail - 1e-12

    def _end_passage(self, tick: Tick) -> None:
        tick.events.append('ended')
        if self.values['loop']:
            self._restart()
            tick.events.append('restarted')
        else:
            self.state = 'idle'
            tick.events.append('idle')
            log.info('passage %d ended; idle (set loop:=true or call ~/reset)', self.passage)

    def _restart(self) -> None:
        if self.last_frame is not None:
            self.time_offset = self.last_frame.time + self.frame_period
        self.last_frame = None
        try:
            self._start_passage()
        except TtbSimError as exc:   # e.g. an irregularity file that does not parse
            self.state = 'failed'
            self.divergence = f'cannot start passage {self.passage + 1}: {exc}'
            log.error(self.divergence)

    def _start_passage(self) -> None:
        """Build a new simulation from the current parameters and start stepping it."""
        scenario = self.passage_scenario()
        self.sim = Simulation(scenario)
        self._frames = self.sim.frames()
        self._exit_time = None
        self.passage += 1
        self.state = 'running'
        self.divergence = ''
        self._anchor = None
        self._next_publish = self.time_offset
        log.info('passage %d: %s at %.1f km/h, dt = %.3g s', self.passage, scenario.name,
                 scenario.train.speed_kmh, self.sim.dt)

    # -- recording ----------------------------------------------------------------------

    def _record(self, frame: Frame) -> None:
        if self.recorder is None:
            return
        try:
            self.recorder.write(frame)
            self.recorded += 1
        except Exception as exc:  # noqa: B902 - any writer failure stops recording only
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
            now = self._clock()
            wall0, sim0, steps0, busy0 = self._window
            self._window = (now, self._sim_total, self._steps_total, self._stepping_total)
            wall = now - wall0
            sim_dt = self._sim_total - sim0
            steps = self._steps_total - steps0
            busy = self._stepping_total - busy0
            rtf = sim_dt / wall if wall > 0 else 0.0
            step_ms = 1e3 * busy / steps if steps else 0.0
            target = float(self.values['real_time_factor'])
            values = [
                ('state', self.state),
                ('passage', str(self.passage)),
                ('simulation time (s)', f'{self._node_time:.6f}'),
                ('real-time factor', f'{rtf:.3g}'),
                ('real-time factor target (0 = max)', f'{target:g}'),
                ('step time (ms)', f'{step_ms:.4f}'),
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
            if self.state == 'diverged':
                level, message = ERROR, f'diverged: {self.divergence}'
            elif self.state == 'failed':
                level, message = ERROR, self.divergence
            elif self.bag_error:
                level, message = ERROR, self.bag_error
            elif (self.state == 'running' and target > 0 and steps
                  and rtf < 0.9 * target):
                level, message = WARN, (f'slower than requested: real-time factor {rtf:.2f} '
                                        f'< {target:g}')
            else:
                level, message = OK, f'{self.state}, passage {self.passage}'
            return DiagnosticsReport(level, message, tuple(values))

    def _bag_state(self) -> str:
        if not self.values.get('bag.enabled', False):
            return 'disabled'
        if self.recorder is not None:
            return 'recording'
        return 'closed' + (f' ({self.bag_error})' if self.bag_error else '')


def frame_values(frame: Frame) -> list[tuple[str, str]]:
    """
    Return a frame's headline values as diagnostic key/value pairs (keys carry units).

    Parameters
    ----------
    frame : Frame
        The frame.

    Returns
    -------
    list of (str, str)

    """
    out = [('head position (m)', f'{frame.head_position:.3f}'),
           ('speed (m/s)', f'{frame.speed:.3f}'),
           ('speed (km/h)', f'{frame.speed * 3.6:.2f}')]
    for k, mid in enumerate(frame.midspan):
        out.append((f'span{k + 1:02d} midspan z (m)', f'{float(mid[2]):.6g}'))
    return out


# --------------------------------------------------------------------------------------
# Markers
# --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Box:
    """
    An axis-aligned box marker in the track frame.

    Attributes
    ----------
    ns : str
        Marker namespace ('girders', 'piers', 'abutments', 'train', 'axles').
    marker_id : int
        Id, unique within the namespace.
    position : tuple of float
        Centre (x, y, z) in metres.
    size : tuple of float
        Edge lengths (x, y, z) in metres.
    color : tuple of float
        (r, g, b, a), each in [0, 1].

    """

    ns: str
    marker_id: int
    position: tuple[float, float, float]
    size: tuple[float, float, float]
    color: tuple[float, float, float, float]


@dataclass(frozen=True)
class MarkerSet:
    """All markers of one ``~/model/markers`` message, in the frame ``frame_id``."""

    boxes: tuple[Box, ...]
    frame_id: str = FRAME_ID


GIRDER_COLOR = (0.62, 0.62, 0.66, 1.0)
PIER_COLOR = (0.45, 0.45, 0.50, 1.0)
ABUTMENT_COLOR = (0.35, 0.35, 0.38, 1.0)
CAR_COLOR = (0.85, 0.85, 0.95, 0.9)
AXLE_COLOR = (0.9, 0.2, 0.15, 1.0)


def _girder_depth(scenario: Scenario) -> float:
    """Return a drawing depth of the girder (m): span/12, at least 0.5 m (display only)."""
    return max(scenario.bridge.span_length / 12.0, 0.5)


def model_markers(scenario: Scenario) -> list[Box]:
    """
    Describe the static structure: one box per girder, pier and abutment.

    The deck top is at z = 0; widths and depths are display values (the beam
    model has no cross-section geometry beyond its stiffness and mass).

    Parameters
    ----------
    scenario : Scenario
        The scenario.

    Returns
    -------
    list of Box

    """
    b = scenario.bridge
    depth = _girder_depth(scenario)
    width = scenario.bearings.spacing + 2.0
    gap = min(0.1, 0.01 * b.span_length)
    boxes = [Box('girders', k, ((k + 0.5) * b.span_length, 0.0, -depth / 2),
                 (b.span_length - gap, width, depth), GIRDER_COLOR)
             for k in range(b.n_spans)]
    height = scenario.piers.height
    for s in range(b.n_spans + 1):
        x = s * b.span_length
        if s in (0, b.n_spans):
            boxes.append(Box('abutments', s, (x, 0.0, -depth - 1.5), (2.0, width + 1.0, 3.0),
                             ABUTMENT_COLOR))
        else:
            boxes.append(Box('piers', s, (x, 0.0, -depth - height / 2),
                             (2.0, 0.6 * width, height), PIER_COLOR))
    return boxes


def train_markers(scenario: Scenario, head_position: float) -> list[Box]:
    """
    Describe the train at a head position: car bodies and one small box per axle.

    Parameters
    ----------
    scenario : Scenario
        The scenario (train layout).
    head_position : float
        Position of the train head along the track (m).

    Returns
    -------
    list of Box

    """
    t = scenario.train
    offsets = t.axle_positions()
    boxes = [Box('axles', i, (head_position - a, 0.0, 0.5), (1.0, 1.5, 1.0), AXLE_COLOR)
             for i, a in enumerate(offsets)]
    if not t.axle_offsets:
        for c in range(t.n_cars):
            x = head_position - (c + 0.5) * t.car_length
            boxes.append(Box('train', c, (x, 0.0, 2.4), (t.car_length - 0.6, 3.2, 3.6),
                             CAR_COLOR))
    return boxes


def markers(scenario: Scenario, head_position: float) -> MarkerSet:
    """Return the complete marker set: structure and train (sent latched as a whole)."""
    return MarkerSet(tuple(model_markers(scenario) + train_markers(scenario, head_position)))
