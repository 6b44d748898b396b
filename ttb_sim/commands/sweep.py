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

from concurrent.futures import as_completed, Future, ProcessPoolExecutor
import csv
import json
import logging
import multiprocessing
import os
from pathlib import Path
import signal
import sys
import threading
import time
from typing import Any, Callable, Iterator, Sequence

from ttb_sim.commands.signals import raise_stopped, signal_name, SignalHandlers, Stopped
from ttb_sim.commands.sweep_case import case_row, CaseSpec, is_finished, run_case
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.report.output import write_json

log = logging.getLogger(__name__)

EXIT_OK, EXIT_FAILURE = 0, 1
MAX_CASES = 10_000
"""Most cases one sweep accepts."""
SCHEDULER_TIMEOUT_S = 10.0
"""How long to wait for a Dask scheduler before giving up (exit 2)."""


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


def _start_worker(workers: int) -> None:
    """
    Worker initializer: Ctrl-C is the parent's to handle (it terminates the workers).

    With several workers each runs its compiled kernels on one thread: the cores are
    already shared out by the processes, and a kernel's second thread would only
    contend with another case (the results do not depend on the thread count).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if workers > 1:
        os.environ['NUMBA_NUM_THREADS'] = '1'


class _Local:
    """Cases in local worker processes (spawned, so each starts clean)."""

    def __init__(self, workers: int) -> None:
        self.pool = ProcessPoolExecutor(max_workers=workers,
                                        mp_context=multiprocessing.get_context('spawn'),
                                        initializer=_start_worker, initargs=(workers,))

    def submit(self, cases: Sequence[CaseSpec]) -> None:
        """Queue the cases (this starts the worker processes)."""
        self.futures: dict[Future[dict[str, Any]], CaseSpec] = {
            self.pool.submit(run_case, c): c for c in cases}

    def results(self) -> Iterator[tuple[CaseSpec, dict[str, Any]]]:
        """Yield (case, record) as cases finish."""
        for fut in as_completed(self.futures):
            yield self.futures[fut], _result(self.futures[fut], fut.result, fut.exception)

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)

    def stop(self) -> None:
        """Terminate the workers at once (their cases have no case.json: redone next time)."""
        for process in list(getattr(self.pool, '_processes', {}).values()):
            process.terminate()
        self.pool.shutdown(wait=False, cancel_futures=True)


class _Dask:
    """Cases on a Dask distributed cluster (the workers need ttb_sim and the out folder)."""

    def __init__(self, address: str) -> None:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ScenarioError("--scheduler needs Dask: pip install 'ttb_sim[dask]' (or "
                                "pip install 'dask[distributed]')") from None
        try:
            self.client = Client(address, timeout=SCHEDULER_TIMEOUT_S,
                                 set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise ScenarioError(f'--scheduler {address!r} is not reachable within '
                                f'{SCHEDULER_TIMEOUT_S:g} s ({type(exc).__name__}: {exc}); '
                                'give the address of a running dask scheduler, e.g. '
                                'tcp://host:8786') from None
        self.futures: list[Any] = []
        self.by_key: dict[Any, CaseSpec] = {}
        workers = self.client.scheduler_info().get('workers', {})
        log.info('Dask scheduler %s with %d workers', address, len(workers))

    def submit(self, cases: Sequence[CaseSpec]) -> None:
        """Send the cases to the scheduler."""
        keys = [f'ttb-sim-{c.name}-{os.getpid()}-{time.time_ns()}' for c in cases]
        self.futures = self.client.map(run_case, list(cases), pure=False, key=keys)
        self.by_key = {f.key: c for f, c in zip(self.futures, cases)}

    def results(self) -> Iterator[tuple[CaseSpec, dict[str, Any]]]:
        """Yield (case, record) as cases finish."""
        from dask.distributed import as_completed as dask_completed
        for fut in dask_completed(self.futures, loop=self.client.loop):
            case = self.by_key[fut.key]
            yield case, _result(case, fut.result, fut.exception)

    def close(self) -> None:
        self.client.close()

    def stop(self) -> None:
        """Cancel the cases still queued or running on the cluster, and disconnect."""
        if self.futures:
            self.client.cancel(list(self.futures))
        self.client.close()


def _result(case: CaseSpec, result: Callable[[], dict[str, Any]],
            exception: Callable[[], BaseException | None]) -> dict[str, Any]:
    """Return a case's record, or a failed record when its worker died."""
    error = exception()
    if error is None:
        return result()
    return {'case': case.name, 'speed_kmh': case.speed_kmh, 'seed': case.seed,
            'status': 'failed', 'error': f'worker lost: {type(error).__name__}: {error}'}


def sweep(scenario: str, *, speeds_kmh: str, seeds: int | None = None,
          overrides: Sequence[str] = (), out: str | Path | None = None,
          workers: int | None = None, scheduler: str | None = None,
          duration: float | None = None, storage: str = 'mcap', force: bool = False) -> int:
    """Run ``ttb-sim sweep``; return 0 when every case succeeded, 1 otherwise."""
    start = time.perf_counter()
    speeds = parse_speeds(speeds_kmh)
    if workers is not None and scheduler is not None:
        raise ScenarioError('give either --workers (local processes) or --scheduler (Dask), '
                            'not both')
    if workers is not None and not 1 <= workers <= 1024:
        raise ScenarioError(f'--workers {workers} must be from 1 to 1024')
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
    runner: _Local | _Dask | None = None
    if todo:
        runner = _Dask(scheduler) if scheduler else \
            _Local(workers or min(len(todo), os.cpu_count() or 1))
    target.mkdir(parents=True, exist_ok=True)
    write_json(target / 'sweep.json', {'settings': settings, 'speeds_kmh': speeds,
                                       'seeds': seeds, 'cases': [c.name for c in cases]})
    where = f'Dask scheduler {scheduler}' if scheduler else \
        f'{workers or min(len(todo), os.cpu_count() or 1)} local worker process(es)'
    if todo:
        print(f'ttb-sim: sweep: running {len(todo)} cases on {where}', file=sys.stderr)
    main_thread = threading.current_thread() is threading.main_thread()
    handlers = SignalHandlers()
    if main_thread:   # workers start with Ctrl-C ignored (inherited): the parent handles it
        handlers.install(signal.SIG_IGN, (signal.SIGINT,))
    try:
        if runner is not None:
            runner.submit(todo)
        if main_thread:
            handlers.install(raise_stopped)
        for i, (case, record) in enumerate(runner.results() if runner else [], start=1):
            records[case.name] = record
            detail = f'in {record.get("wall_time_s", 0.0) or 0.0:.1f} s' \
                if record['status'] == 'ok' else f'{record["status"]}: {record.get("error")}'
            print(f'ttb-sim: sweep: [{i}/{len(todo)}] {case.name} {record["status"]} {detail}',
                  file=sys.stderr, flush=True)
        if runner is not None:
            runner.close()
    except Stopped as stop:
        if runner is not None:
            runner.stop()
        print(f'ttb-sim: stopped by {signal_name(stop.signum)}; {len(records)} of {len(cases)} '
              f'cases finished in {target} (rerun the same command to resume)', file=sys.stderr)
        return 128 + stop.signum
    finally:
        handlers.restore()
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
