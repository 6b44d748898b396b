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
Built-in sensor layouts: the monitoring systems of real bridges, usable by name.

``sensor_layouts`` lists entries ``kind:number``; each expands to sensors whose names
start with the kind and the number, with the specifications of common hardware
(the values below; each is an ordinary sensor afterwards):

- ``span:N`` — girder N: vertical accelerometers at 1/4, 1/2 and 3/4 of the span (plus
  the lateral axis at mid-span), soffit strain gauges at the same sections, an
  inclinometer at each end and, where the girder rests on a pier, a bearing LVDT
  (girder end relative to the pier top);
- ``pier:N`` — piled pier N: pile-head accelerometers on [P]'s piles #5 and #14 and the
  central pile, geophones at [P]'s three VAL ground points, the pier top's settlement and
  a triaxial accelerometer on the pier top (the pier cap's vibration);
- ``wheelset:N`` — car N: its first axle instrumented (both wheels, three force axes).
"""

from __future__ import annotations

from typing import Any, Sequence

from ttb_sim.config.sensor_records import SensorConfig, SensorError

__all__ = ['expand_layouts', 'LAYOUT_KINDS', 'SOFFIT_FIBRE']

ACCELEROMETER = {'type': 'accelerometer', 'rate_hz': 200.0, 'noise_density': 2.2e-4,
                 'resolution': 3.8e-5, 'full_scale': 19.6, 'bias_walk': 1e-5}
"""A MEMS accelerometer: 22.5 micro-g/sqrt(Hz), 20 bits over +-2 g (e.g. ADXL355's data)."""
STRAIN_GAUGE = {'type': 'strain', 'rate_hz': 100.0, 'noise_density': 1e-8,
                'resolution': 1e-8}
"""A foil gauge in a quarter bridge on a 24-bit logger: 0.01 micro-strain/sqrt(Hz)."""
INCLINOMETER = {'type': 'inclinometer', 'rate_hz': 50.0, 'noise_density': 1e-5,
                'resolution': 1e-6}
"""A MEMS tilt sensor: about 0.0006 deg/sqrt(Hz)."""
LVDT = {'type': 'displacement', 'rate_hz': 50.0, 'noise_density': 1e-6, 'resolution': 1e-6}
"""A bearing displacement transducer: 1 micrometre resolution."""
GEOPHONE = {'type': 'geophone', 'rate_hz': 200.0, 'noise_density': 1e-7, 'resolution': 1e-8}
"""A 4.5 Hz geophone on a 24-bit logger (velocity)."""
LEVEL = {'type': 'displacement', 'rate_hz': 50.0, 'noise_density': 2e-6,
         'resolution': 1e-6}
"""A hydrostatic levelling cell on the pier top (settlement)."""
WHEELSET = {'type': 'wheel_force', 'rate_hz': 500.0, 'noise_density': 50.0,
            'resolution': 10.0}
"""An instrumented wheelset: about 1 % of the static wheel load in noise at 500 Hz."""

SOFFIT_FIBRE = -1.5
"""Height of the soffit below the girder axis (m), assumed for a 32 m box girder about
3 m deep ([P] does not give the section's depth)."""
END_INSET = 0.05
"""Distance of the end instruments from the girder end (m): on the girder, not the next."""

LAYOUT_KINDS = ('span', 'pier', 'wheelset')
"""The kinds of ``sensor_layouts`` entries."""


def expand_layouts(entries: Sequence[str], span_length: float, n_spans: int,
                   pier_tops: bool, pile_grid: tuple[int, int]) -> tuple[SensorConfig, ...]:
    """
    Return the sensors of the layouts ``entries`` (``kind:number``).

    Parameters
    ----------
    entries : sequence of str
        The ``sensor_layouts`` entries.
    span_length, n_spans : float, int
        The girders (spans start at x = 0, one after the other).
    pier_tops : bool
        Whether the intermediate supports are piers with a top (foundation springs or
        piles): the bearing LVDTs need one.
    pile_grid : (int, int)
        (rows, cols) of the pile groups, for the central pile.

    Raises
    ------
    SensorError
        Naming the entry and what is allowed.

    """
    out: list[SensorConfig] = []
    for i, entry in enumerate(entries):
        kind, _, number_text = entry.partition(':')
        what = f'sensor_layouts[{i}] = {entry!r}'
        if kind not in LAYOUT_KINDS or not number_text.isdigit():
            raise SensorError(f"{what}: expected 'kind:number' with kind one of "
                              f"{', '.join(LAYOUT_KINDS)} (e.g. 'span:7')")
        number = int(number_text)
        if kind == 'span':
            if not 1 <= number <= n_spans:
                raise SensorError(f'{what}: span {number} does not exist; the bridge has '
                                  f'{n_spans} (1 to {n_spans})')
            items = _span(number, span_length, n_spans, pier_tops)
        elif kind == 'pier':
            items = _pier(number, pile_grid)
        else:
            items = _wheelset(number)
        out.extend(SensorConfig(**item) for item in items)
    return tuple(out)


def _span(n: int, length: float, n_spans: int, pier_tops: bool) -> list[dict[str, Any]]:
    start = (n - 1) * length
    items: list[dict[str, Any]] = []
    for tag, frac in (('q1', 0.25), ('mid', 0.5), ('q3', 0.75)):
        x = start + frac * length
        axes = 'yz' if tag == 'mid' else 'z'
        items.append({**ACCELEROMETER, 'name': f'span{n:02d}_acc_{tag}', 'at': f'girder@{x:g}',
                      'axes': axes})
        items.append({**STRAIN_GAUGE, 'name': f'span{n:02d}_strain_{tag}',
                      'at': f'girder@{x:g}', 'fibre': (0.0, SOFFIT_FIBRE)})
    ends = (('start', start + END_INSET, n), ('end', start + length - END_INSET, n + 1))
    for tag, x, support in ends:
        items.append({**INCLINOMETER, 'name': f'span{n:02d}_tilt_{tag}', 'at': f'girder@{x:g}'})
        if pier_tops and 2 <= support <= n_spans:
            items.append({**LVDT, 'name': f'span{n:02d}_bearing_{tag}', 'at': f'girder@{x:g}',
                          'relative_to': f'pier{support:02d}/top', 'axes': 'xz'})
    return items


def _pier(n: int, grid: tuple[int, int]) -> list[dict[str, Any]]:
    rows, cols = grid
    central = (rows // 2) * cols + cols // 2 + 1
    piles = sorted({p for p in (5, 14, central) if p <= rows * cols})
    items: list[dict[str, Any]] = [
        {**ACCELEROMETER, 'name': f'pier{n:02d}_pile{p:02d}_acc', 'at': f'pier{n:02d}/pile{p:02d}',
         'axes': 'xyz'} for p in piles]
    items += [{**GEOPHONE, 'name': f'pier{n:02d}_geo_{k}', 'at': f'ground/pier{n:02d}/val_{k}'}
              for k in (1, 2, 3)]
    items.append({**LEVEL, 'name': f'pier{n:02d}_settlement', 'at': f'pier{n:02d}/top'})
    items.append({**ACCELEROMETER, 'name': f'pier{n:02d}_top_acc', 'at': f'pier{n:02d}/top',
                  'axes': 'xyz'})
    return items


def _wheelset(n: int) -> list[dict[str, Any]]:
    return [{**WHEELSET, 'name': f'car{n:02d}_wheel_{side}', 'at': f'car{n:02d}/axle1/{side}'}
            for side in ('left', 'right')]
