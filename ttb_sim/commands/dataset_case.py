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
One case of a data set: a passage at drawn parameter values, its labels and features.

:func:`run_dataset_case` is a top-level function of a picklable
:class:`DatasetCase`, so it runs the same in a local process pool and on a Dask
worker.  A case folder holds ``bag/`` (kept unless the spec says
``keep_bags: false``), ``summary.json`` (the run's summary with its ``labels``)
and, written last and atomically, ``case.json``: the drawn values, status,
labels, scalar features, PSDs and truth peaks.  A folder without ``case.json``
did not finish (killed, failed) and is removed and redone by the next run.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import os
from pathlib import Path
import shutil
import socket
import time
import traceback
from typing import Any

from ttb_sim.commands.sweep_case import case_row, DONE, is_finished
from ttb_sim.twin.features import FeatureSpec

__all__ = ['DatasetCase', 'DONE', 'is_finished', 'run_dataset_case']

SWEEP_ONLY = ('case', 'speed_kmh', 'seed', 'status', 'wall_time_s', 'error')
"""Columns of a sweep row that are not truth peaks."""


@dataclass(frozen=True)
class DatasetCase:
    """Everything a worker needs to run one case of a data set."""

    name: str
    index: int
    folder: str
    scenario: str
    overrides: tuple[str, ...]
    values: tuple[tuple[str, Any], ...]
    """The drawn values, then the spec's duration: ``(key, value)`` pairs."""
    parameters: tuple[tuple[str, Any], ...]
    """The drawn values alone (the table's parameter columns)."""
    features: FeatureSpec
    keep_bag: bool = True
    storage: str = 'mcap'
    force: bool = False


def run_dataset_case(case: DatasetCase) -> dict[str, Any]:
    """
    Run one case into its folder; return its record (also ``case.json`` when it succeeded).

    Never raises for a failing case: the record has ``status`` 'failed' or
    'diverged' and the error message, and no ``case.json`` is written.
    """
    from ttb_sim.io.passage import run_to_bag
    from ttb_sim.config import load_scenario
    from ttb_sim.report.output import write_json
    from ttb_sim.sim import Simulation, STEP_BUDGET
    from ttb_sim.twin.features import sensor_features

    start = time.perf_counter()
    folder = Path(case.folder)
    record: dict[str, Any] = {'case': case.name, 'index': case.index,
                              'parameters': dict(case.parameters),
                              'host': socket.gethostname(), 'pid': os.getpid()}
    try:
        if folder.exists():
            shutil.rmtree(folder)   # a half-written case: redo it from scratch
        folder.mkdir(parents=True)
        scenario = load_scenario(case.scenario, case.overrides, case.values)
        sim = Simulation(scenario, max_steps=None if case.force else STEP_BUDGET)
        bag = folder / 'bag'
        result = run_to_bag(scenario, bag, case.storage, simulation=sim)
        record['simulation_wall_time_s'] = result.summary.get('wall_time')
        if result.status != 'ok':
            record.update(status=result.status, error=result.summary.get('message', ''))
            return record
        shutil.copy2(bag / 'summary.json', folder / 'summary.json')
        labels = json.loads((folder / 'summary.json').read_text()).get('labels', {})
        features = sensor_features(bag, scenario.all_sensors, case.features)
        truth = _truth(bag, case.name) if case.features.truth else {}
        if not case.keep_bag:
            shutil.rmtree(bag)
        record.update(status='ok', labels=labels, features=features.scalars,
                      psd={k: v.tolist() for k, v in features.psd.items()},
                      frequencies_hz=features.frequencies_hz.tolist(), truth=truth,
                      wall_time_s=time.perf_counter() - start)
        tmp = folder / f'.{DONE}.tmp'
        write_json(tmp, record)
        tmp.replace(folder / DONE)
        return record
    except Exception as exc:   # a failing case is recorded and the data set goes on
        record.update(status='failed', error=f'{type(exc).__name__}: {exc}',
                      traceback=traceback.format_exc(limit=5))
        return record


def _truth(bag: Path, name: str) -> dict[str, Any]:
    """Return the exact topics' peaks of a bag (the truth columns of ``sweep.csv``)."""
    from ttb_sim.io.streams import load_streams
    from ttb_sim.report.metrics import bag_metrics
    row = case_row({'case': name, 'speed_kmh': None, 'status': 'ok',
                    'metrics': bag_metrics(load_streams(bag, name))})
    return {k: v for k, v in row.items() if k not in SWEEP_ONLY}
