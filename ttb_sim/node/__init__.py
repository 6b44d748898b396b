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
The simulator node's logic, free of ROS, so that it is tested where ROS 2 is absent.

:mod:`ttb_sim.simulator_node` is a thin rclpy shell over this package: it only
copies values into and out of rclpy objects.

- :mod:`~ttb_sim.node.parameters`: the parameter table (derived from the scenario
  schema), validation and normalisation of values, start-up values, the
  scenario of a passage;
- :mod:`~ttb_sim.node.passage`: the :class:`PassageController` that steps,
  paces, records and reports passages (ticks);
- :mod:`~ttb_sim.node.runs`: what it steps and records into (the train run, the frame sink);
- :mod:`~ttb_sim.node.diagnostics`: what ``/diagnostics`` says, as plain data
  (the report, the stepping meter, the level of a passage state);
- :mod:`~ttb_sim.node.stepper`: the stepping thread (:class:`Stepper`) that builds
  the model, opens, writes and closes the bag and steps, off the executor;
- :mod:`~ttb_sim.node.publishing`: the publishing loop (:class:`PublishLoop`)
  that sends frames within a share of the processor, dropping what it cannot send;
- :mod:`~ttb_sim.node.markers`: the structure and train markers as plain boxes;
- :mod:`~ttb_sim.node.message_cache`: live messages built once per topic and
  updated in place;
- :mod:`~ttb_sim.node.shell`: what the rclpy shell decides without ROS (start-up
  parameters, bag destination, /clock guard, the node's diagnostics, log lines).

Threads of the node: the executor answers parameters and services and runs the
1 Hz diagnostics and the 10 Hz paused-clock timers; it is never blocked by the
model. The stepping thread (:class:`Stepper`) builds the model (``/diagnostics``
says "building model" meanwhile), opens the bag, steps paced by
``real_time_factor``, writes every frame to the bag and closes it: the bag lives
on this one thread (SQLite requires it). It also publishes, through a
:class:`PublishLoop` without a thread of its own: after each stepping tick, the
frames due at ``publish_rate_hz`` go out as one batch (messages built once per
topic and updated in place, :mod:`~ttb_sim.node.message_cache`), within 20 % of
the processor (CPU time), dropping (and counting) frames beyond that budget
instead of slowing the stepping. A separate publishing thread was measured to
cost more than the publishing itself (the two threads fought over the
interpreter lock).
"""

from ttb_sim.node.diagnostics import DiagnosticsReport, ERROR, frame_values, OK, WARN
from ttb_sim.node.markers import Box, markers, MarkerSet, model_markers, train_markers
from ttb_sim.node.parameters import (DEFAULT_SCENARIO, initial_values, IRREGULARITY_KEYS,
                                     NodeParameter, normalize_value, parameter_table,
                                     SCENARIO_KEYS, scenario_with, validate_changes,
                                     validate_parameter)
from ttb_sim.node.passage import PassageController, Tick
from ttb_sim.node.publishing import PublishLoop, PublishStats
from ttb_sim.node.runs import FrameSink, TrainRun
from ttb_sim.node.stepper import Stepper, StepperStatus

__all__ = [
    'Box',
    'DEFAULT_SCENARIO',
    'DiagnosticsReport',
    'ERROR',
    'frame_values',
    'FrameSink',
    'initial_values',
    'IRREGULARITY_KEYS',
    'MarkerSet',
    'markers',
    'model_markers',
    'NodeParameter',
    'normalize_value',
    'OK',
    'parameter_table',
    'PassageController',
    'PublishLoop',
    'PublishStats',
    'SCENARIO_KEYS',
    'scenario_with',
    'Stepper',
    'StepperStatus',
    'Tick',
    'TrainRun',
    'train_markers',
    'validate_changes',
    'validate_parameter',
    'WARN',
]
