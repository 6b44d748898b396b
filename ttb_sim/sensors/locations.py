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
Where a sensor's truth is: its location turned into columns of the frames' flat rows.

The columns index :attr:`~ttb_sim.sim.frames.Frame.row`: the frame's own fields for
sensors on piles, pier tops, cars, wheels and ground points, its ``probes`` for
sensors on beam lines and its ``pile_strain`` for strain gauges on piles
(:mod:`ttb_sim.config.sensor_places`).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ttb_sim.config.sensor_places import (ALLOWED_PLACES, AXIS, gauge_of, GaugeRequest,
                                          GROUND_SLOTS, Location, parse_location,
                                          ProbeRequest, request_of)
from ttb_sim.config.sensor_records import SensorConfig
from ttb_sim.errors import ScenarioError
from ttb_sim.sim import Layout, SOIL_VALUES

__all__ = ['truth_columns']


def truth_columns(config: SensorConfig, layout: Layout, requests: Sequence[ProbeRequest],
                  gauges: Sequence[GaugeRequest] = ()
                  ) -> tuple[np.ndarray, np.ndarray | None]:
    """
    Return the frame-row columns of a sensor's truth per axis, and of its ``relative_to``.

    Raises
    ------
    ScenarioError
        Naming the sensor when its location does not exist in the model (no such car,
        axle, piled pier, pile or ground point).

    """
    axes = [AXIS[a] for a in config.measured_axes]
    at = _columns(config, config.at, layout, requests, gauges)[axes]
    if not config.relative_to:
        return at, None
    return at, _columns(config, config.relative_to, layout, requests, gauges)[axes]


def _columns(config: SensorConfig, text: str, layout: Layout,
             requests: Sequence[ProbeRequest], gauges: Sequence[GaugeRequest]) -> np.ndarray:
    """Return the three columns (x, y, z) of one location's quantity."""
    col = layout.columns()
    location = parse_location(text, config.name)
    what = f'sensor {config.name}: at {text!r}'
    if location.kind == 'line':
        request = request_of(config, text)
        assert request is not None   # a line location always has its probe
        return col['probes'][list(requests).index(request)]
    numbers = [int(p) for p in location.parts if p.isdigit()]
    if location.kind == 'car':
        return col['body_acceleration'][_index(what, numbers[0], layout.n_bodies, 'car')]
    if location.kind == 'wheel':
        body = _index(what, numbers[0], layout.n_bodies, 'car')
        axle = _index(what, numbers[1], layout.n_axles, 'axle')
        return col['wheel_rail'][body, axle, 0 if location.parts[2] == 'left' else 1]
    if location.kind == 'pier_top':
        if numbers[0] not in layout.piers:
            raise ScenarioError(f'{what}: pier {numbers[0]} reports no top; piers with a top: '
                                f'{list(layout.piers)}')
        return col[ALLOWED_PLACES[config.type]['pier_top']][layout.piers.index(numbers[0])]
    if location.kind == 'pile':
        index = _pile(what, numbers, layout)
        gauge = gauge_of(config) if text == config.at else None
        if gauge is not None:
            return col['pile_strain'][list(gauges).index(gauge)]
        return col[ALLOWED_PLACES[config.type]['pile']][index]
    return _ground(config, what, location, layout)


def _index(what: str, number: int, count: int, name: str) -> int:
    if count == 0:
        raise ScenarioError(f'{what}: the model has no {name}s (moving forces have no car '
                            'bodies or wheels)')
    if not 1 <= number <= count:
        raise ScenarioError(f'{what}: {name} {number} does not exist; the model has '
                            f'{count} (1 to {count})')
    return number - 1


def _pile(what: str, numbers: list[int], layout: Layout) -> int:
    first = 0
    for pier, n_piles in layout.piles:
        if pier == numbers[0]:
            return first + _index(what, numbers[1], n_piles, 'pile')
        first += n_piles
    raise ScenarioError(f'{what}: pier {numbers[0]} is not piled; piled piers: '
                        f'{[p for p, _ in layout.piles]}')


def _ground(config: SensorConfig, what: str, location: Location, layout: Layout) -> np.ndarray:
    name = f'pier{int(location.parts[0]):02d}/{location.parts[1]}'
    if name not in layout.soil_point_names:
        shown = ', '.join(layout.soil_point_names[:6]) or 'none'
        raise ScenarioError(f'{what}: no ground point {name!r}; the model has {shown}'
                            f'{" ..." if len(layout.soil_point_names) > 6 else ""}')
    first = GROUND_SLOTS[ALLOWED_PLACES[config.type]['ground']]
    row = layout.columns()['soil_points'].reshape(-1, SOIL_VALUES)
    return row[layout.soil_point_names.index(name), first:first + 3]
