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
The ``sweep`` verb: a scenario at several speeds and irregularity seeds, in parallel.

Cases (speed x seed) run in local worker processes (``--workers``, default the
number of cores) or on a Dask distributed cluster (``--scheduler ADDRESS``;
``pip install '.[dask]'``).  Each case writes ``DIR/<case>/`` (bag, summary,
metrics, ``case.json``, see :mod:`ttb_sim.commands.sweep_case`); the sweep then
writes ``DIR/sweep.csv`` (one row per case) and figures of the peaks against
speed, and ``DIR/sweep.json`` with its settings.

Resuming: a rerun with the same ``--out`` skips the cases whose ``case.json``
says ok and redoes the others (half-written or failed).  A different scenario
or ``--set``/``--duration`` for the same folder is refused.  A failing case is
reported and the others go on; the exit code is 1 when any case failed.
All arguments, every case's scenario and the scheduler are checked before any
case starts.
"""

from __future__ import annotations

import csv
import json
import logging
from pathlib import Path
import sys
import time
from typing import Any, Sequence

from ttb_sim.commands.pool import check_workers, make_pool, run_cases
from ttb_sim.commands.signals import signal_name
from ttb_sim.commands.sweep_case import case_row, CaseSpec, is_finished, run_case
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.report.output import write_json

log = logging.getLogger(__name__)

EXIT_OK, EXIT_FAILURE = 0, 1
MAX_CASES = 10_000
"""Most cases one sweep accepts."""


def parse_speeds(text: str) -> list[float]:
    """Parse ``--speeds-kmh`` ('250,300,350'): positive finite numbers, no duplicates."""
    speeds = []
    for part in str(text).split(','):
        try:
            value = float(part)
        except ValueError:
            raise ScenarioError(f'--speeds-kmh {text!r}: {part.strip()!r} is not a number; '
                                'give comma-separated speeds in km/h, e.g. 250,300,350') from None
        if not (0.0 < value <= 10000.0):
            raise ScenarioError(f'--speeds-kmh {text!r}: {value:g} is outside (0, 10000] km/h')
        speeds.append(value)
    if len(set(speeds)) != len(speeds):
        raise ScenarioError(f'--speeds-kmh {text!r} repeats a speed')
    return speeds


def _case_name(speed: float, seed: int | None) -> str:
    return f'v{speed:g}' + ('' if seed is None else f'_seed{seed}')


def plan_cases(scenario: str, speeds: Sequence[float], seeds: int | None,
               overrides: Sequence[str], duration: float | None, out: Path,
               storage: str = 'mcap', force: bool = False) -> list[CaseSpec]:
    """Return the cases of a sweep, each scenario validated (ScenarioError before any run)."""
    if seeds is not None and not (isinstance(seeds, int) and 1 <= seeds <= MAX_CASES):
        raise ScenarioError(f'--seeds {seeds!r} must be an integer from 1 to {MAX_CASES}')
    seed_list: list[int | None] = list(range(1, seeds + 1)) if seeds else [None]
    if len(speeds) * len(seed_list) > MAX_CASES:
        raise ScenarioError(f'{len(speeds)} speeds x {len(seed_list)} seeds exceed the '
                            f'{MAX_CASES} cases of one sweep')
    cases = []
    for speed in speeds:
        for seed in seed_list:
            name = _case_name(speed, seed)
            spec = CaseSpec(name, str(out / name), str(scenario), tuple(overrides), speed, seed,
                            duration, storage, force)
            load_scenario(spec.scenario, spec.overrides, spec.values())   # validates
            cases.append(spec)
    return cases


def _check_settings(out: Path, settings: dict[str, Any]) -> None:
    """Refuse a folder that holds a sweep of other settings, or is not a sweep at all."""
    if out.exists() and not out.is_dir():
        raise ScenarioError(f'--out {str(out)!r} is a file; give a folder for the sweep')
    saved = out / 'sweep.json'
    if saved.is_file():
        try:
            previous = json.loads(saved.read_text()).get('settings', {})
        except (OSError, ValueError, AttributeError):
            previous = {}
        if previous and previous != settings:
            changed = sorted(k for k in set(previous) | set(settings)
                             if previous.get(k) != settings.get(k))
            raise ScenarioError(f'--out {str(out)!r} holds a sweep with other settings '
                                f'({", ".join(changed)}); give a new folder to sweep these')
    elif out.is_dir() and any(p for p in out.iterdir() if not p.name.startswith('v')):
        raise ScenarioError(f'--out {str(out)!r} is a non-empty folder that is not a sweep '
                            '(no sweep.json); give a new or empty folder')


def _lost(case: CaseSpec, error: BaseException) -> dict[str, Any]:
    """Return the failed record of a case whose worker died."""
    return {'case': case.name, 'speed_kmh': case.speed_kmh, 'seed': case.seed,
            'status': 'failed', 'error': f'worker lost: {type(error).__name__}: {error}'}


def sweep(scenario: str, *, speeds_kmh: str, seeds: int | None = None,
          overrides: Sequence[str] = (), out: str | Path | None = None,
          workers: int | None = None, scheduler: str | None = None,
          duration: float | None = None, storage: str = 'mcap', force: bool = False) -> int:
    """Run ``ttb-sim sweep``; return 0 when every case succeeded, 1 otherwise."""
    start = time.perf_counter()
    speeds = parse_speeds(speeds_kmh)
    check_workers(workers, scheduler)
    name = load_scenario(scenario, overrides).name
    target = Path(out) if out is not None else Path('runs') / f'sweep-{name}'
    settings = {'scenario': str(scenario), 'overrides': list(overrides), 'duration': duration,
                'storage': storage}
    _check_settings(target, settings)
    cases = plan_cases(scenario, speeds, seeds, overrides, duration, target, storage, force)
    done = [c for c in cases if is_finished(Path(c.folder))]
    todo = [c for c in cases if c not in done]
    records: dict[str, dict[str, Any]] = {}
    for c in done:
        records[c.name] = json.loads((Path(c.folder) / 'case.json').read_text())
    if done:
        print(f'ttb-sim: sweep: {len(done)} of {len(cases)} cases already finished, skipped '
              f'({", ".join(c.name for c in done)})', file=sys.stderr)
    pool = make_pool(run_case, len(todo), workers, scheduler) if todo else None
    target.mkdir(parents=True, exist_ok=True)
    write_json(target / 'sweep.json', {'settings': settings, 'speeds_kmh': speeds,
                                       'seeds': seeds, 'cases': [c.name for c in cases]})
    if pool is not None:
        stop = run_cases(pool, todo, _lost, 'sweep',
                         lambda case, record: records.__setitem__(case.name, record))
        if stop is not None:
            print(f'ttb-sim: stopped by {signal_name(stop.signum)}; {len(records)} of '
                  f'{len(cases)} cases finished in {target} (rerun the same command to '
                  'resume)', file=sys.stderr)
            return 128 + stop.signum
    rows = [case_row(records[c.name]) for c in cases if c.name in records]
    _write_csv(target / 'sweep.csv', rows)
    from ttb_sim.report.sweep_figures import sweep_figures
    figures = sweep_figures(rows, target)
    failed = [r['case'] for r in rows if r['status'] != 'ok']
    print(f'{target}: {len(cases)} cases ({len(done)} skipped as finished, '
          f'{len(todo) - len(failed)} run, {len(failed)} failed), sweep.csv, '
          f'{len(figures)} figures ({time.perf_counter() - start:.1f} s)')
    if failed:
        print(f'ttb-sim: sweep: failed cases: {", ".join(failed)} (rerun the same command to '
              'retry them)', file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK


def _write_csv(path: Path, rows: Sequence[dict[str, Any]]) -> None:
    """Write the aggregate table atomically (columns: the union of the rows' keys)."""
    columns: list[str] = []
    for row in rows:
        columns.extend(k for k in row if k not in columns)
    tmp = path.with_name(f'.{path.name}.tmp')
    with tmp.open('w', newline='') as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: '' if row.get(k) is None else row.get(k) for k in columns})
    tmp.replace(path)
