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
The places a sensor may be, parsed: locations of ``at`` and ``relative_to``, and the probes.

Sensors on a pile head, a pier top, a car body, a wheel or a ground point read
values every frame holds already; pile strain gauges read the pile's axial strain
at their depth, which the runners evaluate for the gauges asked for
(:func:`gauge_requests`). Sensors on a beam line (girder, rails, slab,
base plates) read *probes*: rows of the line's element interpolation applied to
the structure's displacement, velocity or acceleration, or to its derivative
along the beam (rotation; fibre strain u' - z w'' - y v'' at the fibre (y, z)),
which the stepping core evaluates at every frame (:func:`probe_requests` gives
them in frame order). Nothing here needs the model.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math
from typing import Any, Sequence

from ttb_sim.config.sensor_records import LOCATION_FORMS, SensorConfig, SensorError

__all__ = ['ALLOWED_PLACES', 'check_places', 'gauge_requests', 'GaugeRequest', 'Location',
           'on_girders', 'parse_location', 'probe_requests', 'ProbeRequest']

AXIS = {'x': 0, 'y': 1, 'z': 2}

ALLOWED_PLACES = {
    'accelerometer': {'line': 'acceleration', 'car': 'body_acceleration',
                      'pile': 'pile_acceleration', 'pier_top': 'pier_top_acceleration',
                      'ground': 'acceleration'},
    'displacement': {'line': 'displacement', 'pile': 'pile_displacement',
                     'pier_top': 'pier_tops', 'ground': 'displacement'},
    'inclinometer': {'line': 'rotation'},
    'geophone': {'line': 'velocity', 'ground': 'velocity'},
    'strain': {'line': 'strain', 'pile': 'pile_strain'},
    'wheel_force': {'wheel': 'wheel_rail'},
}
"""Per sensor type: the kinds of location it may be at, and what it reads there."""

GROUND_SLOTS = {'displacement': 3, 'acceleration': 6, 'velocity': 9}
"""First of the three columns of each quantity among a ground point's values."""


@dataclass(frozen=True)
class Location:
    """A parsed ``at`` (or ``relative_to``): its kind and the numbers or names it holds."""

    kind: str
    parts: tuple[str, ...]

    @property
    def x(self) -> float:
        """Track position of a beam-line point (m)."""
        return float(self.parts[1])

    @property
    def depth(self) -> float:
        """Depth of a pile point below the pile head (m; 0: at the head)."""
        return float(self.parts[2]) if self.kind == 'pile' and self.parts[2] else 0.0


@dataclass(frozen=True)
class ProbeRequest:
    """A beam-line quantity the stepping core evaluates at every frame (three values)."""

    component: str
    """'girder', 'rail_left', 'rail_right', 'slab' or 'base'."""
    x: float
    """Track position (m)."""
    quantity: str
    """'displacement', 'velocity', 'acceleration' (x, y, z), 'rotation' (about x, y, z) or
    'strain' (the fibre strain, then two zeros)."""
    fibre: tuple[float, float] = (0.0, 0.0)
    """The (y, z) offset of the point from the beam axis (m): the strain gauge's fibre."""


@dataclass(frozen=True)
class GaugeRequest:
    """A pile strain gauge the runner evaluates at every frame: the pile's axial strain."""

    pier: int
    """Pier number (1-based support)."""
    pile: int
    """Pile number in the group (1-based)."""
    depth: float
    """Depth below the pile head (m)."""


def parse_location(text: str, what: str) -> Location:
    """
    Parse a location string (``girder@208``, ``car03``, ``pier07/pile05`` ...).

    Raises
    ------
    SensorError
        Naming ``what`` and the forms allowed.

    """
    for kind, form in LOCATION_FORMS.items():
        match = form.match(text.strip())
        if match:
            location = Location(kind, tuple(g or '' for g in match.groups()))
            if kind in ('line', 'span'):
                _number(what, text, location.parts[1], 'position')
            if kind == 'pile' and location.parts[2] and not _number(
                    what, text, location.parts[2], 'depth') >= 0.0:
                raise SensorError(f'{what} = {text!r}: depth {location.parts[2]!r} is above '
                                  'the pile head; allowed: 0 to the pile length (m below it)')
            return location
    raise SensorError(f"{what} = {text!r}: allowed forms are 'spanNN/x=X' (X m from the "
                      "span's left support), 'girder@x' (x along the track; or rail_left, "
                      "rail_right, slab, base), 'carNN', 'carNN/axleK/left|right', "
                      "'pierNN/pileMM', 'pierNN/pileMM/depth=D' (strain), 'pierNN/top', "
                      "'ground/pierNN/<point>'")


def _number(what: str, text: str, part: str, name: str) -> float:
    """Return ``part`` as a finite float, or raise naming the location."""
    try:
        value = float(part)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise SensorError(f'{what} = {text!r}: {name} {part!r} is not a finite number (m)')
    return value


def on_girders(config: SensorConfig, span_length: float, n_spans: int) -> SensorConfig:
    """
    Return the sensor with ``spanNN/x=X`` places written as girder points ``girder@x``.

    Span NN runs from (NN - 1) L to NN L along the track; a point at its right support
    (X = L) is put a micrometre inside, on this girder rather than the next.

    Raises
    ------
    SensorError
        For a span that does not exist or an X off the span.

    """
    changes: dict[str, Any] = {}
    for key in ('at', 'relative_to'):
        text = getattr(config, key)
        if not text:
            continue
        location = parse_location(text, f'{config.name}: {key}')
        if location.kind != 'span':
            continue
        span, x = int(location.parts[0]), location.x
        if not 1 <= span <= n_spans:
            raise SensorError(f'{config.name}: {key} = {text!r}: span {span} does not exist; '
                              f'the bridge has {n_spans} (1 to {n_spans})')
        if not 0.0 <= x <= span_length:
            raise SensorError(f'{config.name}: {key} = {text!r}: x = {x:g} m is off the span; '
                              f'allowed 0 to {span_length:g} m (bridge.span_length)')
        track_x = (span - 1) * span_length + min(x, span_length - 1e-6)
        changes[key] = f'girder@{track_x:.9g}'
    return replace(config, **changes) if changes else config


def check_places(config: SensorConfig) -> None:
    """
    Check that a sensor's type may be at its location(s) (scenario load time).

    Raises
    ------
    SensorError
        Naming the sensor, its type and where such a sensor may be.

    """
    places = ALLOWED_PLACES[config.type]
    for key in ('at', 'relative_to'):
        text = getattr(config, key)
        if not text:
            continue
        location = parse_location(text, f'{config.name}: {key}')
        if location.kind not in places:
            raise SensorError(f'{config.name}: a {config.type} cannot be at {text!r} (a '
                              f'{location.kind.replace("_", " ")}); allowed: '
                              f'{", ".join(_FORM_NAMES[k] for k in places)}')
        if location.kind == 'pile' and location.parts[2] and config.type != 'strain':
            raise SensorError(f'{config.name}: {key} = {text!r}: a {config.type} reads the '
                              "pile head ('pierNN/pileMM'); only a strain gauge may be at a "
                              "depth ('pierNN/pileMM/depth=D')")


_FORM_NAMES = {'line': 'girder@x (rail_left, rail_right, slab, base)', 'car': 'carNN',
               'wheel': 'carNN/axleK/left|right', 'pile': 'pierNN/pileMM[/depth=D]',
               'pier_top': 'pierNN/top', 'ground': 'ground/pierNN/<point>'}


def request_of(config: SensorConfig, text: str) -> ProbeRequest | None:
    """Return the probe a sensor reads at location ``text`` (None off the beam lines)."""
    location = parse_location(text, config.name)
    if location.kind != 'line':
        return None
    fibre = (float(config.fibre[0]), float(config.fibre[1])) if config.type == 'strain' \
        else (0.0, 0.0)
    return ProbeRequest(location.parts[0], location.x, ALLOWED_PLACES[config.type]['line'],
                        fibre)


def probe_requests(sensors: Sequence[SensorConfig]) -> tuple[ProbeRequest, ...]:
    """Return the distinct beam-line probes the sensors read, in first-use order."""
    out: list[ProbeRequest] = []
    for config in sensors:
        for text in (config.at, config.relative_to):
            request = request_of(config, text) if text else None
            if request is not None and request not in out:
                out.append(request)
    return tuple(out)


def gauge_of(config: SensorConfig) -> GaugeRequest | None:
    """Return the pile strain gauge a sensor reads (None unless a strain gauge on a pile)."""
    location = parse_location(config.at, config.name)
    if config.type != 'strain' or location.kind != 'pile':
        return None
    return GaugeRequest(int(location.parts[0]), int(location.parts[1]), location.depth)


def gauge_requests(sensors: Sequence[SensorConfig]) -> tuple[GaugeRequest, ...]:
    """Return the distinct pile strain gauges the sensors read, in first-use order."""
    out: list[GaugeRequest] = []
    for config in sensors:
        request = gauge_of(config)
        if request is not None and request not in out:
            out.append(request)
    return tuple(out)
