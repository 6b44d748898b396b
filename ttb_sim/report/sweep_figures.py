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
Figures of a sweep: peak responses against train speed ([P] Example 2, Figs. 20-26).

Every seed of a speed is a marker, their mean a line.  Figures are drawn only
for the quantities some finished case has; each returns its file name.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ttb_sim.analysis.figures import Panel, panels_figure

log = logging.getLogger(__name__)


def _by_speed(rows: Sequence[dict[str, Any]], column: str, scale: float
              ) -> tuple[list[tuple[str, np.ndarray, np.ndarray]], bool]:
    """Return traces (seeds as points, mean as line) of one column against speed."""
    ok = [r for r in rows if r['status'] == 'ok' and r.get(column) is not None]
    if not ok:
        return [], False
    speed = np.array([float(r['speed_kmh']) for r in ok])
    value = np.array([float(r[column]) * scale for r in ok])
    speeds = np.unique(speed)
    mean = np.array([value[speed == v].mean() for v in speeds])
    traces = [('mean over seeds', speeds, mean)]
    if len(ok) > len(speeds):
        traces.append(('cases (seeds)', speed, value))
    return traces, True


def _panel(rows: Sequence[dict[str, Any]], column: str, title: str, ylabel: str,
           scale: float = 1.0) -> Panel | None:
    traces, found = _by_speed(rows, column, scale)
    if not found:
        return None
    return Panel(title, 'train speed V (km/h)', ylabel, traces, style='sweep')


def sweep_figures(rows: Sequence[dict[str, Any]], out: Path) -> list[str]:
    """Write the sweep figures into ``out``; return the file names written."""
    written = []
    general = [p for p in (
        _panel(rows, 'girder_displacement_peak_m', 'peak girder mid-span displacement',
               'displacement (mm)', 1e3),
        _panel(rows, 'deck_acceleration_peak_m_s2', 'peak deck acceleration (30 Hz low-pass)',
               'acceleration (m/s$^2$)'),
        _panel(rows, 'wheel_rail_vertical_max_N', 'peak vertical wheel-rail force',
               'force (kN)', 1e-3),
        _panel(rows, 'car_body_vertical_peak_m_s2', 'peak car-body vertical acceleration',
               'acceleration (m/s$^2$)'),
        _panel(rows, 'sperling_vertical_max', 'Sperling index, vertical (worst car)',
               'Sperling index W (-)'),
        _panel(rows, 'derailment_coefficient_max', 'derailment coefficient Q/P (worst wheel)',
               'Q/P (-)'),
    ) if p is not None]
    if general:
        grid = [general[i:i + 2] for i in range(0, len(general), 2)]
        panels_figure(out / 'sweep_peaks.png', 'Peak responses against speed', grid)
        written.append('sweep_peaks.png')
    piles = [p for p in (
        _panel(rows, 'pile_acceleration_peak_m_s2', 'peak pile-head vertical acceleration',
               'acceleration (m/s$^2$)'),) if p is not None]
    rotation_columns = sorted({k for r in rows for k in r if k.startswith('rotation_peak_rad.')})
    ok = [r for r in rows if r['status'] == 'ok']
    if rotation_columns and ok:
        speeds = sorted({float(r['speed_kmh']) for r in ok})
        index = np.arange(len(rotation_columns), dtype=float) + 1
        traces = []
        for v in speeds:
            values = [np.nanmean([float(r[c]) if r.get(c) not in (None, '') else np.nan
                                  for r in ok if float(r['speed_kmh']) == v])
                      for c in rotation_columns]
            traces.append((f'{v:g} km/h', index, np.array(values)))
        piles.append(Panel('peak pile rotation per pile ([P] Fig. 24); x: '
                           + ', '.join(c.split('.', 1)[1] for c in rotation_columns),
                           'pile (order of the list in the title)', 'rotation (rad)', traces,
                           legend=True))
    if piles:
        panels_figure(out / 'sweep_piles.png', 'Piles against speed ([P] Example 2)',
                      [[p] for p in piles])
        written.append('sweep_piles.png')
    val_columns = sorted({k for r in rows for k in r if k.startswith(('val_max_db.',
                                                                     'vl_wk_db.'))})
    soil = [p for p in (_panel(rows, c, c.replace('.', ' at ').replace('_', ' '),
                               'level (dB re 1e-6 m/s$^2$)') for c in val_columns)
            if p is not None]
    if soil:
        panels_figure(out / 'sweep_soil.png', 'Ground vibration levels against speed '
                      '([P] Fig. 26)', [soil[i:i + 2] for i in range(0, len(soil), 2)])
        written.append('sweep_soil.png')
    return written
