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
The ROS 2 simulator node ``ttb_sim`` (``ros2 run ttb_sim simulator``).

A thin rclpy shell over the ROS-free :mod:`ttb_sim.node`: it declares the parameters
of :func:`~ttb_sim.node.parameters.parameter_table`, forwards parameter changes and
service calls to a :class:`~ttb_sim.node.stepper.Stepper`, and copies frames,
diagnostics and markers into standard messages (what it decides without ROS is in
:mod:`ttb_sim.node.shell`). Its threads: the executor (a
:class:`rclpy.executors.MultiThreadedExecutor`), which answers parameters and
services and runs the 1 Hz diagnostics and the 10 Hz paused-clock timers, and the
stepping thread, which builds, steps, records and publishes (:mod:`ttb_sim.node`).

Publishers and their QoS (all explicit):

- the topic table (:func:`ttb_sim.io.topics.topic_table`), private topics
  ``~/...``: profile 'reliable' (reliable, volatile, keep last 10; the default, so
  that ``ros2 bag record`` and ``ros2 topic echo`` get every message) or, with
  ``qos.reliability:=best_effort``, 'best_effort' (rclpy's
  ``qos_profile_sensor_data``: best effort, volatile, keep last 5); created once the
  model is built (its sizes come from the model); each topic family at its own rate
  (``publish_rate_hz``, ``publish_rates.<family>_hz``: :mod:`ttb_sim.node.rates`);
- ``/clock`` (when ``publish_clock``): reliable, volatile, keep last 1, so that
  both best-effort (rclcpp/rclpy time sources) and reliable subscribers match;
  it never goes backwards, and while paused or idle it repeats the current time;
- ``/diagnostics``: reliable, volatile, keep last 10, at 1 Hz of wall clock,
  stamped with simulation time like every data topic;
- ``~/model/markers``: reliable, transient local, keep last 1 (latched: a late
  RViz gets the structure and the latest train position);
- ``/tf_static`` (``tf2_msgs/msg/TFMessage``, when tf2_msgs is installed): reliable,
  transient local, keep last 1, one message once the model is built: the frames of
  :mod:`ttb_sim.node.frames_tf` under ``track``;
- ``~/sensors/<name>`` (the scenario's virtual sensors, docs/sensors.md): as the data
  topics, each sample once, at the sensor's own sample times;
- ``~/labels`` (``std_msgs/msg/String``, JSON): latched (reliable, transient local, keep
  last 1), at every passage and speed change.

The library's log records (:mod:`logging`) go to the node's ROS logger, each warning
once per node life (:mod:`ttb_sim.node.logs`); BLAS is held at one thread
(:mod:`ttb_sim.node.threads`); at shutdown one line says what ran.

Timers use the steady clock, so ``use_sim_time`` (driven by this node's own
/clock) cannot stall them. On shutdown, SIGINT and SIGTERM the publishing stops
first, then the stepping thread closes the bag; start-up errors (scenario,
parameter values and types, bag destination) are one FATAL line and exit code 2.
"""

from __future__ import annotations

from dataclasses import replace
import functools
from pathlib import Path
import sys
from typing import Any, Callable, Sequence

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                ParameterType, SetParametersResult)
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.clock import Clock, ClockType
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import (DurabilityPolicy, HistoryPolicy, qos_profile_sensor_data, QoSProfile,
                       ReliabilityPolicy)
from rclpy.task import Future
from rosgraph_msgs.msg import Clock as ClockMsg
from rosidl_runtime_py.utilities import get_message
from std_srvs.srv import SetBool, Trigger
from ttb_sim.errors import ModelError, ScenarioError
from ttb_sim.io.sensor_topics import extra_topics
from ttb_sim.io.topics import Topic, topic_table
from ttb_sim.node import (markers, NodeParameter, PassageController, validate_changes,
                          validate_parameter)
from ttb_sim.node.diagnostics import diagnostic_array
from ttb_sim.node.frames_tf import static_frames, tf_message
from ttb_sim.node.logs import ForwardingHandler, install, ProgressWatcher
from ttb_sim.node.markers import marker_array
from ttb_sim.node.message_cache import MessageCache
from ttb_sim.node.parameters import descriptor_range, NumericRange
from ttb_sim.node.passage import Tick
from ttb_sim.node.publishing import PublishLoop
from ttb_sim.node.rates import RATE_PARAMETERS
from ttb_sim.node.runs import FrameSink
from ttb_sim.node.shell import (bag_destination, building_message, ClockGuard,
                                declare_parameters, live_topics, node_diagnostics, open_bag,
                                pause_answer, qos_class, shutdown_line, tick_messages)
from ttb_sim.node.stepper import Stepper
from ttb_sim.node.threads import hold_blas_threads
from ttb_sim.sim import Frame, Layout
from visualization_msgs.msg import MarkerArray

STEP_BUDGET = 0.02
"""Wall-clock seconds one stepping tick may spend before it hands its frames on."""
PUBLISH_DUTY = 0.2
"""Largest share of the processor (CPU time) publishing may take."""
PAUSED_CLOCK_PERIOD = 0.1
"""Wall-clock seconds between two /clock messages while paused or idle."""
BUILD_LOG_PERIOD = 10.0
"""Wall-clock seconds between two "building model" progress lines."""

QOS = {
    'reliable': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                           reliability=ReliabilityPolicy.RELIABLE,
                           durability=DurabilityPolicy.VOLATILE),
    'best_effort': qos_profile_sensor_data,   # rclpy's: best effort, keep last 5
    'clock': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                        reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE),
    'latched': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                          reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL),
}
"""The node's QoS profiles, by name (:func:`ttb_sim.node.shell.qos_class` maps the topics')."""
DIAGNOSTICS_QOS = QOS['reliable']

_PARAM_TYPES = {'bool': ParameterType.PARAMETER_BOOL,
                'integer': ParameterType.PARAMETER_INTEGER,
                'double': ParameterType.PARAMETER_DOUBLE,
                'string': ParameterType.PARAMETER_STRING}


@functools.lru_cache(maxsize=None)
def message_class(name: str) -> Any:
    """Return the rclpy message class of a type name such as 'std_msgs/msg/Header'."""
    return get_message(name)


def ros_log(logger: Any, level: str, message: str) -> None:
    """
    Log at a level given by name ('debug' .. 'fatal') through an rclpy logger.

    rclpy ties a severity to each calling line (it refuses another severity from the
    same line), so each level has a call of its own.
    """
    if level == 'debug':
        logger.debug(message)
    elif level == 'info':
        logger.info(message)
    elif level == 'warning':
        logger.warning(message)
    elif level == 'error':
        logger.error(message)
    else:
        logger.fatal(message)


def optional_message_class(name: str) -> Any:
    """Return a message class, or None when its package is not installed (tf2_msgs)."""
    try:
        return message_class(name)
    except (ImportError, AttributeError, ValueError):
        return None


def descriptor(param: NodeParameter, numeric: NumericRange | None = None,
               allowed: str | None = None) -> ParameterDescriptor:
    """
    Build the ROS parameter descriptor of a node parameter.

    Double parameters use dynamic typing so that an integer (``350``) is
    accepted; the on-set callback validates numerically and the pre-set
    callback stores the value as a double. The range is exactly what the
    validation accepts (:func:`~ttb_sim.node.parameters.descriptor_range`).

    Parameters
    ----------
    param : NodeParameter
        The parameter's declaration.
    numeric : NumericRange, optional
        A narrower range than the declaration's (a family's rate once the
        model's output rate is known).
    allowed : str, optional
        The allowed values in words, for that narrower range.

    Returns
    -------
    ParameterDescriptor

    """
    d = ParameterDescriptor(type=_PARAM_TYPES[param.kind], description=param.description(),
                            additional_constraints=f'allowed: {allowed or param.allowed()}',
                            read_only=param.read_only,
                            dynamic_typing=param.accepts_integer)
    rng = numeric or descriptor_range(param)
    if rng is not None and param.kind == 'double':
        d.floating_point_range = [FloatingPointRange(
            from_value=float(rng.from_value), to_value=float(rng.to_value),
            step=float(rng.step))]
    elif rng is not None and param.kind == 'integer':
        d.integer_range = [IntegerRange(from_value=int(rng.from_value),
                                        to_value=int(rng.to_value), step=int(rng.step))]
    return d


class SimulatorNode(Node):
    """
    The ``ttb_sim`` node.

    The constructor validates everything a user gives at start-up (scenario,
    parameter values and types, bag destination) and returns at once; the model
    is built on the stepping thread. :attr:`fatal` completes with ``(message,
    exit code)`` if that build fails (or stepping ends on an unexpected error).

    Parameters
    ----------
    kwargs
        Passed to :class:`rclpy.node.Node` (e.g. ``parameter_overrides``).

    Raises
    ------
    ScenarioError
        If the scenario, a start-up parameter or the bag destination is invalid
        (the node is destroyed first).

    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('ttb_sim', **kwargs)
        self.stepper: Stepper | None = None
        self.publish_loop: PublishLoop | None = None
        self.topics: list[Topic] = []
        self.publishers_by_name: dict[str, Any] = {}
        self._live: list[Any] = []
        self._extra_pubs: list[Any] = []   # ~/labels, then ~/sensors/<name> in order
        self._messages: MessageCache | None = None
        self.fatal = Future()
        self._fatal: tuple[str, int] = ('', 0)
        self._clock_guard = ClockGuard()
        self._last_build_log = 0.0
        self._closed = False
        self._bag_path: Path | None = None
        self.tf_static_pub: Any = None
        self._restore_blas = hold_blas_threads()   # before any numpy work of the model
        self._log_handler = ForwardingHandler(self._forward_log)
        self._uninstall_log = install(self._log_handler)
        self._progress = ProgressWatcher()
        self._uninstall_progress = install(self._progress)
        try:
            self._configure()
        except BaseException:   # a bad value, or Ctrl-C in the middle of the set-up
            self.close()
            self.destroy_node()
            raise

    @property
    def controller(self) -> PassageController | None:
        """The passage controller, once the model is built (None before)."""
        return self.stepper.controller if self.stepper is not None else None

    # -- set-up -------------------------------------------------------------------------

    def _declare(self, name: str, default: Any, param: NodeParameter) -> Any:
        """Declare one parameter; a value rclpy refuses becomes a ScenarioError."""
        override = getattr(self, '_parameter_overrides', {}).get(name)
        if override is not None:
            ok, reason = validate_parameter(param, override.value, initial=True)
            if not ok:
                raise ScenarioError(reason)
        try:
            return self.declare_parameter(name, default, descriptor(param)).value
        except ParameterException as exc:
            raise ScenarioError(f'{name}: {" ".join(str(exc).split())} (allowed '
                                f'{param.allowed()})') from None

    def _configure(self) -> None:
        start = declare_parameters(self._declare)
        scenario, self.table, values = start.scenario, start.table, start.values
        self.scenario, self.values = scenario, values
        # Start-up integers for double parameters: store them as doubles, too.
        retype = [Parameter(n, Parameter.Type.DOUBLE, values[n])
                  for n in start.integers_for_doubles()]
        if retype:
            self.set_parameters(retype)

        self.namespace = self.get_fully_qualified_name()
        path = bag_destination(values, scenario.name)
        self._bag_path = path
        open_recorder = None if path is None else \
            functools.partial(self._open_recorder, path, values['bag.storage'])

        self.clock_pub = self.create_publisher(ClockMsg, '/clock', QOS['clock'])
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, '/diagnostics',
                                                     DIAGNOSTICS_QOS)
        self.markers_pub = self.create_publisher(MarkerArray, '~/model/markers',
                                                 QOS['latched'])
        tf_type = optional_message_class('tf2_msgs/msg/TFMessage')
        if tf_type is not None:
            self.tf_static_pub = self.create_publisher(tf_type, '/tf_static', QOS['latched'])
        else:
            self.get_logger().info('tf2_msgs is not installed: no static TF frames on '
                                   '/tf_static (apt install ros-jazzy-tf2-msgs)')
        self.create_service(Trigger, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/pause', self._on_pause)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.diagnostics_timer = self.create_timer(1.0, self._on_diagnostics, clock=steady)
        self.paused_clock_timer = self.create_timer(
            PAUSED_CLOCK_PERIOD, self._on_paused_clock,
            callback_group=MutuallyExclusiveCallbackGroup(), clock=steady)
        self._built_guard = self.create_guard_condition(self._on_built)
        self._failed_guard = self.create_guard_condition(self._on_failed)
        self.add_pre_set_parameters_callback(self._pre_set)
        self.add_on_set_parameters_callback(self._on_set)
        self.add_post_set_parameters_callback(self._post_set)
        self._publish_markers(scenario.train.start_position)

        self.stepper = Stepper(scenario, values, on_tick=self._on_tick,
                               open_recorder=open_recorder,
                               on_built=lambda _c: self._built_guard.trigger(),
                               on_failed=self._stepper_failed, budget=STEP_BUDGET)
        self.stepper.start()
        self.get_logger().info(f'scenario {scenario.name!r}: building model '
                               '(see /diagnostics)')

    def _open_recorder(self, path: Path, storage: str, layout: Layout) -> FrameSink:
        """Open the bag (on the stepping thread, which also writes and closes it)."""
        recorder = open_bag(path, storage, layout, self.namespace,
                            extra_topics(self.scenario.all_sensors))
        self._log('info', f'recording to {path} ({storage})')
        return recorder

    def _log(self, level: str, message: str) -> None:
        """Log through rclpy while the context is valid (never after shutdown: no rosout)."""
        if self.context.ok() and not self._closed:
            ros_log(self.get_logger(), level, message)

    def _forward_log(self, level: str, message: str) -> bool:
        """Log a library record through rclpy; False once the node is closed."""
        if not self.context.ok() or self._closed:
            return False
        ros_log(self.get_logger(), level, message)
        return True

    def _stepper_failed(self, message: str, code: int) -> None:
        """Hand a build failure to the executor (runs on the stepping thread)."""
        self._fatal = (message, code)
        self._failed_guard.trigger()

    def _on_failed(self) -> None:
        if not self.fatal.done():
            self.fatal.set_result(self._fatal)

    def _on_built(self) -> None:
        """Create the topic-table publishers (on the executor) and start publishing."""
        controller = self.controller
        if controller is None or self.publish_loop is not None or self._closed:
            return
        self.topics = topic_table(controller.layout)
        live = live_topics(self.topics)
        reliability = str(self.values['qos.reliability'])
        for topic, name in live:
            self.publishers_by_name[topic.name] = self.create_publisher(
                message_class(topic.msgtype), name, QOS[qos_class(topic.qos, reliability)])
        self._live = [self.publishers_by_name[t.name] for t, _ in live]
        if controller.sensing is not None:
            self._extra_pubs = [
                self.create_publisher(message_class(msgtype), f'~/{name}',
                                      QOS['latched' if index == 0 else
                                          qos_class('data', reliability)])
                for index, (name, msgtype) in enumerate(controller.sensing.extra)]
        self._messages = MessageCache([t for t, _ in live], message_class)
        self._narrow_rate_ranges(controller.output_period)
        if self.tf_static_pub is not None:
            self.tf_static_pub.publish(tf_message(
                message_class, static_frames(self.scenario, controller.layout)))
        self.publish_loop = PublishLoop(self._publish_frames, duty=PUBLISH_DUTY,
                                        threaded=False)
        self.publish_loop.start()
        assert self.stepper is not None
        self.stepper.publishing_ready()
        status = self.stepper.status()
        self.get_logger().info(
            f'model built in {status.elapsed:.2f} s: {controller.sim.dt:.3g} s steps, '
            f'{len(self.topics)} topics under {self.namespace}/; publishing')

    def _narrow_rate_ranges(self, output_period: float) -> None:
        """Make the family rates' descriptors end at the model's output rate."""
        if output_period <= 0:
            return
        output_rate = 1.0 / output_period
        for name in RATE_PARAMETERS:
            param = self.table[name]
            rng = descriptor_range(param)
            if rng is None or rng.to_value <= output_rate:
                continue
            narrow = replace(rng, to_value=output_rate)
            try:
                self.set_descriptor(name, descriptor(
                    param, narrow, f'[0, {output_rate:g}] Hz (the output rate of this model; '
                    '0 = publish_rate_hz)'))
            except Exception as exc:  # noqa: B902 - the on-set check refuses them anyway
                self.get_logger().debug(f'{name}: range not narrowed: {exc}')

    # -- parameters ---------------------------------------------------------------------

    def _pre_set(self, parameters: list[Parameter]) -> list[Parameter]:
        """Turn integers for double parameters into doubles (``ros2 param set ... 350``)."""
        out = []
        for p in parameters:
            spec = self.table.get(p.name)
            if (spec is not None and spec.accepts_integer
                    and p.type_ == Parameter.Type.INTEGER):
                p = Parameter(p.name, Parameter.Type.DOUBLE, float(p.value))
            out.append(p)
        return out

    def _on_set(self, parameters: list[Parameter]) -> SetParametersResult:
        """Validate proposed values; a refusal changes nothing and names the range."""
        known = {p.name: p.value for p in parameters if p.name in self.table}
        ok, reason = validate_changes(self.table, known)
        controller = self.controller
        if ok and controller is not None:
            ok, reason = controller.check_rates(known)
        return SetParametersResult(successful=ok, reason=reason)

    def _post_set(self, parameters: list[Parameter]) -> None:
        """Apply accepted values to the running simulation (or the one being built)."""
        for p in parameters:
            if p.name in self.table and self.stepper is not None:
                self.stepper.apply(p.name, p.value)
                self.values[p.name] = p.value
                self.get_logger().info(f'{p.name} = {p.value!r}')

    # -- services -----------------------------------------------------------------------

    def _building(self) -> str:
        assert self.stepper is not None
        return building_message(self.stepper.status())

    def _serve(self, act: Callable[[PassageController], tuple[bool, str]]) -> tuple[bool, str]:
        """Answer a service: (False, why) before the model exists, else act and wake stepping."""
        controller = self.controller
        if controller is None:
            return False, self._building()
        answer = act(controller)
        if self.stepper is not None:
            self.stepper.wake()
        return answer

    def _on_reset(self, request: Trigger.Request,
                  response: Trigger.Response) -> Trigger.Response:
        response.success, response.message = self._serve(lambda c: (True, c.reset()))
        return response

    def _on_pause(self, request: SetBool.Request,
                  response: SetBool.Response) -> SetBool.Response:
        response.success, response.message = self._serve(
            lambda c: pause_answer(c, bool(request.data)))
        return response

    # -- stepping and publishing --------------------------------------------------------

    def _on_tick(self, tick: Tick) -> None:
        """Log passage events and hand the frames to the publisher (stepping thread)."""
        for level, message in tick_messages(tick, self.controller):
            self._log(level, message)
        self._publish_sensing(tick)
        if self.publish_loop is not None:
            self.publish_loop.offer(list(zip(tick.frames, tick.due)), tick.markers)

    def _publish_frames(self, items: Sequence[tuple[Frame, frozenset[str]]],
                        refresh_markers: bool) -> None:
        """Send each frame's due messages in order (stepping thread), updated in place."""
        if not items and not refresh_markers:
            return
        cache = self._messages
        try:
            clock = bool(self.values['publish_clock'])
            for frame, due in items:
                if not self.context.ok() or cache is None:
                    return
                if clock:
                    self._publish_clock(frame.stamp_ns)
                for index, msg in cache.due_messages(frame, due):
                    self._live[index].publish(msg)
            if refresh_markers and items:
                self._publish_markers(items[-1][0].head_position)
        except Exception as exc:  # noqa: B902 - shutting down under our feet
            if self.context.ok() and not self._closed:
                raise
            self._log('debug', f'publishing stopped at shutdown: {exc}')

    def _publish_sensing(self, tick: Tick) -> None:
        """Publish the labels when they changed and every sensor sample (stepping thread)."""
        controller = self.controller
        sensing = controller.sensing if controller is not None else None
        if sensing is None or not self._extra_pubs or self._closed or not self.context.ok():
            return
        try:
            if tick.labels:
                self._extra_pubs[0].publish(sensing.labels_message(message_class))
            for sample in tick.samples:
                self._extra_pubs[sample.index].publish(sensing.message(message_class, sample))
        except Exception as exc:  # noqa: B902 - shutting down under our feet
            if self.context.ok() and not self._closed:
                raise
            self._log('debug', f'publishing stopped at shutdown: {exc}')

    def _publish_clock(self, stamp_ns: int) -> None:
        """Publish /clock unless that would go back in time (from any thread)."""
        self._clock_guard.send(stamp_ns, lambda sec, nanosec: self.clock_pub.publish(
            ClockMsg(clock=Time(sec=sec, nanosec=nanosec))))

    def _on_paused_clock(self) -> None:
        """While paused, idle or diverged, keep /clock at the current simulation time."""
        controller = self.controller
        if (controller is None or controller.state == 'running'
                or not self.values['publish_clock'] or self._closed):
            return
        self._publish_clock(round(controller.node_time * 1e9))

    def _publish_markers(self, head_position: float) -> None:
        self.markers_pub.publish(marker_array(message_class,
                                              markers(self.scenario, head_position)))

    def _on_diagnostics(self) -> None:
        if self.stepper is None:
            return
        controller = self.controller
        status = self.stepper.status()
        if (controller is None and status.state != 'failed'
                and status.elapsed - self._last_build_log >= BUILD_LOG_PERIOD):
            self._last_build_log = status.elapsed
            self.get_logger().info(f'building model {self.scenario.name!r}: '
                                   f'{status.elapsed:.1f} s so far')
        loop = self.publish_loop if controller is not None else None
        report = node_diagnostics(self.scenario.name, status,
                                  controller.diagnostics() if controller is not None else None,
                                  loop.stats() if loop is not None else None,
                                  loop.error if loop is not None else '',
                                  self._progress.latest)
        # Simulation time, like every data topic (0 while the model is being built).
        sim_ns = round(controller.node_time * 1e9) if controller is not None else 0
        sec, nanosec = divmod(sim_ns, 1_000_000_000)
        self.diagnostics_pub.publish(diagnostic_array(
            message_class, report, 'ttb_sim: simulation', self.get_name(),
            Time(sec=sec, nanosec=nanosec)))

    def close(self) -> None:
        """Stop publishing, then stepping (the bag closes on its thread); log what ran."""
        if self._closed:
            return
        self._closed = True   # from here on nothing is published through rclpy
        if self.publish_loop is not None:
            self.publish_loop.stop()
        building = self.stepper is not None and self.stepper.status().state == 'building'
        # Once rclpy shuts down (SIGINT, possibly while this runs) the node's logger cannot
        # reach /rosout any more; a child logger is not tied to /rosout, so it always logs
        # (console and log file), whenever the shutdown comes.
        logger = get_logger(f'{self.get_name()}.shutdown')
        if self.stepper is not None and not self.stepper.stop(timeout=1.0 if building else 10.0):
            logger.warning('the model is still being built; leaving it behind (no bag was '
                           'open yet)')
        if self.stepper is not None:
            published = self.publish_loop.stats().published if self.publish_loop else 0
            logger.info(shutdown_line(self.controller, published, self._bag_path))
        self._uninstall_progress()   # before the forwarding handler: it restores the logger
        self._uninstall_log()
        if self._restore_blas is not None:
            self._restore_blas()
            self._restore_blas = None


def _shutting_down(context: Any = None) -> bool:
    """Tell whether rclpy is shutting down (the context is no longer valid)."""
    try:
        return not rclpy.ok(context=context)
    except Exception:  # noqa: B902 - no context at all: shutting down
        return True


def main(args: list[str] | None = None) -> int:
    """
    Run the node until shutdown, Ctrl-C or SIGTERM.

    Parameters
    ----------
    args : list of str, optional
        Command-line arguments (``--ros-args ...``); ``sys.argv`` when omitted.

    Returns
    -------
    int
        0 on a normal or signalled end, 2 on an invalid scenario, parameter or bag
        destination, or a model that cannot be built (one FATAL line).

    """
    logger = get_logger('ttb_sim')
    try:
        rclpy.init(args=args)
    except KeyboardInterrupt:
        return 0
    node: SimulatorNode | None = None
    executor: MultiThreadedExecutor | None = None
    code = 0
    try:
        node = SimulatorNode()
        executor = MultiThreadedExecutor()
        executor.add_node(node)
        executor.spin_until_future_complete(node.fatal)
        if node.fatal.done():
            message, code = node.fatal.result()
            logger.fatal(message)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (ScenarioError, ModelError) as exc:
        logger.fatal(str(exc))
        code = 2
    except Exception as exc:  # noqa: B902 - the rclpy shutdown race (RCLError, InvalidHandle)
        if not _shutting_down():
            logger.fatal(f'{type(exc).__name__}: {exc}')
            code = 1
    finally:
        _finish(node, executor)
    return code


def _finish(node: SimulatorNode | None, executor: MultiThreadedExecutor | None) -> None:
    """Close the bag, destroy the node and shut rclpy down; a second Ctrl-C changes nothing."""
    for step in ('close', 'executor', 'destroy', 'shutdown'):
        try:
            if step == 'close' and node is not None:
                node.close()
            elif step == 'executor' and executor is not None:
                executor.shutdown(timeout_sec=1.0)
            elif step == 'destroy' and node is not None:
                node.destroy_node()
            elif step == 'shutdown':
                rclpy.try_shutdown()
        except (KeyboardInterrupt, Exception):  # noqa: B902 - never a traceback at exit
            pass


if __name__ == '__main__':
    sys.exit(main())
