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
The figures of ``ttb-sim analyze`` and ``compare``: one PNG per question of [P] section 4.

Each figure function takes the bags (one for analyze, several overlaid for
compare) and returns a :class:`FigureNote` with the caption, or raises
:class:`Skip` with the reason when no bag has the streams it needs.
"""

from __future__ import annotations

import logging
from pathlib import Path
import re
from typing import Callable, Sequence

import numpy as np

from ttb_sim.analysis.excitation import Excitation
from ttb_sim.analysis.figures import (contour_figure, IndexValue, indices_figure,
                                      map_figure, Panel, panels_figure)
from ttb_sim.analysis.levels import vibration_levels
from ttb_sim.analysis.psd import resolving_segment_seconds, welch_psd
from ttb_sim.analysis.rigid_displacement import rigid_midspan_displacement
from ttb_sim.analysis.safety import deck_acceleration
from ttb_sim.io.streams import Series, Streams
from ttb_sim.report.metrics import (bag_metrics, CAR_BODY_LOWEST_HZ, marks_of, observer_stations,
                                    pier_power_flows, power_flows)
from ttb_sim.report.output import FigureNote
from ttb_sim.report.soil import ground_grid_rms, soil_line, soil_val_points

log = logging.getLogger(__name__)

_LAYERS = ('rail', 'slab', 'base', 'girder')


class Skip(Exception):
    """A figure cannot be drawn from these bags (the message is the reason)."""


def _marks(bags: Sequence[Streams]) -> list[Excitation]:
    """Excitation marks of the first bag with a speed (compare: bags may differ; say so)."""
    for s in bags:
        marks = marks_of(s)
        if marks:
            if len(bags) > 1:
                return [Excitation(f'{m.label} [{s.label}]', m.low, m.high) for m in marks]
            return marks
    return []


def _psd(series: Series, x: np.ndarray, lowest_hz: float) -> tuple[np.ndarray, np.ndarray]:
    seconds = resolving_segment_seconds(lowest_hz, x.size / series.rate)
    return welch_psd(x, series.rate, segment_seconds=min(seconds, x.size / series.rate))


def _time_psd_row(name: str, what: str, unit: str, scale: float,
                  traces: Sequence[tuple[str, Series, np.ndarray]], lowest_hz: float,
                  fmax: float, marks: Sequence[Excitation], logf: bool = False
                  ) -> list[Panel]:
    """Return [time history, PSD] panels of one quantity (values scaled by ``scale`` to unit)."""
    time = Panel(f'{name}: time history', 'time t (s)', f'{what} ({unit})',
                 [(lbl, s.t, x * scale) for lbl, s, x in traces])
    spectra = []
    for lbl, s, x in traces:
        f, p = _psd(s, x * scale, lowest_hz)
        spectra.append((lbl, f[1:], p[1:]))
    bins = ' / '.join(sorted({f'{t[1][1] - t[1][0]:.3g}' for t in spectra}))
    top = min(fmax, min(s.rate for _, s, _ in traces) / 2)
    lo = spectra[0][1][0] if logf else 0.0
    psd = Panel(f'{name}: PSD (Welch, Hann, bins {bins} Hz)', 'frequency f (Hz)',
                f'PSD of {what} ({unit})$^2$/Hz', spectra, logx=logf, logy=True,
                xlim=(lo, top), marks=marks)
    return [time, psd]


def car_body(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Car-body vertical (and lateral) acceleration of the lead car: time beside PSD."""
    have = [s for s in bags if s.car_body]
    if not have:
        raise Skip('no car-body IMU topic (train/carNN/body/imu)')
    marks = _marks(bags)
    car = min(min(s.car_body) for s in have)
    series = [(s.label, s.car_body[car]) for s in have if car in s.car_body]
    rows = [_time_psd_row(f'car{car:02d} body vertical', 'acceleration', 'm/s$^2$', 1.0,
                          [(lbl, v, v.values[:, 2]) for lbl, v in series],
                          CAR_BODY_LOWEST_HZ, 20.0, marks)]
    if any(np.any(v.values[:, 1]) for _, v in series):
        rows.append(_time_psd_row(f'car{car:02d} body lateral', 'acceleration', 'm/s$^2$', 1.0,
                                  [(lbl, v, v.values[:, 1]) for lbl, v in series],
                                  CAR_BODY_LOWEST_HZ, 20.0, marks))
    path = panels_figure(out / 'car_body.png', f'Car-body acceleration, car{car:02d} '
                         '([P] Fig. 12)', rows)
    return FigureNote(path.name, f'Car-body acceleration of car{car:02d} (gravity excluded): '
                      'time history and Welch PSD; the window resolves 0.84 Hz where the '
                      'record allows (else the whole record; bin size in the title).')


def wheel_rail(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Vertical wheel-rail force of the first wheel: time beside a log-log PSD."""
    have = [s for s in bags if s.wheel_rail]
    if not have:
        raise Skip('no wheel-rail force topic (wheel_rail/carNN/axleK/left|right)')
    key = min(min(s.wheel_rail) for s in have)
    series = [(s.label, s.wheel_rail[key]) for s in have if key in s.wheel_rail]
    name = f'car{key[0]:02d} axle{key[1]} {key[2]} wheel'
    rows = [_time_psd_row(name, 'vertical force', 'kN', 1e-3,
                          [(lbl, v, v.values[:, 2]) for lbl, v in series], 2.0, 500.0,
                          _marks(bags), logf=True)]
    path = panels_figure(out / 'wheel_rail.png', f'Vertical wheel-rail force, {name} '
                         '([P] Fig. 14)', rows)
    return FigureNote(path.name, f'Vertical wheel-rail force of the {name}: time history '
                      'and PSD; V/\u03bb marks the change of irregularity spectrum (Eq. 15).')


def _girder_spans(bags: Sequence[Streams]) -> list[int]:
    spans: list[int] = sorted(set().union(*(s.midspan for s in bags)))
    picked: list[int] = [k for k in (5, 7) if k in spans]   # [P]'s observation points ##2 and ##1
    return picked or [spans[len(spans) // 2]]


def girder(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Girder mid-span displacement and deck acceleration: time beside PSD."""
    if not any(s.midspan for s in bags):
        raise Skip('no girder mid-span topic (bridge/spanNN/midspan)')
    marks = _marks(bags)
    rows = []
    for span in _girder_spans(bags):
        series = [(s.label, s.midspan[span]) for s in bags if span in s.midspan]
        rows.append(_time_psd_row(f'span{span:02d} mid-span', 'vertical displacement', 'mm',
                                  1e3, [(lbl, v, v.values[:, 2]) for lbl, v in series], 1.0,
                                  50.0, marks))
        rows.append(_time_psd_row(f'span{span:02d} deck', 'vertical acceleration (30 Hz '
                                  'low-pass)', 'm/s$^2$', 1.0,
                                  [(lbl, v, deck_acceleration(v.values[:, 2], v.rate))
                                   for lbl, v in series], 1.0, 50.0, marks))
    path = panels_figure(out / 'girder.png', 'Girder mid-span ([P] Fig. 17)', rows)
    return FigureNote(path.name, 'Girder mid-span vertical displacement (z up: sagging is '
                      'negative) and deck acceleration (its second derivative, low-passed at '
                      "30 Hz) at the spans of [P]'s observation points where present.")


def _pile_keys(bags: Sequence[Streams]) -> list[tuple[int, int]]:
    keys: list[tuple[int, int]] = sorted(set().union(*(s.pile_acceleration for s in bags)))
    piers = sorted({k[0] for k in keys})[:2]
    if len(piers) == 1:   # one group: [P]'s piles #5 and #14, else the first and the last
        wanted = [k for k in ((piers[0], 5), (piers[0], 14)) if k in keys]
        return wanted or sorted({keys[0], keys[-1]})
    picked = []
    for pier in piers:
        mine = [k for k in keys if k[0] == pier]
        picked.append((pier, 5) if (pier, 5) in mine else mine[0])
    return picked


def piles(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Pile-head vertical acceleration: time beside PSD, for up to two piled piers."""
    if not any(s.pile_acceleration for s in bags):
        raise Skip('no pile IMU topic (piles/pierNN/pileMM/imu): the bag has no piled '
                   'foundation')
    marks = _marks(bags)
    rows = []
    for key in _pile_keys(bags):
        series = [(s.label, s.pile_acceleration[key]) for s in bags
                  if key in s.pile_acceleration]
        rows.append(_time_psd_row(f'pier{key[0]:02d} pile{key[1]:02d} head', 'vertical '
                                  'acceleration', 'm/s$^2$', 1.0,
                                  [(lbl, v, v.values[:, 2]) for lbl, v in series], 1.0, 200.0,
                                  marks, logf=True))
    path = panels_figure(out / 'piles.png', 'Pile-head acceleration ([P] Figs. 20-21)', rows)
    return FigureNote(path.name, 'Pile-head vertical acceleration: time history and PSD, '
                      'with the excitation frequencies of the train (Eq. 19 band).')


def _val_points(bags: Sequence[Streams]) -> list[tuple[Streams, list[tuple[str, np.ndarray]]]]:
    return [(s, pts) for s in bags for pts in [soil_val_points(s)] if pts and s.soil is not None]


def ground(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Ground acceleration at the VAL points: time beside PSD."""
    points = _val_points(bags)
    if not points:
        raise Skip('no soil point cloud with x, y, z, az (soil/points)')
    marks = _marks(bags)
    rows = []
    for k, (label, _) in enumerate(points[0][1]):
        traces = [(s.label, s.soil, pts[k][1]) for s, pts in points
                  if s.soil is not None and k < len(pts)]
        rows.append(_time_psd_row(f'ground {label}', 'vertical acceleration', 'm/s$^2$', 1.0,
                                  traces, 1.0, 100.0, marks, logf=True))
    path = panels_figure(out / 'ground.png', 'Ground acceleration', rows)
    return FigureNote(path.name, 'Vertical ground acceleration at the VAL points (off the '
                      'observation line; else its first, middle and last point).')


def soil_val(bags: Sequence[Streams], out: Path) -> FigureNote:
    """VAL per 1/3 octave at the VAL points (a0 = 1e-6 m/s^2)."""
    points = _val_points(bags)
    if not points:
        raise Skip('no soil point cloud with x, y, z, az (soil/points)')
    marks = _marks(bags)
    panels = []
    for k, (label, _) in enumerate(points[0][1]):
        traces = []
        for s, pts in points:
            if s.soil is not None and k < len(pts):
                c, v = vibration_levels(pts[k][1], s.soil.rate)
                traces.append((s.label, c, v))
        panels.append(Panel(label, '1/3-octave band centre frequency (Hz)',
                            'VAL (dB re 1e-6 m/s$^2$)', traces, logx=True, style='step',
                            xlim=(0.9, 90.0), marks=marks, floor_below_top=80.0))
    path = panels_figure(out / 'soil_val.png', 'Vibration acceleration level per 1/3 octave '
                         '([P] Fig. 26)', [[p] for p in panels])
    return FigureNote(path.name, 'Vertical vibration acceleration level VAL = 20 log10(a_rms '
                      '/ 1e-6 m/s^2) per 1/3-octave band, 1-80 Hz, at the VAL points.')


def soil_contour(bags: Sequence[Streams], out: Path) -> list[FigureNote]:
    """Space-time contour of ground acceleration along the observation line, one per bag."""
    notes = []
    for s in bags:
        line = soil_line(s)
        if line is None or s.soil is None:
            continue
        order, distance, az = line
        if az.shape[1] < 2:
            continue
        ends = s.soil.values[0][order[[0, -1]]]
        x, y = s.soil_fields.index('x'), s.soil_fields.index('y')
        where = f'from ({ends[0, x]:.1f}, {ends[0, y]:.1f}) to ({ends[1, x]:.1f}, ' \
            f'{ends[1, y]:.1f}) m'
        name = 'soil_contour.png' if len(bags) == 1 else \
            f'soil_contour_{re.sub(r"[^A-Za-z0-9_.-]", "_", s.label)}.png'
        contour_figure(out / name, 'Ground vertical acceleration along the observation line '
                       f'([P] Fig. 25)\n{s.label}: line {where}', s.soil.t, distance, az,
                       'time t (s)', 'distance along the observation line (m)',
                       'vertical acceleration (m/s$^2$)')
        notes.append(FigureNote(name, f'{s.label}: vertical ground acceleration along the soil '
                                'observation line against time.'))
    if not notes:
        raise Skip('no soil point cloud of two or more points with az (soil/points)')
    return notes


def soil_grid(bags: Sequence[Streams], out: Path) -> list[FigureNote]:
    """Plan map of the RMS vertical ground acceleration over each piled pier's grid, per bag."""
    notes = []
    for s in bags:
        maps = ground_grid_rms(s)
        if not maps:
            continue
        name = 'soil_grid.png' if len(bags) == 1 else \
            f'soil_grid_{re.sub(r"[^A-Za-z0-9_.-]", "_", s.label)}.png'
        map_figure(out / name, f'RMS vertical ground acceleration around the piled piers\n'
                   f'{s.label}', [(f'{pier} (peak RMS {v.max():.3g} m/s$^2$)', x, y, v)
                                  for pier, (x, y, v) in maps.items()],
                   'RMS vertical acceleration (m/s$^2$)')
        notes.append(FigureNote(name, f'{s.label}: RMS of the vertical ground acceleration over '
                                'the whole record at each point of the ground grid around each '
                                'piled pier (output.soil_grid_spacing), in track axes.'))
    if not notes:
        raise Skip('no ground grid of soil points (output.soil_grid_spacing, named in '
                   'summary.json)')
    return notes


def pier_power_flow(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Power flow into each pier through its bearings, piled piers beside piers on springs."""
    flows = [(s, pier_power_flows(s)) for s in bags]
    flows = [(s, f) for s, f in flows if f]
    if not flows:
        raise Skip('needs observers of rail, slab, base and girder at one x (output.observers) '
                   'on a slab track and summary.json, or pier tops (piers/pierNN/top) with '
                   'their bearings')
    marks = _marks(bags)
    panels = []
    for pier in sorted(set().union(*(f for _, f in flows))):
        piled = any(pier in _piled(s) for s, _ in flows)
        panels.append(_power_panel(f'pier{pier:02d} ({"piled" if piled else "springs"})', 'W',
                                   [(s.label, f[pier]) for s, f in flows if pier in f], marks))
    rows = [panels[i:i + 3] for i in range(0, len(panels), 3)]
    path = panels_figure(out / 'power_flow.png', 'Vibration power flow into the piers through '
                         'their bearings ([P] Eqs. 17-18)', rows)
    return FigureNote(path.name, 'Power flow P(f) = 1/2 Re[F V*] per FFT line into each pier: the '
                      "force of its two bearings against its top's velocity (W), piled piers "
                      'and piers on foundation springs side by side (the rocking power of the '
                      'bearing pair is not recorded). Magnitudes on a log axis; the titles give '
                      'the time-mean power (the sum of the lines).')


def _power_panel(title: str, unit: str,
                 spectra: Sequence[tuple[str, tuple[np.ndarray, np.ndarray]]],
                 marks: Sequence[Excitation]) -> Panel:
    """Return a panel of power-flow magnitudes per line, one trace per bag, means in the title."""
    traces = [(label, freq[1:], np.abs(p[1:])) for label, (freq, p) in spectra]
    means = ' / '.join(f'{p.sum():.3g}' for _, (_, p) in spectra)
    return Panel(f'{title}: mean {means} {unit}', 'frequency f (Hz)',
                 f'|P(f)| per line ({unit})', traces, logy=True, xlim=(0.0, 50.0), marks=marks)


def _piled(s: Streams) -> set[int]:
    """Return the piled piers of a bag (from its pile topics)."""
    return {pier for pier, _ in s.pile_displacement} | {pier for pier, _ in s.pile_acceleration}


def power_flow(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Power flow per layer (rail, slab, base, girder) at each observer station."""
    flows = [(s, power_flows(s)) for s in bags]
    flows = [(s, f) for s, f in flows if f]
    if not flows:
        return pier_power_flow(bags, out)
    marks = _marks(bags)
    stations = sorted(set().union(*(f for _, f in flows)))
    panels = []
    for station in stations:
        for layer in _LAYERS:
            panels.append(_power_panel(f'{layer} at {station}', 'W/m',
                                       [(s.label, f[station][layer]) for s, f in flows
                                        if station in f], marks))
    rows = [panels[i:i + 2] for i in range(0, len(panels), 2)]
    path = panels_figure(out / 'power_flow.png', 'Vibration power flow per layer ([P] Eqs. '
                         '17-18, Figs. 18-19)', rows)
    return FigureNote(path.name, 'Power flow P(f) = 1/2 Re[F V*] per FFT line, W per metre of '
                      'track: for the rail the fastener force against the rail velocity (power '
                      'passed down), for slab, base and girder the force of the connection '
                      'above against their velocity (power received). Magnitudes on a log '
                      'axis; the titles give the time-mean power (the sum of the lines).')


def observers(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Displacements at observer stations (rail, slab, base, girder) over time."""
    stations = [(s, observer_stations(s)) for s in bags]
    if not any(st for _, st in stations):
        if any(s.observers for s in bags):
            raise Skip('observer positions unknown without summary.json')
        raise Skip('no observer topic (observers/NAME)')
    xs = sorted(set().union(*(st for _, st in stations)))
    panels = []
    for x in xs:
        traces = []
        for s, st in stations:
            for layer, series in st.get(x, {}).items():
                label = layer if len(bags) == 1 else f'{layer} [{s.label}]'
                traces.append((label, series.t, series.values[:, 2] * 1e3))
        panels.append(Panel(f'x = {x:g} m', 'time t (s)', 'vertical displacement (mm)',
                            traces))
    path = panels_figure(out / 'observers.png', 'Track and girder displacement at the '
                         'observation points ([P] Fig. 15)', [[p] for p in panels])
    return FigureNote(path.name, 'Vertical displacement (z up) of rail, slab, base plate and '
                      'girder at each observer position.')


def rigid(bags: Sequence[Streams], out: Path) -> FigureNote:
    """Mid-span displacement against the rigid-displacement estimate of Eq. 16."""
    panels = []
    for s in bags:
        piers = sorted({k[0] for k in s.pile_displacement})
        for span in sorted(s.midspan):
            if span not in piers and span + 1 not in piers:
                continue
            groups = []
            for pier in (span, span + 1):
                keys = sorted(k for k in s.pile_displacement if k[0] == pier)
                groups.append(np.stack([s.pile_displacement[k].values[:, 2] for k in keys],
                                       axis=1) if keys else None)
            mid = s.midspan[span]
            n = min([mid.t.size] + [g.shape[0] for g in groups if g is not None])
            est = rigid_midspan_displacement(*(None if g is None else g[:n] for g in groups))
            label = '' if len(bags) == 1 else f' [{s.label}]'
            panels.append(Panel(f'span{span:02d}{label}', 'time t (s)', 'vertical '
                                'displacement (mm)',
                                [('girder mid-span', mid.t[:n], mid.values[:n, 2] * 1e3),
                                 ('rigid estimate (Eq. 16)', mid.t[:n], est * 1e3),
                                 ('difference', mid.t[:n], (mid.values[:n, 2] - est) * 1e3)]))
    if not panels:
        raise Skip('needs pile displacements (piles/pierNN/pileMM/displacement) under a span '
                   'with a mid-span topic')
    path = panels_figure(out / 'rigid_displacement.png', 'Rigid-displacement method ([P] Eq. '
                         '16, Fig. 17)', [[p] for p in panels])
    return FigureNote(path.name, 'Girder mid-span displacement against the rigid-body '
                      'estimate from the pile-head displacements of its two supports (Eq. 16).')


def indices(bags: Sequence[Streams], out: Path,
            metrics: Sequence[dict] | None = None) -> FigureNote:
    """Ride and safety indices of every bag against their limits."""
    all_metrics = list(metrics) if metrics is not None else [bag_metrics(s) for s in bags]
    names: list[str] = []
    for m in all_metrics:
        names.extend(k for k in m.get('indices', {}) if k not in names)
    if not names:
        raise Skip('no car-body, wheel-rail or mid-span topic to rate')
    rows = []
    for name in names:
        values: list[IndexValue] = []
        limit, unit = 0.0, ''
        for s, m in zip(bags, all_metrics):
            entry = m.get('indices', {}).get(name)
            if entry:
                values.append((s.label, entry['value'], entry.get('reason', '')))
                limit, unit = entry['limit'], entry['unit']
        rows.append((name.replace('_', ' '), values, limit, unit))
    path = indices_figure(out / 'indices.png', 'Ride comfort and running safety against '
                          'limits', rows)
    return FigureNote(path.name, 'Each index over its limit (Sperling 2.5 = excellent; car '
                      'body 1.3 / 1.0 m/s^2; Q/P 0.8; wheel-load reduction 0.6; lateral '
                      'wheelset force 10 kN + P0/3; deck 5 m/s^2): green within, red beyond; '
                      "n/a where the bag's vehicle model cannot produce the index (a quarter "
                      'car has no lateral dynamics), with the reason.')


FIGURES: tuple[Callable[..., FigureNote | list[FigureNote]], ...] = (
    car_body, wheel_rail, girder, observers, power_flow, piles, rigid, ground, soil_val,
    soil_contour, soil_grid)
"""Every figure but the indices chart, in the order of index.html."""


def write_figures(bags: Sequence[Streams], out: Path, metrics: Sequence[dict]
                  ) -> tuple[list[FigureNote], list[FigureNote]]:
    """Draw every figure the bags allow into ``out``; return (written, skipped with reason)."""
    written: list[FigureNote] = []
    skipped: list[FigureNote] = []
    for draw in (*FIGURES, indices):
        try:
            note = draw(bags, out, metrics) if draw is indices else draw(bags, out)
        except Skip as reason:
            log.info('figure %s skipped: %s', draw.__name__, reason)
            skipped.append(FigureNote(draw.__name__, str(reason)))
            continue
        written.extend(note if isinstance(note, list) else [note])
    return written, skipped
