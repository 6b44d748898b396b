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

The scenario's ``sensors`` list (:class:`SensorConfig`) names each sensor, its
type, its place in the model and its acquisition chain; :class:`SensorBank`
(``ttb_sim.sensors.bank``) turns the frames of a run into each sensor's samples,
published on ``~/sensors/<name>`` beside the exact truth on the other topics.
See docs/sensors.md.
"""

from ttb_sim.sensors.places import ALLOWED_PLACES, probe_requests, ProbeRequest
from ttb_sim.sensors.records import SENSOR_TYPES, SensorConfig, SensorError, UNITS

__all__ = ['ALLOWED_PLACES', 'probe_requests', 'ProbeRequest', 'SENSOR_TYPES', 'SensorConfig',
           'SensorError', 'UNITS']
