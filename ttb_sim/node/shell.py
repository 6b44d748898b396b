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
The ROS-free half of the rclpy shell (:mod:`ttb_sim.simulator_node`).

What the shell decides without ROS lives here, so that it is tested where ROS 2 is
absent: the order of the start-up parameters (the scenario first, then its own),
the QoS profile of each topic, the bag destination
and the opening of the recorder, the guard that keeps ``/clock`` from going
backwards, the node's ``/diagnostics`` report (the passage's, or the build's while
the model is being built, with the publishing counters), the answer of the pause
service, the messages the shell logs for passage events and answers while
building, and the line it logs at shutdown.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
import threading
from typing import Any, Callable, Mapping, Sequence

from ttb_sim.config import load_scenario, Scenario
from ttb_sim.io.bag import BagRecorder, check_destination, default_bag_path, make_parents
from ttb_sim.io.topics import Topic, topic_table
from ttb_sim.node.diagnostics import DiagnosticsReport, ERROR, OK
from ttb_sim.node.parameters import (DEFAULT_SCENARIO, initial_values, NodeParameter,
                                     parameter_table)
from ttb_sim.node.passage import PassageController, Tick
from ttb_sim.node.publishing import PublishStats
from ttb_sim.node.runs import FrameSink
from ttb_sim.node.stepper import StepperStatus
from ttb_sim.sim import Layout


@dataclass(frozen=True)
class StartUp:
    """The node's start-up: the scenario, its parameter table, the values given and in force."""

    scenario: Scenario
    table: dict[str, NodeParameter]
    given: dict[str, Any]
    values: dict[str, Any]

    def integers_for_doubles(self) -> list[str]:
        """Return the double parameters given as integers (to be stored as doubles, too)."""
        return [n for n, p in self.table.items()
                if p.kind == 'double' and not isinstance(self.given[n], float)]


def declare_parameters(declare: Callable[[str, Any, NodeParameter], Any]) -> StartUp:
    """
    Declare the ``scenario`` parameter, load the scenario, then declare its parameters.

    ``declare(name, default, parameter)`` declares one parameter and returns its
    start-up value (the ROS node's ``declare_parameter``).

    Raises
    ------
    ScenarioError
        For a scenario that does not load, or a start-up value ``declare`` refuses.

    """
    source = declare('scenario', DEFAULT_SCENARIO, parameter_table()['scenario'])
    scenario = load_scenario(source)
    table = parameter_table(scenario)
    given: dict[str, Any] = {'scenario': source}
    for name, param in table.items():
        if name != 'scenario':
            given[name] = declare(name, param.default, param)
    return StartUp(scenario, table, given, initial_values(table, given))


QOS_CLASSES = {'data': None, 'clock': 'clock', 'latched': 'latched'}
"""The node's QoS class of each topic-table ``qos`` name (None: ``qos.reliability``).

The topic table (:mod:`ttb_sim.io.topics`) calls its data topics' class 'data': the node
names its profiles by what they are, 'reliable' (the default, so ``ros2 bag record`` and
``ros2 topic echo`` get every message) and 'best_effort' (as rclpy's
``qos_profile_sensor_data``), and the parameter ``qos.reliability`` chooses between them.
"""


def qos_class(topic_qos: str, reliability: str) -> str:
    """
    Return the node's QoS profile name of a topic-table QoS class.

    Parameters
    ----------
    topic_qos : str
        The topic's ``qos`` ('data', 'clock' or 'latched').
    reliability : str
        The ``qos.reliability`` parameter ('reliable' or 'best_effort').

    Returns
    -------
    str
        'reliable', 'best_effort', 'clock' or 'latched'.

    """
    try:
        fixed = QOS_CLASSES[topic_qos]
    except KeyError:
        raise ValueError(f'unknown topic QoS class {topic_qos!r}; known: '
                         f'{", ".join(QOS_CLASSES)}') from None
    return reliability if fixed is None else fixed


def bag_destination(values: Mapping[str, Any], scenario_name: str) -> Path | None:
    """
    Return the bag directory of the node's parameters (None when ``bag.enabled`` is false).

    Raises
    ------
    ScenarioError
        When the destination cannot be created (named as ``bag.path``).

    """
    if not values['bag.enabled']:
        return None
    path = Path(values['bag.path']) if values['bag.path'] else default_bag_path(scenario_name)
    check_destination(path, values['bag.storage'], option='bag.path')
    return path


def open_bag(path: Path, storage: str, layout: Layout, namespace: str,
             extra: Sequence[tuple[str, str]] = ()) -> FrameSink:
    """
    Open the node's bag of the model's topic table under the node's namespace.

    ``extra``: (name, type) of the topics written message by message, the labels and
    the sensors (:func:`~ttb_sim.io.sensor_topics.extra_topics`).
    """
    make_parents(path)
    return BagRecorder(path, topic_table(layout), storage, namespace=namespace,
                       extra=extra).__enter__()


class ClockGuard:
    """Send ``/clock`` stamps that never go backwards, from any thread."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._last = -1

    def send(self, stamp_ns: int, publish: Callable[[int, int], None]) -> None:
        """Call ``publish(sec, nanosec)`` unless the stamp is older than the last one sent."""
        with self._lock:   # held while publishing: two threads cannot swap their stamps
            if stamp_ns < self._last:
                return
            self._last = stamp_ns
            sec, nanosec = divmod(int(stamp_ns), 1_000_000_000)
            publish(sec, nanosec)


def live_topics(topics: list[Topic]) -> list[tuple[Topic, str]]:
    """Return the topics published live (all but /clock) with their node-relative names."""
    return [(t, t.name if t.name.startswith('/') else f'~/{t.name}') for t in topics
            if t.qos != 'clock']


def building_message(status: StepperStatus) -> str:
    """Return the answer of a service called before the model exists."""
    if status.state == 'failed':
        return f'the model could not be built: {status.error}'
    return f'the model is still being built ({status.elapsed:.1f} s so far); try again'


def pause_answer(controller: PassageController, paused: bool) -> tuple[bool, str]:
    """Pause or resume; return (success, message) of the ``~/pause`` service."""
    message = controller.set_paused(paused)
    return controller.state in ('paused', 'running'), message


def tick_messages(tick: Tick, controller: PassageController | None) -> list[tuple[str, str]]:
    """Return the (level, message) lines to log for a tick's passage events."""
    out = []
    if 'diverged' in tick.events and controller is not None:
        out.append(('error', f'{controller.divergence}; stepping stopped, bag closed; '
                    'call ~/reset to restart'))
    if 'idle' in tick.events:
        out.append(('info', 'the train has left: idle (set loop:=true or call ~/reset for '
                    'another passage)'))
    return out


def node_diagnostics(scenario_name: str, status: StepperStatus,
                     passage: DiagnosticsReport | None, publishing: PublishStats | None = None,
                     publish_error: str = '',
                     progress: tuple[float, float | None, str] | None = None
                     ) -> DiagnosticsReport:
    """
    Return the node's ``/diagnostics`` report.

    Parameters
    ----------
    scenario_name : str
        The scenario's name.
    status : StepperStatus
        What the stepping thread is doing.
    passage : DiagnosticsReport or None
        The passage controller's report, once the model is built (None before).
    publishing : PublishStats, optional
        The publishing counters, once publishing has started.
    publish_error : str
        Why publishing stopped ('' if it did not).
    progress : (fraction, seconds left or None, message), optional
        The last progress line of a long build (the pile-soil reduction), shown
        while the model is being built.

    """
    if passage is None:
        if status.state == 'failed':
            level, message = ERROR, f'cannot build the model: {status.error}'
        else:
            level, message = OK, f'building model: {status.elapsed:.1f} s'
        values = [('state', status.state), ('scenario', scenario_name),
                  ('build time so far (s)', f'{status.elapsed:.1f}')]
        if progress is not None and status.state != 'failed':
            fraction, left, line = progress
            values += [('substructure reduction done (%)', f'{100 * fraction:.0f}'),
                       ('substructure reduction CPU time left (s)',
                        f'{left:.0f}' if left is not None else 'unknown'), ('progress', line)]
            message += f' ({line})'
        return DiagnosticsReport(level, message, tuple(values))
    level, message = passage.level, passage.message
    values = list(passage.values)
    values.append(('model build time (s)', f'{status.elapsed:.2f}'))
    if status.state == 'failed':
        level, message = ERROR, status.error
    if publishing is not None:
        values += [('published frames', str(publishing.published)),
                   ('dropped frames (publishing could not keep up)', str(publishing.dropped)),
                   ('publish CPU time per frame (ms)', f'{publishing.ms_per_frame:.3f}')]
        if publish_error:
            level, message = ERROR, publish_error
    return DiagnosticsReport(level, message, tuple(values))


def shutdown_line(controller: PassageController | None, published: int,
                  bag: Path | None) -> str:
    """
    Return the line the node logs at shutdown: what ran.

    Parameters
    ----------
    controller : PassageController or None
        The passage controller (None: the model was never built).
    published : int
        Frames published live.
    bag : Path or None
        The bag directory when recording.

    """
    if controller is None:
        return 'shutting down before the model was built; nothing was simulated' + (
            f' (no bag was opened at {bag})' if bag is not None else '')
    line = (f'shutting down: {controller.passage} passage(s), '
            f'{controller.simulated:.2f} s simulated (node time {controller.node_time:.2f} s), '
            f'real-time factor {controller.run_real_time_factor():.3f} over the run, '
            f'{published} frames published')
    if bag is not None:
        line += f', {controller.recorded} frames recorded to {bag}'
    return line
