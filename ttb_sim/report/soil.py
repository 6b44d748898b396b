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
The ground points of a bag's ``~/soil/points``: the observation line, the VAL points, the grid.

Shared by :mod:`ttb_sim.report.metrics` (their numbers in ``metrics.json``) and
:mod:`ttb_sim.report.figures`. Points are told apart by the names ``summary.json``
gives them (``pierNN/line_01``, ``val_1``, ``user_01``, ``grid_RR_CC``); a bag
without them (a node's) by where ttb_sim writes them.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ttb_sim.analysis.levels import total_level, vibration_levels
from ttb_sim.io.streams import Streams


def _soil_xyz(s: Streams) -> np.ndarray | None:
    if s.soil is None or not all(c in s.soil_fields for c in ('x', 'y', 'z', 'az')):
        return None
    return np.stack([s.soil.values[0, :, s.soil_fields.index(c)] for c in ('x', 'y', 'z')],
                    axis=-1).astype(float)


def soil_line(s: Streams) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """
    Return (point indices, distance along the line (m), az (n, points)) of the observation line.

    The first piled pier's ``line_`` points where summary.json names the points;
    else the points from the first one on that share its y and z (to 1 mm), in
    the order written: ttb_sim writes [P]'s observation line first, then the VAL
    points, the user's points and the ground grid. Ordered by x.
    """
    xyz = _soil_xyz(s)
    if xyz is None or s.soil is None:
        return None
    if s.soil_names:
        first = s.soil_names[0].split('/')[0]
        on = np.array([i for i, n in enumerate(s.soil_names)
                       if n.startswith(f'{first}/line_')], dtype=np.intp)
    else:
        same = ((np.abs(xyz[:, 1] - xyz[0, 1]) < 1e-3) & (np.abs(xyz[:, 2] - xyz[0, 2]) < 1e-3))
        on = np.arange(int(np.argmin(same)) if not same.all() else same.size)
    if on.size == 0:
        on = np.arange(1)
    order = on[np.argsort(xyz[on, 0], kind='stable')]
    distance = xyz[order, 0] - xyz[order[0], 0]
    return order, distance, s.soil.values[:, order, s.soil_fields.index('az')]


def ground_grid_rms(s: Streams) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """
    Return, per piled pier, its ground grid's x (nx,), y (ny,) and RMS az (ny, nx) (m, m/s^2).

    The points named ``pierNN/grid_RR_CC`` in summary.json (rows along y, x fastest);
    {} without names or grid.
    """
    xyz = _soil_xyz(s)
    if xyz is None or s.soil is None or not s.soil_names:
        return {}
    az = s.soil.values[:, :, s.soil_fields.index('az')]
    rms = np.sqrt(np.mean(az ** 2, axis=0))
    out: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    piers = sorted({n.split('/')[0] for n in s.soil_names if '/grid_' in n})
    for pier in piers:
        idx = np.array([i for i, n in enumerate(s.soil_names) if n.startswith(f'{pier}/grid_')])
        rows = max(int(s.soil_names[i].split('_')[-2]) for i in idx)
        if idx.size % rows:
            continue
        shape = (rows, idx.size // rows)
        out[pier] = (xyz[idx, 0].reshape(shape)[0], xyz[idx, 1].reshape(shape)[:, 0],
                     rms[idx].reshape(shape))
    return out


VAL_POINTS_UNNAMED = 6
"""Points rated by VAL in a cloud without names: the first ones after the line."""


def soil_val_points(s: Streams) -> list[tuple[str, np.ndarray]]:
    """
    Return (label, vertical acceleration record) of the ground points to rate by VAL.

    Where summary.json names the points: every pier's [P] section 4.2.2 VAL
    points and the user's points (not the ground grid). Without names: the
    first :data:`VAL_POINTS_UNNAMED` points after the observation line. Where
    there are none, the first, middle and last point of the line.
    """
    xyz = _soil_xyz(s)
    line = soil_line(s)
    if xyz is None or line is None or s.soil is None:
        return []
    az = s.soil.values[:, :, s.soil_fields.index('az')]
    on_line = set(line[0].tolist())
    if s.soil_names:
        off = [i for i, n in enumerate(s.soil_names)
               if n.split('/')[-1].startswith(('val_', 'user_'))]
    else:
        off = [i for i in range(xyz.shape[0]) if i not in on_line][:VAL_POINTS_UNNAMED]
    if off:
        return [(f'point ({xyz[i, 0]:.1f}, {xyz[i, 1]:.1f}) m', az[:, i]) for i in off]
    order, distance, _ = line
    n = order.size
    return [(f'line point at {distance[k]:.1f} m', az[:, order[k]])
            for k in sorted({0, n // 2, n - 1})]


def soil_metrics(s: Streams) -> dict[str, Any]:
    """Return the ground points' numbers of ``metrics.json``: line peak, VAL per point."""
    line = soil_line(s)
    if line is None or s.soil is None:
        return {}
    fs = s.soil.rate
    points = {}
    for label, record in soil_val_points(s):
        centres, val = vibration_levels(record, fs)
        points[label.replace(' ', '_')] = {
            'vertical_acceleration_peak_m_s2': float(np.max(np.abs(record))),
            'vertical_acceleration_rms_m_s2': float(np.sqrt(np.mean(np.square(record)))),
            'val_band_centres_hz': [float(c) for c in centres],
            'val_db': [float(v) if math.isfinite(v) else None for v in val],
            'val_max_db': float(np.max(val)), 'val_max_band_hz': float(centres[np.argmax(val)]),
            'vl_total_db': total_level(centres, val),
            'vl_wk_db': total_level(centres, val, 'Wk'),
            'vl_wm_db': total_level(centres, val, 'Wm')}
    return {'line_peak_acceleration_m_s2': float(np.max(np.abs(line[2]))), 'points': points}
