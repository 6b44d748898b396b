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
The topic table: names, standard ROS 2 message types and frame -> message conversion.

One table serves the offline bag writer (messages built from the rosbags
typestore) and the live node (messages built from the rclpy classes): a
conversion receives a ``types`` callable that maps a type name such as
``'geometry_msgs/msg/Vector3Stamped'`` to a message class, and builds the message
with keyword arguments named exactly as the ROS fields. Every field is given, so
the same call works for both back-ends. A topic reads its numbers from the
frame's flat row (:attr:`~ttb_sim.sim.Frame.row`) at its ``columns``, so that
the values of many frames and topics are gathered with one index; the
builders stay the one definition of each message, and the bags' bulk CDR
layouts are learnt from them (:mod:`ttb_sim.io.codec`).
"""

from __future__ import annotations

import array
from dataclasses import dataclass
from functools import cached_property
from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.sim import Frame, Layout

MessageTypes = Callable[[str], Any]
"""Maps a ROS type name to its message class."""

FRAME_ID = 'track'
"""REP 103 track frame: x along the track from its start, y left, z up."""
NAMESPACE = '/ttb_sim'
"""Default node namespace of the private topics (node name ``ttb_sim``)."""

_ZERO9 = np.zeros(9)
_NO_ORIENTATION = np.array([-1.0, 0, 0, 0, 0, 0, 0, 0, 0])  # REP 145: not provided


def _time(types: MessageTypes, stamp_ns: int) -> Any:
    return types('builtin_interfaces/msg/Time')(sec=int(stamp_ns // 1_000_000_000),
                                                nanosec=int(stamp_ns % 1_000_000_000))


def stamped_header(types: MessageTypes, stamp_ns: int) -> Any:
    """Build the ``std_msgs/msg/Header`` of a message: its stamp, frame :data:`FRAME_ID`."""
    return types('std_msgs/msg/Header')(stamp=_time(types, stamp_ns), frame_id=FRAME_ID)


def vector3(types: MessageTypes, xyz: Sequence[float] | np.ndarray) -> Any:
    """Build a ``geometry_msgs/msg/Vector3`` from (x, y, z)."""
    return types('geometry_msgs/msg/Vector3')(x=float(xyz[0]), y=float(xyz[1]),
                                              z=float(xyz[2]))


def build_vector3_stamped(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """Build ``geometry_msgs/msg/Vector3Stamped`` from (x, y, z)."""
    return types('geometry_msgs/msg/Vector3Stamped')(header=stamped_header(types, stamp_ns),
                                                     vector=vector3(types, values))


def build_wrench_stamped(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """Build ``geometry_msgs/msg/WrenchStamped`` from (fx, fy, fz, tx, ty, tz)."""
    wrench = types('geometry_msgs/msg/Wrench')(force=vector3(types, values[:3]),
                                               torque=vector3(types, values[3:6]))
    return types('geometry_msgs/msg/WrenchStamped')(header=stamped_header(types, stamp_ns),
                                                    wrench=wrench)


def build_imu(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """Build ``sensor_msgs/msg/Imu`` from (ax, ay, az, wx, wy, wz); no orientation."""
    quaternion = types('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0)
    return types('sensor_msgs/msg/Imu')(
        header=stamped_header(types, stamp_ns), orientation=quaternion,
        orientation_covariance=_NO_ORIENTATION.copy(),
        angular_velocity=vector3(types, values[3:6]),
        angular_velocity_covariance=_ZERO9.copy(),
        linear_acceleration=vector3(types, values[:3]),
        linear_acceleration_covariance=_ZERO9.copy())


def build_odometry(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """Build ``nav_msgs/msg/Odometry`` from (head position x, speed vx)."""
    point = types('geometry_msgs/msg/Point')(x=float(values[0]), y=0.0, z=0.0)
    quaternion = types('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0)
    pose = types('geometry_msgs/msg/Pose')(position=point, orientation=quaternion)
    twist = types('geometry_msgs/msg/Twist')(
        linear=vector3(types, (values[1], 0.0, 0.0)),
        angular=vector3(types, (0.0, 0.0, 0.0)))
    pose_cov = types('geometry_msgs/msg/PoseWithCovariance')(pose=pose,
                                                             covariance=np.zeros(36))
    twist_cov = types('geometry_msgs/msg/TwistWithCovariance')(twist=twist,
                                                               covariance=np.zeros(36))
    return types('nav_msgs/msg/Odometry')(header=stamped_header(types, stamp_ns),
                                          child_frame_id='train', pose=pose_cov,
                                          twist=twist_cov)


SOIL_FIELDS = ('x', 'y', 'z', 'ux', 'uy', 'uz', 'ax', 'ay', 'az', 'vx', 'vy', 'vz')
"""
Float32 fields of every ground point in ``~/soil/points``, in this order.

Position (m), displacement (m), acceleration (m/s^2), then velocity (m/s): the
velocity comes last so that the first nine fields keep the offsets readers of
the earlier nine-field clouds use.
"""
_FLOAT32 = 7  # sensor_msgs/msg/PointField.FLOAT32


def build_point_cloud(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """
    Build ``sensor_msgs/msg/PointCloud2`` of ground points from flattened (n, 12) values.

    One row of n points (``height`` 1), little-endian float32 fields
    :data:`SOIL_FIELDS`, 48 bytes per point, dense.
    """
    points = np.ascontiguousarray(np.asarray(values, dtype='<f4').reshape(-1, len(SOIL_FIELDS)))
    field_type = types('sensor_msgs/msg/PointField')
    fields = [field_type(name=name, offset=4 * i, datatype=_FLOAT32, count=1)
              for i, name in enumerate(SOIL_FIELDS)]
    step = 4 * len(SOIL_FIELDS)
    cloud = types('sensor_msgs/msg/PointCloud2')
    raw = points.view(np.uint8).ravel()
    # rosbags' message classes take a numpy uint8 array, rclpy's an array('B').
    data: Any = raw if cloud.__module__.startswith('rosbags') else array.array('B', raw.tobytes())
    return cloud(header=stamped_header(types, stamp_ns), height=1, width=int(points.shape[0]),
                 fields=fields, is_bigendian=False, point_step=step,
                 row_step=step * int(points.shape[0]), data=data, is_dense=True)


def build_clock(types: MessageTypes, stamp_ns: int, values: np.ndarray) -> Any:
    """Build ``rosgraph_msgs/msg/Clock``."""
    return types('rosgraph_msgs/msg/Clock')(clock=_time(types, stamp_ns))


VECTOR3 = ('x', 'y', 'z')
WRENCH = ('force.x', 'force.y', 'force.z', 'torque.x', 'torque.y', 'torque.z')
IMU = ('linear_acceleration.x', 'linear_acceleration.y', 'linear_acceleration.z',
       'angular_velocity.x', 'angular_velocity.y', 'angular_velocity.z')


@dataclass(frozen=True)
class Topic:
    """
    One published / recorded topic.

    Attributes
    ----------
    name : str
        Name relative to the node (``bridge/span01/midspan``), or absolute
        (``/clock``) for global topics.
    msgtype : str
        Standard ROS 2 message type.
    fields : tuple of str
        Names of the numeric values that ``extract`` returns (for summaries).
    columns : tuple of int
        Where the topic's values are in a frame's flat row (:attr:`~ttb_sim.sim.Frame.row`,
        mapped by :meth:`~ttb_sim.sim.Layout.columns`), in the order ``build`` takes them.
    build : callable
        (types, stamp_ns, values) -> message.
    qos : str
        'data' (the data topics: the node publishes them reliable or best effort, as its
        ``qos.reliability`` says), 'clock' or 'latched'.
    unit : str
        Unit of the values, for documentation.

    """

    name: str
    msgtype: str
    fields: tuple[str, ...]
    columns: tuple[int, ...]
    build: Callable[[MessageTypes, int, np.ndarray], Any]
    qos: str = 'data'
    unit: str = ''

    def full_name(self, namespace: str = NAMESPACE) -> str:
        """Return the absolute topic name under a node namespace."""
        return self.name if self.name.startswith('/') else f'{namespace}/{self.name}'

    @cached_property
    def index(self) -> np.ndarray:
        """Return :attr:`columns` as an integer index array."""
        return np.asarray(self.columns, dtype=np.intp)

    def extract(self, frame: Frame) -> np.ndarray:
        """Return the topic's numeric values (SI) of a frame."""
        return frame.row[self.index]

    def message(self, types: MessageTypes, frame: Frame) -> Any:
        """Convert a frame to this topic's message."""
        return self.build(types, frame.stamp_ns, self.extract(frame))


def _columns(*parts: np.ndarray) -> tuple[int, ...]:
    """Return the row columns of some blocks of :meth:`~ttb_sim.sim.Layout.columns`, in order."""
    return tuple(int(c) for part in parts for c in np.ravel(part))


def topic_table(layout: Layout) -> list[Topic]:
    """
    Return the topics a run with this layout produces, in a fixed order.

    Parameters
    ----------
    layout : Layout
        Sizes of the model's outputs.

    Returns
    -------
    list of Topic

    """
    col = layout.columns()
    pad3 = np.full(3, col['zero'])   # the torque of a force-only wrench
    topics = [Topic('/clock', 'rosgraph_msgs/msg/Clock', (), (), build_clock, qos='clock',
                    unit='s')]
    if layout.train:
        topics.append(Topic('train/odometry', 'nav_msgs/msg/Odometry',
                            ('pose.pose.position.x', 'twist.twist.linear.x'),
                            _columns(col['head_position'], col['speed']), build_odometry,
                            unit='m, m/s'))
    for i in range(layout.n_bodies):
        topics.append(Topic(
            f'train/car{i + 1:02d}/body/imu', 'sensor_msgs/msg/Imu', IMU,
            _columns(col['body_acceleration'][i], col['body_angular_velocity'][i]), build_imu,
            unit='m/s^2, rad/s'))
        for k in range(layout.n_axles):
            for s, side in enumerate(('left', 'right')):
                topics.append(Topic(
                    f'wheel_rail/car{i + 1:02d}/axle{k + 1}/{side}',
                    'geometry_msgs/msg/WrenchStamped', WRENCH,
                    _columns(col['wheel_rail'][i, k, s], pad3), build_wrench_stamped, unit='N'))
    for k in range(layout.n_spans):
        topics.append(Topic(f'bridge/span{k + 1:02d}/midspan',
                            'geometry_msgs/msg/Vector3Stamped', VECTOR3,
                            _columns(col['midspan'][k]), build_vector3_stamped, unit='m'))
    for s in range(layout.n_supports):
        for side_index, side in enumerate(('left', 'right')):
            topics.append(Topic(
                f'bearings/pier{s + 1:02d}/{side}', 'geometry_msgs/msg/WrenchStamped', WRENCH,
                _columns(col['bearings'][s, side_index], pad3), build_wrench_stamped,
                unit='N'))
    for j, pier in enumerate(layout.piers):
        topics.append(Topic(f'piers/pier{pier:02d}/top', 'geometry_msgs/msg/Vector3Stamped',
                            VECTOR3, _columns(col['pier_tops'][j]), build_vector3_stamped,
                            unit='m'))
    index = 0
    for pier, n_piles in layout.piles:
        for m in range(n_piles):
            base = f'piles/pier{pier:02d}/pile{m + 1:02d}'
            topics.append(Topic(f'{base}/displacement', 'geometry_msgs/msg/Vector3Stamped',
                                VECTOR3, _columns(col['pile_displacement'][index]),
                                build_vector3_stamped, unit='m'))
            topics.append(Topic(f'{base}/imu', 'sensor_msgs/msg/Imu', IMU,
                                _columns(col['pile_acceleration'][index],
                                         col['pile_rotation_rate'][index]), build_imu,
                                unit='m/s^2, rad/s'))
            index += 1
    if layout.soil_points:
        topics.append(Topic('soil/points', 'sensor_msgs/msg/PointCloud2', (),
                            _columns(col['soil_points']), build_point_cloud,
                            unit='m, m, m/s^2, m/s'))
    for j, name in enumerate(layout.observers):
        topics.append(Topic(f'observers/{name}', 'geometry_msgs/msg/Vector3Stamped', VECTOR3,
                            _columns(col['observers'][j]), build_vector3_stamped, unit='m'))
    return topics


class PeakTracker:
    """
    Running minimum and maximum of every topic's numeric fields.

    The extremes are kept per column of the frames' flat rows
    (:attr:`~ttb_sim.sim.Frame.row`): one ``minimum`` and one ``maximum`` per
    frame (or per block of frames) over every value, read per topic at the end.
    A value that is ever NaN stays NaN, and its topic is left out of the summary.
    """

    def __init__(self, topics: Sequence[Topic], namespace: str = NAMESPACE) -> None:
        self._topics = [t for t in topics if t.fields]
        self._names = [t.full_name(namespace) for t in self._topics]
        self._lo: np.ndarray | None = None
        self._hi: np.ndarray | None = None

    def update(self, frame: Frame) -> None:
        """Fold one frame into the running extremes."""
        row = frame.row
        if self._lo is None or self._hi is None:
            self._lo, self._hi = row.copy(), row.copy()
            return
        np.minimum(self._lo, row, out=self._lo)
        np.maximum(self._hi, row, out=self._hi)

    def update_rows(self, rows: np.ndarray) -> None:
        """Fold the flat rows ``(frames, width)`` of some frames into the running extremes."""
        if not len(rows):
            return
        lo, hi = np.min(rows, axis=0), np.max(rows, axis=0)
        if self._lo is None or self._hi is None:
            self._lo, self._hi = lo, hi
            return
        np.minimum(self._lo, lo, out=self._lo)
        np.maximum(self._hi, hi, out=self._hi)

    def summary(self) -> dict[str, dict[str, dict[str, float]]]:
        """Return {topic: {field: {min, max, abs_max}}} (fields never seen are omitted)."""
        out: dict[str, dict[str, dict[str, float]]] = {}
        if self._lo is None or self._hi is None:
            return out
        for name, topic in zip(self._names, self._topics):
            lo, hi = self._lo[topic.index], self._hi[topic.index]
            if not np.all(np.isfinite(lo)):
                continue
            out[name] = {f: {'min': float(a), 'max': float(b),
                             'abs_max': float(max(abs(a), abs(b)))}
                         for f, a, b in zip(topic.fields, lo, hi)}
        return out
