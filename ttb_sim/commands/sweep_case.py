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
One case of a sweep: run a scenario at one speed and seed, analyse its bag, mark it finished.

:func:`run_case` is a plain top-level function of a picklable :class:`CaseSpec`,
so it runs the same in a local process pool and on a Dask worker.  A case
folder holds ``bag/`` (rosbag2 + ``summary.json``), ``metrics.json`` and, written
last and atomically, ``case.json``: a folder without ``case.json`` is a case
that did not finish (killed, failed) and is removed and redone by the next
sweep.  :func:`case_row` reduces a case's metrics to the aggregate CSV's row.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
import json
import os
from pathlib import Path
import shutil
import socket
import time
import traceback
from typing import Any

import numpy as np

DONE = 'case.json'
"""Name of the file that marks a finished case."""


@dataclass(frozen=True)
class CaseSpec:
    """Everything a worker needs to run one case."""

    name: str
    folder: str
    scenario: str
    overrides: tuple[str, ...]
    speed_kmh: float
    seed: int | None
    duration: float | None
    storage: str = 'mcap'
    force: bool = False

    def values(self) -> list[tuple[str, Any]]:
        """Return the (key, value) settings of this case on top of the overrides."""
        out: list[tuple[str, Any]] = [('train.speed_kmh', self.speed_kmh)]
        if self.seed is not None:
            out.append(('irregularity.seed', self.seed))
        if self.duration is not None:
            out.append(('solver.duration', self.duration))
        return out


def is_finished(folder: Path) -> bool:
    """Return True when the case folder holds a readable ``case.json`` with status ok."""
    try:
        return json.loads((folder / DONE).read_text()).get('status') == 'ok'
    except (OSError, ValueError, AttributeError):
        return False


def run_case(spec: CaseSpec) -> dict[str, Any]:
    """
    Run one case into its folder; return its record (also ``case.json`` when it succeeded).

    Never raises for a failing case: the record has ``status`` 'failed' or
    'diverged' and the error message, and no ``case.json`` is written.
    """
    from ttb_sim.io.passage import run_to_bag
    from ttb_sim.config import load_scenario
    from ttb_sim.io.streams import load_streams
    from ttb_sim.report.metrics import bag_metrics
    from ttb_sim.report.output import write_json
    from ttb_sim.sim import Simulation, STEP_BUDGET

    start = time.perf_counter()
    folder = Path(spec.folder)
    record: dict[str, Any] = {'case': spec.name, 'speed_kmh': spec.speed_kmh, 'seed': spec.seed,
                              'host': socket.gethostname(), 'pid': os.getpid()}
    try:
        if folder.exists():
            shutil.rmtree(folder)   # a half-written case: redo it from scratch
        folder.mkdir(parents=True)
        scenario = load_scenario(spec.scenario, spec.overrides, spec.values())
        sim = Simulation(scenario, max_steps=None if spec.force else STEP_BUDGET)
        result = run_to_bag(scenario, folder / 'bag', spec.storage, simulation=sim)
        record['simulation_wall_time_s'] = result.summary.get('wall_time')
        if result.status != 'ok':
            record.update(status=result.status, error=result.summary.get('message', ''))
            return record
        analysed = time.perf_counter()
        metrics = bag_metrics(load_streams(folder / 'bag', spec.name))
        write_json(folder / 'metrics.json', metrics)
        record.update(status='ok', metrics=metrics,
                      analysis_time_s=time.perf_counter() - analysed,
                      wall_time_s=time.perf_counter() - start, spec=asdict(spec))
        tmp = folder / f'.{DONE}.tmp'
        write_json(tmp, record)
        tmp.replace(folder / DONE)
        return record
    except Exception as exc:   # a failing case is reported and the sweep goes on
        record.update(status='failed', error=f'{type(exc).__name__}: {exc}',
                      traceback=traceback.format_exc(limit=5))
        return record


def _max(values: list[float]) -> float | None:
    finite = [v for v in values if v is not None and np.isfinite(v)]
    return max(finite) if finite else None


def case_row(record: dict[str, Any]) -> dict[str, Any]:
    """Return the aggregate CSV row of a case record (peaks over cars, wheels, spans, piles)."""
    m = record.get('metrics') or {}
    row: dict[str, Any] = {'case': record['case'], 'speed_kmh': record['speed_kmh'],
                           'seed': record.get('seed'), 'status': record['status'],
                           'wall_time_s': record.get('wall_time_s'),
                           'error': record.get('error', '')}
    girder = m.get('girder', {})
    row['girder_displacement_peak_m'] = _max([max(-g['displacement_min_m'],
                                                  g['displacement_max_m'])
                                              for g in girder.values()])
    row['deck_acceleration_peak_m_s2'] = _max([g['deck_acceleration_peak_m_s2']
                                               for g in girder.values()])
    wheel = m.get('wheel_rail', {})
    row['wheel_rail_vertical_max_N'] = wheel.get('vertical_max_N')
    row['derailment_coefficient_max'] = wheel.get('derailment_coefficient_max')
    row['wheel_load_reduction_max'] = _max([wheel.get('wheel_load_reduction_max'),
                                            wheel.get('wheel_load_reduction_dynamic_max')])
    cars = m.get('car_body', {})
    row['car_body_vertical_peak_m_s2'] = _max([c['vertical_peak_m_s2'] for c in cars.values()])
    row['sperling_vertical_max'] = _max([c['sperling_vertical'] for c in cars.values()])
    piles = m.get('piles', {})
    row['pile_acceleration_peak_m_s2'] = _max([p.get('vertical_acceleration_peak_m_s2')
                                               for p in piles.values()])
    for name, p in piles.items():
        row[f'rotation_peak_rad.{name}'] = p.get('rotation_peak_rad')
    soil = m.get('soil', {})
    for name, p in soil.get('points', {}).items():
        row[f'val_max_db.{name}'] = p.get('val_max_db')
        row[f'vl_wk_db.{name}'] = p.get('vl_wk_db')
    return row
