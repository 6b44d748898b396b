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
Virtual sensors: what a monitoring system would record of the model, with its imperfections.

A scenario's ``sensors`` list and ``sensor_layouts`` (records in
:mod:`ttb_sim.config.sensor_records`, places in :mod:`ttb_sim.config.sensor_places`,
layouts in :mod:`ttb_sim.config.sensor_layouts`) name each sensor, its type, its
place in the model and its acquisition chain. Here: :class:`SensorBank` gathers each
sensor's truth from the frames of a run (:mod:`~ttb_sim.sensors.locations`) and
passes it through its :class:`Acquisition` chain; ``ttb-sim run`` publishes the
samples on ``~/sensors/<name>`` beside the exact truth. See docs/sensors.md.
"""

from ttb_sim.config.sensor_records import SENSOR_TYPES, SensorConfig, SensorError, UNITS
from ttb_sim.sensors.acquisition import Acquisition, AntiAlias, design_anti_alias, Samples
from ttb_sim.sensors.bank import SensorBank, SensorChannel

__all__ = ['Acquisition', 'AntiAlias', 'design_anti_alias', 'Samples', 'SENSOR_TYPES',
           'SensorBank', 'SensorChannel', 'SensorConfig', 'SensorError', 'UNITS']
