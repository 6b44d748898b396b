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
The topics of the virtual sensors and of the labels: names, types and messages.

Each sensor publishes on ``~/sensors/<name>`` at its own sample times:

- accelerometer: ``sensor_msgs/msg/Imu``, the measured axes of
  ``linear_acceleration`` with their variance on the covariance's diagonal (white
  noise per sample plus the quantisation's step^2/12); an axis not measured reads 0
  with variance -1 (REP 145's "not provided", per axis); no orientation, no
  angular velocity (their covariances' first element -1);
- wheel_force: ``geometry_msgs/msg/WrenchStamped``, the measured force axes;
- displacement, inclinometer, geophone, strain: ``geometry_msgs/msg/Vector3Stamped``,
  the measured axes (a strain gauge's strain in ``x``).

``~/labels`` (``std_msgs/msg/String``, latched) holds the run's ground truth as JSON.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
from typing import Any, Sequence

import numpy as np

from ttb_sim.config.sensor_places import AXIS
from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.io.topics import (build_vector3_stamped, build_wrench_stamped, MessageTypes,
                               NAMESPACE, stamped_header, vector3)

__all__ = ['extra_topics', 'LABELS_TOPIC', 'labels_message', 'SensorTopic', 'sensor_topics']

LABELS_TOPIC = 'labels'
"""The labels' topic, private to the node (``~/labels``)."""

MESSAGE_TYPES = {'accelerometer': 'sensor_msgs/msg/Imu',
                 'wheel_force': 'geometry_msgs/msg/WrenchStamped'}
"""The message type of each sensor type (the others: ``geometry_msgs/msg/Vector3Stamped``)."""


@dataclass(frozen=True)
class SensorTopic:
    """The topic of one sensor and how its samples become messages."""

    config: SensorConfig
    variance: float
    """Variance of one sample's noise (unit^2): white noise plus quantisation."""

    @property
    def name(self) -> str:
        """Return the topic name relative to the node (``sensors/<name>``)."""
        return f'sensors/{self.config.name}'

    @property
    def msgtype(self) -> str:
        """Return the topic's message type."""
        return MESSAGE_TYPES.get(self.config.type, 'geometry_msgs/msg/Vector3Stamped')

    def full_name(self, namespace: str = NAMESPACE) -> str:
        """Return the absolute topic name under a node namespace."""
        return f'{namespace}/{self.name}'

    def spread(self, values: np.ndarray) -> np.ndarray:
        """Return (n, 3) values with the measured axes in place and zeros elsewhere."""
        out = np.zeros((len(values), 3))
        out[:, [AXIS[a] for a in self.config.measured_axes]] = values
        return out

    def message(self, types: MessageTypes, stamp_ns: int, xyz: np.ndarray) -> Any:
        """Build the message of one sample, its values already spread to x, y, z."""
        kind = self.config.type
        if kind == 'accelerometer':
            return self._imu(types, stamp_ns, xyz)
        if kind == 'wheel_force':
            return build_wrench_stamped(types, stamp_ns, np.concatenate([xyz, np.zeros(3)]))
        return build_vector3_stamped(types, stamp_ns, xyz)

    def _imu(self, types: MessageTypes, stamp_ns: int, xyz: np.ndarray) -> Any:
        covariance = np.zeros(9)
        diagonal = np.full(3, -1.0)
        diagonal[[AXIS[a] for a in self.config.measured_axes]] = self.variance
        covariance[[0, 4, 8]] = diagonal
        not_provided = np.zeros(9)
        not_provided[0] = -1.0
        quaternion = types('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0)
        return types('sensor_msgs/msg/Imu')(
            header=stamped_header(types, stamp_ns), orientation=quaternion,
            orientation_covariance=not_provided.copy(),
            angular_velocity=vector3(types, (0.0, 0.0, 0.0)),
            angular_velocity_covariance=not_provided.copy(),
            linear_acceleration=vector3(types, xyz), linear_acceleration_covariance=covariance)


def extra_topics(sensors: Sequence[SensorConfig]) -> list[tuple[str, str]]:
    """Return (name, message type) of the labels' topic, then of each sensor's topic."""
    return [(LABELS_TOPIC, 'std_msgs/msg/String')] + [
        (SensorTopic(c, 0.0).name, SensorTopic(c, 0.0).msgtype) for c in sensors]


def sensor_topics(sensors: Sequence[SensorConfig],
                  noise_std: Sequence[float]) -> list[SensorTopic]:
    """Return the sensors' topics, with each sample's noise std (white noise, per sample)."""
    return [SensorTopic(c, float(s) ** 2 + c.resolution ** 2 / 12.0)
            for c, s in zip(sensors, noise_std)]


def labels_message(types: MessageTypes, labels: dict[str, Any]) -> Any:
    """Build the ``std_msgs/msg/String`` of the labels (sorted-key JSON)."""
    return types('std_msgs/msg/String')(data=json.dumps(labels, sort_keys=True))
