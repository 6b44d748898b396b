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
Frames: what the stepping core emits at each output tick (SI units, track axes).

Every frame of a run also reads as one flat float64 row (:attr:`Frame.row`): a
zero, then every field of the frame in :data:`ROW_FIELDS` order, each raveled
in C order. :meth:`Layout.columns` says where each value lands in that row, so
the writers gather any topic's values of many frames with one index, and fold
extremes over all values at once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

ROW_FIELDS = ('head_position', 'speed', 'midspan', 'bearings', 'body_acceleration',
              'body_angular_velocity', 'wheel_rail', 'observers', 'pile_displacement',
              'pile_acceleration', 'pile_rotation_rate', 'soil_points', 'pier_tops', 'probes',
              'pier_top_acceleration', 'pile_strain')
"""The fields of a :class:`Frame` in the order of :attr:`Frame.row` (after its leading zero)."""
SOIL_VALUES = 12
"""Values per ground point: x, y, z, displacement, acceleration (the contract's nine), velocity."""
ZERO_COLUMN = 0
"""The column of :attr:`Frame.row` that always holds 0.0 (for values a topic pads with)."""


@dataclass(frozen=True)
class Layout:
    """Sizes of the things a run reports, known before the first frame."""

    n_spans: int
    n_supports: int
    n_bodies: int
    """Number of car bodies with an IMU (quarter cars: one per axle)."""
    n_axles: int = 1
    """Axles per body with wheel-rail forces (4 for multibody cars)."""
    observers: tuple[str, ...] = ()
    """Names of the displacement observers."""
    piles: tuple[tuple[int, int], ...] = ()
    """(pier number, 1-based; number of piles) of every piled pier, in frame order."""
    soil_points: int = 0
    """Number of ground observation points (all piled piers together)."""
    train: bool = True
    """Whether a train runs (False for a substructure alone: no odometry)."""
    piers: tuple[int, ...] = ()
    """Pier numbers (1-based supports) whose top displacement is reported, in frame order."""
    soil_point_names: tuple[str, ...] = ()
    """Name of each ground point in frame order, ``pierNN/<name>`` (``line_01``, ``val_1``,
    ``user_01``, ``grid_RR_CC``): written to ``summary.json`` so analysis can tell them apart."""
    probes: int = 0
    """Number of beam-line probes the sensors read (:func:`ttb_sim.sensors.probe_requests`)."""
    pile_gauges: int = 0
    """Number of pile strain gauges the sensors read
    (:func:`~ttb_sim.config.sensor_places.gauge_requests`)."""

    @property
    def n_piles(self) -> int:
        """Total number of piles over all piled piers."""
        return sum(n for _, n in self.piles)

    def shapes(self) -> dict[str, tuple[int, ...]]:
        """Return the shape of every field of a frame of this layout, by :data:`ROW_FIELDS`."""
        bodies, piles = (self.n_bodies, 3), (self.n_piles, 3)
        return {'head_position': (), 'speed': (), 'midspan': (self.n_spans, 3),
                'bearings': (self.n_supports, 2, 3), 'body_acceleration': bodies,
                'body_angular_velocity': bodies,
                'wheel_rail': (self.n_bodies, self.n_axles, 2, 3),
                'observers': (len(self.observers), 3), 'pile_displacement': piles,
                'pile_acceleration': piles, 'pile_rotation_rate': piles,
                'soil_points': (self.soil_points, SOIL_VALUES),
                'pier_tops': (len(self.piers), 3), 'probes': (self.probes, 3),
                'pier_top_acceleration': (len(self.piers), 3),
                'pile_strain': (self.pile_gauges, 3)}

    @property
    def row_width(self) -> int:
        """Return the number of values in :attr:`Frame.row` of a frame of this layout."""
        return 1 + sum(int(np.prod(s, dtype=np.int64)) for s in self.shapes().values())

    def columns(self) -> dict[str, np.ndarray]:
        """
        Return the column of :attr:`Frame.row` of every value of every field.

        Returns
        -------
        dict of str to numpy.ndarray
            Per field of :data:`ROW_FIELDS`, integer columns shaped like the field
            (``columns(...)['wheel_rail'][body, axle, side]`` are the 3 columns of
            that wheel's force); and ``'zero'``: the column that always holds 0.0.

        """
        out: dict[str, np.ndarray] = {'zero': np.array(ZERO_COLUMN)}
        start = ZERO_COLUMN + 1
        for name, shape in self.shapes().items():
            size = int(np.prod(shape, dtype=np.int64))
            out[name] = np.arange(start, start + size).reshape(shape)
            start += size
        return out

    def check(self, frame: Frame) -> None:
        """
        Raise ValueError unless every field of ``frame`` has this layout's shape.

        Raises
        ------
        ValueError
            Naming the first field whose shape differs.

        """
        for name, shape in self.shapes().items():
            got = np.shape(getattr(frame, name))
            if got != shape:
                raise ValueError(f'frame field {name} has shape {got}; the layout says {shape}')


@dataclass(frozen=True)
class Frame:
    """
    The observable state at one output tick.

    Attributes
    ----------
    step : solver step index
    time : simulation time (s)
    head_position : position of the train head along the track (m)
    speed : train speed (m/s)
    midspan : (n_spans, 3) girder mid-span displacement (m), z up
    bearings : (n_supports, 2, 3) bearing forces on each support, left/right (N)
    body_acceleration : (n_bodies, 3) car-body acceleration, gravity excluded (m/s^2)
    body_angular_velocity : (n_bodies, 3) car-body angular velocity (rad/s)
    wheel_rail : (n_bodies, n_axles, 2, 3) force of the rail on each wheel, left/right (N)
    observers : (n_observers, 3) displacement at each observer (m)
    pile_displacement : (n_piles, 3) pile-head displacement, area-weighted mean over the
        head (m), piles in :attr:`Layout.piles` order
    pile_acceleration : (n_piles, 3) pile-head acceleration (m/s^2)
    pile_rotation_rate : (n_piles, 3) pile-head rotation rate (rad/s)
    soil_points : (n_points, 12) ground points: x, y, z (m), displacement (m),
        acceleration (m/s^2), velocity (m/s)
    pier_tops : (n_piers, 3) displacement of each pier top, the bearing seat (m), piers
        in :attr:`Layout.piers` order
    probes : (n_probes, 3) the beam-line quantities the sensors read, in
        :func:`~ttb_sim.sensors.probe_requests` order (SI units)
    pier_top_acceleration : (n_piers, 3) acceleration of each pier top (m/s^2), the
        integrated state's (not a difference of displacements), piers as ``pier_tops``
    pile_strain : (n_gauges, 3) axial strain of the piles at the sensors' gauges (tension
        positive), then two zeros, in
        :func:`~ttb_sim.config.sensor_places.gauge_requests` order

    """

    step: int
    time: float
    head_position: float
    speed: float
    midspan: np.ndarray
    bearings: np.ndarray
    body_acceleration: np.ndarray
    body_angular_velocity: np.ndarray
    wheel_rail: np.ndarray
    observers: np.ndarray
    pile_displacement: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pile_acceleration: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pile_rotation_rate: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    soil_points: np.ndarray = field(default_factory=lambda: np.zeros((0, SOIL_VALUES)))
    pier_tops: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    probes: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pier_top_acceleration: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pile_strain: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    @cached_property
    def row(self) -> np.ndarray:
        """
        Return every value of the frame in one flat float64 array, computed once.

        ``row[0]`` is 0.0 (:data:`ZERO_COLUMN`); then the fields of :data:`ROW_FIELDS`,
        each raveled in C order; :meth:`Layout.columns` maps them.
        """
        return np.concatenate(   # in ROW_FIELDS order; axis None ravels each
            ((0.0, self.head_position, self.speed), self.midspan, self.bearings,
             self.body_acceleration, self.body_angular_velocity, self.wheel_rail,
             self.observers, self.pile_displacement, self.pile_acceleration,
             self.pile_rotation_rate, self.soil_points, self.pier_tops, self.probes,
             self.pier_top_acceleration, self.pile_strain), axis=None,
            dtype=np.float64)

    @property
    def stamp_ns(self) -> int:
        """Simulation time in integer nanoseconds (message stamps)."""
        return int(round(self.time * 1e9))
