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
Reading bags back: a rosbag2 directory (MCAP or SQLite 3) -> numpy arrays per topic.

:func:`read_bag` reads any bag of ours, written by ``ttb-sim run`` or recorded
from the node with ``ros2 bag record``, into one :class:`TopicArrays` per topic:
the ``header.stamp`` of every message and the time the bag received it (both in
seconds, and exactly in integer nanoseconds), and the message's numeric fields
flattened to arrays whose first axis is the message index.

Flattening, per message type (``components`` names the last axis of each field):

``geometry_msgs/msg/Vector3Stamped``
    ``vector`` (n, 3): x, y, z.
``geometry_msgs/msg/WrenchStamped``
    ``force``, ``torque`` (n, 3): x, y, z.
``sensor_msgs/msg/Imu``
    ``linear_acceleration``, ``angular_velocity`` (n, 3): x, y, z;
    ``orientation`` (n, 4): x, y, z, w.
``nav_msgs/msg/Odometry``
    ``position``, ``linear_velocity``, ``angular_velocity`` (n, 3): x, y, z;
    ``orientation`` (n, 4): x, y, z, w.
``rosgraph_msgs/msg/Clock``
    no fields; the stamp is the clock value.
``sensor_msgs/msg/PointCloud2``
    ``points`` (n, points, fields): one column per scalar point field (x, y, z,
    ux, ...) in the message's order, in the fields' common dtype (float32 for
    ours); organised clouds are flattened row by row; a message with fewer
    points than the largest is padded with NaN.
``diagnostic_msgs/msg/DiagnosticArray``
    ``{status name}/level`` (n,) and ``{status name}/{key}`` (n,) for every key
    whose value reads as a number (NaN where absent or not numeric); text
    values are dropped.

Other message types (``visualization_msgs/msg/MarkerArray``, ``/rosout``,
``/parameter_events``, ...) are skipped when reading every topic, and refused
when asked for by name.

Messages are decoded without a Python call per message where the bytes allow:
messages of a topic whose strings and sequences have the same lengths share one
CDR layout, so each field is one strided column of a ``(messages, bytes)``
array (:mod:`ttb_sim.io.cdr`: the layout is computed from the type definitions
of the rosbags type store for ROS 2 Jazzy). Any other message (another layout,
big-endian CDR) is deserialised by rosbags one by one, with the same result.
This module flattens the decoded fields per message type.
"""

from __future__ import annotations

from collections import defaultdict
from contextlib import contextmanager
from dataclasses import dataclass
import logging
from pathlib import Path
import struct
from typing import Any, Iterable, Iterator, Mapping, Sequence, TYPE_CHECKING

import numpy as np
from rosbags.rosbag2 import Reader, ReaderError
from rosbags.serde import SerdeError
from ttb_sim.errors import BagError
from ttb_sim.io.bag_checks import check_bag_path, one_line, unclosed_file, unreadable
from ttb_sim.io.cdr import Group, groups, typestore

if TYPE_CHECKING:
    from ttb_sim.io.salvage import Salvage

log = logging.getLogger(__name__)

XYZ = ('x', 'y', 'z')
XYZW = ('x', 'y', 'z', 'w')

_FLAT: dict[str, dict[str, str]] = {
    'geometry_msgs/msg/Vector3Stamped': {'vector': 'vector'},
    'geometry_msgs/msg/WrenchStamped': {'force': 'wrench.force', 'torque': 'wrench.torque'},
    'sensor_msgs/msg/Imu': {'linear_acceleration': 'linear_acceleration',
                            'angular_velocity': 'angular_velocity',
                            'orientation': 'orientation'},
    'nav_msgs/msg/Odometry': {'position': 'pose.pose.position',
                              'orientation': 'pose.pose.orientation',
                              'linear_velocity': 'twist.twist.linear',
                              'angular_velocity': 'twist.twist.angular'},
    'rosgraph_msgs/msg/Clock': {},
}
"""Fixed-size types: output field -> message path of a Vector3, Point or Quaternion."""

POINT_CLOUD = 'sensor_msgs/msg/PointCloud2'
DIAGNOSTICS = 'diagnostic_msgs/msg/DiagnosticArray'

SUPPORTED_TYPES = (*_FLAT, POINT_CLOUD, DIAGNOSTICS)
"""Message types :func:`read_bag` flattens."""

_POINT_FIELD_TYPES = {1: 'i1', 2: 'u1', 3: 'i2', 4: 'u2', 5: 'i4', 6: 'u4', 7: 'f4', 8: 'f8'}
"""``sensor_msgs/msg/PointField`` datatype -> numpy dtype (without byte order)."""


@dataclass(frozen=True)
class TopicArrays:
    """
    The messages of one topic as arrays, in the order the bag received them.

    Attributes
    ----------
    topic : str
        Absolute topic name.
    msgtype : str
        ROS message type, e.g. ``'geometry_msgs/msg/Vector3Stamped'``.
    stamp_ns : numpy.ndarray
        (n,) int64, ``header.stamp`` of each message in nanoseconds (for
        ``rosgraph_msgs/msg/Clock``: the clock value). Simulation time for the
        topics of ttb_sim.
    receive_ns : numpy.ndarray
        (n,) int64, the time the bag recorded each message (ns): simulation time
        for ``ttb-sim run``, the recorder's clock for ``ros2 bag record``.
    fields : mapping of str to numpy.ndarray
        Flattened message fields, first axis the message (see the module
        documentation for each type); SI units as published.
    components : mapping of str to tuple of str
        For each field, the names along its last axis (``('x', 'y', 'z')``, or
        the point field names of a point cloud); ``()`` for (n,) fields.

    """

    topic: str
    msgtype: str
    stamp_ns: np.ndarray
    receive_ns: np.ndarray
    fields: Mapping[str, np.ndarray]
    components: Mapping[str, tuple[str, ...]]

    @property
    def stamp(self) -> np.ndarray:
        """``header.stamp`` in seconds, (n,) float64."""
        return self.stamp_ns * 1e-9

    @property
    def receive_time(self) -> np.ndarray:
        """Receive (bag log) time in seconds, (n,) float64."""
        return self.receive_ns * 1e-9

    def __len__(self) -> int:
        """Return the number of messages."""
        return len(self.stamp_ns)

    def __getitem__(self, name: str) -> np.ndarray:
        """Return one field, e.g. ``arrays['vector'][:, 2]`` for z."""
        try:
            return self.fields[name]
        except KeyError:
            msg = f'{self.topic} ({self.msgtype}) has no field {name!r}; fields: ' \
                  f'{", ".join(self.fields) or "none"}'
            raise KeyError(msg) from None

    def component(self, name: str, component: str) -> np.ndarray:
        """Return one component of a field as (n,) or (n, points), e.g. ``('vector', 'z')``."""
        names = self.components[name]
        if component not in names:
            msg = f'{self.topic}: field {name!r} has components {", ".join(names)}, ' \
                  f'not {component!r}'
            raise KeyError(msg)
        return self[name][..., names.index(component)]


def bag_topics(path: str | Path) -> dict[str, str]:
    """
    List the topics of a bag and their message types.

    Parameters
    ----------
    path : path-like
        Bag directory (with ``metadata.yaml``) or storage file.

    Returns
    -------
    dict
        Topic name -> message type, in the bag's order.

    Raises
    ------
    BagError
        If ``path`` is not a readable bag.

    """
    with _open(Path(path)) as reader:
        return {c.topic: c.msgtype for c in reader.connections}


def read_bag(path: str | Path, topics: Iterable[str] | None = None) -> dict[str, TopicArrays]:
    """
    Read a bag into arrays per topic.

    Parameters
    ----------
    path : path-like
        Bag directory (with ``metadata.yaml``) or a storage file (``.mcap``,
        ``.db3``).
    topics : iterable of str, optional
        Topics to read. An absolute name (``/ttb_sim/bridge/span01/midspan``)
        must match exactly; a relative one (``bridge/span01/midspan``) matches
        the topic of that name under any namespace, if there is exactly one.
        Default: every topic of a supported type (others are skipped).

    Returns
    -------
    dict
        Absolute topic name -> :class:`TopicArrays`, in the bag's topic order.

    Raises
    ------
    BagError
        If ``path`` is not a bag, the bag is truncated or corrupt (e.g. from a
        killed recording), a requested topic is missing or ambiguous, or its
        type is not one of :data:`SUPPORTED_TYPES`.

    """
    path = Path(path)
    with _open(path) as reader:
        available: dict[str, str] = {}
        for conn in reader.connections:
            previous = available.setdefault(conn.topic, conn.msgtype)
            if previous != conn.msgtype:
                msg = f'bag {str(path)!r}: topic {conn.topic} has two types, {previous} ' \
                      f'and {conn.msgtype}'
                raise BagError(msg)
        wanted = _select(path, available, topics)
        raw: dict[str, list[bytes]] = defaultdict(list)
        received: dict[str, list[int]] = defaultdict(list)
        connections = [c for c in reader.connections if c.topic in wanted]
        try:   # (an empty connection list would mean every connection to rosbags)
            for conn, timestamp, data in (reader.messages(connections=connections)
                                          if connections else ()):
                raw[conn.topic].append(data)
                received[conn.topic].append(timestamp)
        except CORRUPT as exc:   # a record cut short, or a length field gone wrong
            raise BagError(unreadable(path, exc)) from None
    store = typestore()
    out: dict[str, TopicArrays] = {}
    for topic in wanted:
        msgtype = available[topic]
        try:
            stamp_ns, fields, components = _decode(store, msgtype, raw[topic])
        except (SerdeError, *CORRUPT, ValueError) as exc:
            msg = f'bag {str(path)!r} is corrupt: the messages of {topic} ({msgtype}) cannot ' \
                  f'be decoded ({type(exc).__name__}: {one_line(str(exc))})'
            raise BagError(msg) from None
        out[topic] = TopicArrays(topic, msgtype, stamp_ns,
                                 np.asarray(received[topic], dtype=np.int64), fields,
                                 components)
        log.debug('%s: %d messages of %s', topic, len(stamp_ns), msgtype)
    return out


CORRUPT = (ReaderError, OverflowError, EOFError, IndexError, struct.error, MemoryError,
           UnicodeDecodeError)
"""What reading a damaged storage file raises (rosbags checks most, not every length field)."""


# -- opening and selecting --------------------------------------------------------------

@contextmanager
def _open(path: Path) -> Iterator[Reader | Salvage]:
    """
    Open a bag with rosbags, translating its errors to one-line :class:`BagError`.

    A bag whose recording did not finish (:func:`~ttb_sim.io.bag_checks.unclosed_file`)
    is read by :func:`~ttb_sim.io.salvage.salvage` instead, with a warning.
    """
    check_bag_path(path)
    unclosed = unclosed_file(path)
    if unclosed is not None:
        yield _salvage(path, unclosed)
        return
    try:
        reader = Reader(path)
        reader.open()
    except CORRUPT as exc:
        raise BagError(unreadable(path, exc)) from None
    except (OSError, ValueError, KeyError) as exc:
        msg = f'bag {str(path)!r} cannot be read: {one_line(str(exc))}'
        raise BagError(msg) from None
    try:
        yield reader
    finally:
        reader.close()


def _salvage(path: Path, file: Path) -> Salvage:
    """Read an unclosed bag up to its last complete chunk or commit; warn in one line."""
    from ttb_sim.io.salvage import salvage
    try:
        found = salvage(file)
    except BagError as exc:
        raise BagError(f'bag {str(path)!r}: the recording did not finish (a killed run?), '
                       f'and {exc}') from None
    unit = 'chunk' if found.storage == 'mcap' else 'commit'
    state = 'has no metadata.yaml' if found.closed else \
        f'was not closed (a killed recording?): read up to its last complete {unit}'
    log.warning('bag %s %s: %s; `ttb-sim recover %s` writes a closed copy', path, state,
                found.describe(), path)
    return found


def _select(path: Path, available: Mapping[str, str],
            topics: Iterable[str] | None) -> list[str]:
    """Resolve the requested topic names (bag order), or pick every supported topic."""
    if topics is None:
        skipped = [t for t, m in available.items() if m not in SUPPORTED_TYPES]
        if skipped:
            log.info('skipping topics of unsupported types: %s', ', '.join(skipped))
        return [t for t, m in available.items() if m in SUPPORTED_TYPES]
    chosen: set[str] = set()
    for name in topics:
        if name.startswith('/'):
            matches = [name] if name in available else []
        else:
            matches = [t for t in available if t.endswith('/' + name)]
        if len(matches) != 1:
            what = 'is ambiguous in' if matches else 'is not in'
            msg = f'topic {name!r} {what} bag {str(path)!r}; topics: ' \
                  f'{", ".join(matches or available) or "none"}'
            raise BagError(msg)
        topic = matches[0]
        if available[topic] not in SUPPORTED_TYPES:
            msg = f'topic {topic} has type {available[topic]}, which read_bag does not ' \
                  f'flatten; supported: {", ".join(SUPPORTED_TYPES)}'
            raise BagError(msg)
        chosen.add(topic)
    return [t for t in available if t in chosen]


# -- flattening -----------------------------------------------------------------------------

Decoded = tuple[np.ndarray, dict[str, np.ndarray], dict[str, tuple[str, ...]]]


def _decode(store: Any, msgtype: str, raws: Sequence[bytes]) -> Decoded:
    """Flatten a topic's raw messages: (stamp_ns, fields, components)."""
    if msgtype == DIAGNOSTICS:
        return _diagnostics([store.deserialize_cdr(d, msgtype) for d in raws])
    n = len(raws)
    stamp_path = 'clock' if msgtype == 'rosgraph_msgs/msg/Clock' else 'header.stamp'
    stamp_ns = np.zeros(n, dtype=np.int64)
    fields: dict[str, np.ndarray] = {}
    components: dict[str, tuple[str, ...]] = {}
    clouds: list[tuple[np.ndarray, np.ndarray, tuple[str, ...]]] = []
    for group in groups(store, msgtype, raws):
        stamp_ns[group.index] = (group.get(f'{stamp_path}.sec').astype(np.int64) * 1_000_000_000
                                 + group.get(f'{stamp_path}.nanosec').astype(np.int64))
        if msgtype == POINT_CLOUD:
            names, points = _points(group)
            clouds.append((group.index, points, names))
            continue
        for name, path in _FLAT[msgtype].items():
            axes = XYZW if name == 'orientation' else XYZ
            values = np.stack([group.get(f'{path}.{a}') for a in axes], axis=-1)
            fields.setdefault(name, np.empty((n, len(axes)), dtype=values.dtype))
            fields[name][group.index] = values
            components[name] = axes
    if msgtype == POINT_CLOUD:
        fields['points'], components['points'] = _stack_clouds(n, clouds)
    for name in _FLAT.get(msgtype, {}):
        if name not in fields:   # a topic without messages
            components[name] = XYZW if name == 'orientation' else XYZ
            fields[name] = np.zeros((0, len(components[name])))
    return stamp_ns, fields, components


def _points(group: Group) -> tuple[tuple[str, ...], np.ndarray]:
    """Return the field names and (messages, points, fields) values of a cloud group."""
    sample = group.sample()
    n_points = int(sample.width) * int(sample.height)
    step = int(sample.point_step)
    order = '>' if sample.is_bigendian else '<'
    data = group.get('data')
    n = len(group.index)
    if data.shape[1] < n_points * step:
        raise BagError(f'point cloud with {n_points} points of {step} bytes carries only '
                       f'{data.shape[1]} bytes')
    raw = data[:, :n_points * step].reshape(n, n_points, step)
    names, columns = [], []
    for f in sample.fields:
        dtype = _POINT_FIELD_TYPES.get(int(f.datatype))
        if dtype is None or int(f.count) != 1:
            log.debug('point field %r (datatype %d, count %d) skipped', f.name, f.datatype,
                      f.count)
            continue
        size = int(dtype[1])
        cells = np.ascontiguousarray(raw[:, :, f.offset:f.offset + size])
        columns.append(cells.view(order + dtype)[..., 0])
        names.append(str(f.name))
    if not columns:
        return (), np.zeros((n, n_points, 0))
    return tuple(names), np.stack(columns, axis=-1)


def _stack_clouds(n: int, clouds: list[tuple[np.ndarray, np.ndarray, tuple[str, ...]]]
                  ) -> tuple[np.ndarray, tuple[str, ...]]:
    """Assemble the groups of a point-cloud topic, padding shorter clouds with NaN."""
    if not clouds:
        return np.zeros((0, 0, 0)), ()
    names = clouds[0][2]
    for _, _, other in clouds:
        if other != names:
            raise BagError(f'point clouds of one topic have different fields: {names} and '
                           f'{other}')
    n_points = max(points.shape[1] for _, points, _ in clouds)
    dtype = np.result_type(*(points.dtype for _, points, _ in clouds))
    if any(points.shape[1] != n_points for _, points, _ in clouds):
        dtype = np.result_type(dtype, np.float32)
    out = np.full((n, n_points, len(names)), np.nan if dtype.kind == 'f' else 0, dtype=dtype)
    for index, points, _ in clouds:
        out[index, :points.shape[1]] = points
    return out, names


def _diagnostics(messages: list[Any]) -> Decoded:
    """Flatten diagnostic arrays: level and numeric values per status name."""
    n = len(messages)
    stamp_ns = np.array([m.header.stamp.sec * 1_000_000_000 + m.header.stamp.nanosec
                         for m in messages], dtype=np.int64)
    fields: dict[str, np.ndarray] = {}
    for i, msg in enumerate(messages):
        for status in msg.status:
            level = status.level
            level = level[0] if isinstance(level, (bytes, bytearray)) else int(level)
            _column(fields, f'{status.name}/level', n)[i] = level
            for kv in status.values:
                number = _number(kv.value)
                if number is not None:
                    _column(fields, f'{status.name}/{kv.key}', n)[i] = number
    return stamp_ns, fields, {name: () for name in fields}


def _column(fields: dict[str, np.ndarray], name: str, n: int) -> np.ndarray:
    if name not in fields:
        fields[name] = np.full(n, np.nan)
    return fields[name]


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None
