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
service calls to a :class:`~ttb_sim.node.passage.PassageController`, and copies
the controller's frames, diagnostics and markers into standard messages.

Publishers and their QoS (all explicit):

- the topic table (:func:`ttb_sim.io.topics.topic_table`), private topics
  ``~/...``: reliable, volatile, keep last 10 (QoS class 'sensor');
- ``/clock`` (when ``publish_clock``): reliable, volatile, keep last 1, so that
  both best-effort (rclcpp/rclpy time sources) and reliable subscribers match;
- ``/diagnostics``: reliable, volatile, keep last 10, at 1 Hz (wall clock);
- ``~/model/markers``: reliable, transient local, keep last 1 (latched: a late
  RViz gets the structure and the latest train position).

Stepping runs in a steady-clock timer of its own callback group under a
:class:`rclpy.executors.MultiThreadedExecutor`, so parameter and service calls
(default callback group) are answered while the model steps; each tick steps
for at most 20 ms. Timers use the steady clock, so ``use_sim_time`` (driven by
this node's own /clock) cannot stall them. The bag is closed in ``main``'s
``finally`` on shutdown, SIGINT and SIGTERM.
"""

from __future__ import annotations

import functools
from pathlib import Path
import sys
from typing import Any

from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Point, Pose, Quaternion, Vector3
from rcl_interfaces.msg import (FloatingPointRange, IntegerRange, ParameterDescriptor,
                                ParameterType, SetParametersResult)
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.logging import get_logger
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rosidl_runtime_py.utilities import get_message
from std_msgs.msg import ColorRGBA, Header
from std_srvs.srv import SetBool, Trigger
from ttb_sim.config import load_scenario
from ttb_sim.errors import ModelError, ScenarioError
from ttb_sim.io.bag import BagRecorder, default_bag_path
from ttb_sim.io.topics import FRAME_ID, topic_table
from ttb_sim.node import (DEFAULT_SCENARIO, initial_values, markers, MarkerSet, NodeParameter,
                          parameter_table, PassageController, validate_changes)
from visualization_msgs.msg import Marker, MarkerArray

STEP_PERIOD = 0.01
"""Stepping timer period (s, wall clock)."""
STEP_BUDGET = 0.02
"""Wall-clock seconds one stepping tick may spend (keeps calls answered within 100 ms)."""

QOS = {
    'sensor': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                         reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.VOLATILE),
    'clock': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                        reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.VOLATILE),
    'latched': QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                          reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL),
}
"""QoS of each topic-table QoS class."""
DIAGNOSTICS_QOS = QOS['sensor']

_PARAM_TYPES = {'bool': ParameterType.PARAMETER_BOOL,
                'integer': ParameterType.PARAMETER_INTEGER,
                'double': ParameterType.PARAMETER_DOUBLE,
                'string': ParameterType.PARAMETER_STRING}


@functools.lru_cache(maxsize=None)
def message_class(name: str) -> Any:
    """Return the rclpy message class of a type name such as 'std_msgs/msg/Header'."""
    return get_message(name)


def descriptor(param: NodeParameter) -> ParameterDescriptor:
    """
    Build the ROS parameter descriptor of a node parameter.

    Double parameters use dynamic typing so that an integer (``350``) is
    accepted; the on-set callback validates numerically and the pre-set
    callback stores the value as a double.

    Parameters
    ----------
    param : NodeParameter
        The parameter's declaration.

    Returns
    -------
    ParameterDescriptor

    """
    d = ParameterDescriptor(type=_PARAM_TYPES[param.kind], description=param.description(),
                            additional_constraints=f'allowed: {param.allowed()}',
                            read_only=param.read_only,
                            dynamic_typing=param.accepts_integer)
    spec = param.spec
    if spec.low is not None and spec.high is not None:
        if param.kind == 'double':
            d.floating_point_range = [FloatingPointRange(
                from_value=float(spec.low), to_value=float(spec.high), step=0.0)]
        elif param.kind == 'integer':
            d.integer_range = [IntegerRange(from_value=int(spec.low), to_value=int(spec.high),
                                            step=1)]
    return d


class SimulatorNode(Node):
    """
    The ``ttb_sim`` node.

    Parameters
    ----------
    kwargs
        Passed to :class:`rclpy.node.Node` (e.g. ``parameter_overrides``).

    Raises
    ------
    ScenarioError
        If the scenario or a start-up parameter is invalid, or the bag cannot be
        created (the node is destroyed first).

    """

    def __init__(self, **kwargs: Any) -> None:
        super().__init__('ttb_sim', **kwargs)
        self.controller: PassageController | None = None
        try:
            self._configure()
        except (ScenarioError, ModelError):
            self.close()
            self.destroy_node()
            raise

    @property
    def _controller(self) -> PassageController:
        """The passage controller; set by the constructor (callbacks run only after it)."""
        if self.controller is None:
            raise RuntimeError('the ttb_sim node is not configured')
        return self.controller

    # -- set-up -------------------------------------------------------------------------

    def _configure(self) -> None:
        table = parameter_table()
        first = table['scenario']
        source = self.declare_parameter('scenario', DEFAULT_SCENARIO,
                                        descriptor(first)).value
        scenario = load_scenario(source)
        self.table = parameter_table(scenario)
        given: dict[str, Any] = {'scenario': source}
        for name, param in self.table.items():
            if name != 'scenario':
                given[name] = self.declare_parameter(name, param.default,
                                                     descriptor(param)).value
        values = initial_values(self.table, given)
        # Start-up integers for double parameters: store them as doubles, too.
        retype = [Parameter(n, Parameter.Type.DOUBLE, values[n]) for n, p in self.table.items()
                  if p.kind == 'double' and not isinstance(given[n], float)]
        if retype:
            self.set_parameters(retype)

        self._types = message_class
        namespace = self.get_fully_qualified_name()
        self.controller = PassageController(scenario, values)
        self.topics = topic_table(self.controller.layout)
        if values['bag.enabled']:
            path = Path(values['bag.path']) if values['bag.path'] else \
                default_bag_path(scenario.name)
            path.parent.mkdir(parents=True, exist_ok=True)
            # Nothing has been stepped yet, so the bag gets every frame from t = 0.
            self.controller.recorder = BagRecorder(path, self.topics, values['bag.storage'],
                                                   namespace=namespace).__enter__()
            self.get_logger().info(f'recording to {path} ({values["bag.storage"]})')
        self.publishers_by_name = {}
        for topic in self.topics:
            name = topic.name if topic.name.startswith('/') else f'~/{topic.name}'
            self.publishers_by_name[topic.name] = self.create_publisher(
                message_class(topic.msgtype), name, QOS[topic.qos])
        self.diagnostics_pub = self.create_publisher(DiagnosticArray, '/diagnostics',
                                                     DIAGNOSTICS_QOS)
        self.markers_pub = self.create_publisher(MarkerArray, '~/model/markers',
                                                 QOS['latched'])
        self.create_service(Trigger, '~/reset', self._on_reset)
        self.create_service(SetBool, '~/pause', self._on_pause)

        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.step_timer = self.create_timer(STEP_PERIOD, self._on_step,
                                            callback_group=MutuallyExclusiveCallbackGroup(),
                                            clock=steady)
        self.diagnostics_timer = self.create_timer(1.0, self._on_diagnostics, clock=steady)

        self.add_pre_set_parameters_callback(self._pre_set)
        self.add_on_set_parameters_callback(self._on_set)
        self.add_post_set_parameters_callback(self._post_set)
        self._publish_markers(scenario.train.start_position)
        self.get_logger().info(
            f'scenario {scenario.name!r}: {self.controller.sim.dt:.3g} s steps, '
            f'{len(self.topics)} topics under {namespace}/')

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
        ok, reason = validate_changes(self.table, {p.name: p.value for p in parameters})
        return SetParametersResult(successful=ok, reason=reason)

    def _post_set(self, parameters: list[Parameter]) -> None:
        """Apply accepted values to the running simulation."""
        for p in parameters:
            self._controller.apply(p.name, p.value)
            self.get_logger().info(f'{p.name} = {p.value!r}')

    # -- services -----------------------------------------------------------------------

    def _on_reset(self, request: Trigger.Request,
                  response: Trigger.Response) -> Trigger.Response:
        response.message = self._controller.reset()
        response.success = True
        return response

    def _on_pause(self, request: SetBool.Request,
                  response: SetBool.Response) -> SetBool.Response:
        response.message = self._controller.set_paused(bool(request.data))
        response.success = self._controller.state in ('paused', 'running')
        return response

    # -- stepping and publishing --------------------------------------------------------

    def _on_step(self) -> None:
        tick = self._controller.advance(budget=STEP_BUDGET)
        if 'diverged' in tick.events:
            self.get_logger().error(f'{self._controller.divergence}; stepping stopped, bag '
                                    'closed; call ~/reset to restart')
        if 'idle' in tick.events:
            self.get_logger().info('the train has left: idle (set loop:=true or call '
                                   '~/reset for another passage)')
        if not tick.frames or not self.context.ok():
            return
        clock = self._controller.values['publish_clock']
        try:
            for frame in tick.frames:
                for topic in self.topics:
                    if topic.qos == 'clock' and not clock:
                        continue
                    self.publishers_by_name[topic.name].publish(
                        topic.message(self._types, frame))
            if tick.markers:
                self._publish_markers(tick.frames[-1].head_position)
        except Exception as exc:  # noqa: B902 - shutting down under our feet
            if self.context.ok():
                raise
            self.get_logger().debug(f'publishing stopped at shutdown: {exc}')

    def _publish_markers(self, head_position: float) -> None:
        self.markers_pub.publish(marker_array(markers(self._controller.base, head_position)))

    def _on_diagnostics(self) -> None:
        report = self._controller.diagnostics()
        status = DiagnosticStatus(level=bytes([report.level]), name='ttb_sim: simulation',
                                  message=report.message, hardware_id=self.get_name(),
                                  values=[KeyValue(key=k, value=v) for k, v in report.values])
        header = Header(stamp=self.get_clock().now().to_msg(), frame_id='')
        self.diagnostics_pub.publish(DiagnosticArray(header=header, status=[status]))

    def close(self) -> None:
        """Stop stepping and close the bag (idempotent; called before destroy_node)."""
        if self.controller is not None:
            self.controller.close()


def marker_array(marker_set: MarkerSet) -> MarkerArray:
    """
    Copy a plain marker description into a ``visualization_msgs/msg/MarkerArray``.

    Parameters
    ----------
    marker_set : MarkerSet
        Boxes in the track frame.

    Returns
    -------
    MarkerArray
        One CUBE marker per box, stamp zero (latest transform), never expiring.

    """
    header = Header(stamp=Time(sec=0, nanosec=0), frame_id=marker_set.frame_id or FRAME_ID)
    out = []
    for box in marker_set.boxes:
        x, y, z = (float(v) for v in box.position)
        sx, sy, sz = (float(v) for v in box.size)
        r, g, b, a = (float(v) for v in box.color)
        out.append(Marker(header=header, ns=box.ns, id=box.marker_id, type=Marker.CUBE,
                          action=Marker.ADD,
                          pose=Pose(position=Point(x=x, y=y, z=z),
                                    orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0)),
                          scale=Vector3(x=sx, y=sy, z=sz),
                          color=ColorRGBA(r=r, g=g, b=b, a=a), frame_locked=False))
    return MarkerArray(markers=out)


def main(args: list[str] | None = None) -> int:
    """
    Run the node until shutdown, Ctrl-C or SIGTERM (the Jazzy pattern).

    Parameters
    ----------
    args : list of str, optional
        Command-line arguments (``--ros-args ...``); ``sys.argv`` when omitted.

    Returns
    -------
    int
        0 on a normal or signalled end, 2 on an invalid scenario or parameter.

    """
    rclpy.init(args=args)
    node = None
    code = 0
    try:
        node = SimulatorNode()
        executor = MultiThreadedExecutor()
        executor.add_node(node)
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (ScenarioError, ModelError) as exc:
        get_logger('ttb_sim').fatal(str(exc))
        code = 2
    finally:
        if node is not None:
            node.close()
            node.destroy_node()
        rclpy.try_shutdown()
    return code


if __name__ == '__main__':
    sys.exit(main())
