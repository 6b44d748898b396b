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
The ``dataset`` verb: labelled passages drawn from priors over scenario keys, as one table.

``ttb-sim dataset SPEC.yaml --out DIR [--n N] [--workers N | --scheduler ADDRESS]``
reads the spec (:mod:`ttb_sim.twin.spec`), draws the cases, checks them, and runs
them in local worker processes or on a Dask cluster (:mod:`ttb_sim.commands.pool`).
Each case writes ``DIR/<case>/`` (:mod:`ttb_sim.commands.dataset_case`); the verb
then writes ``DIR/dataset.parquet`` (one row per case: ``case``, ``index``,
``status``, ``error``, ``wall_time_s``, a column per prior key named as the key,
``labels.*``, ``features.*``, ``truth.*``, and a ``psd.<sensor>.<axis>`` list column
per channel on the grid stored in the table's metadata) and ``DIR/dataset.json``
(the spec, the grid, the case names).

Resuming: a rerun with the same spec and ``--out`` skips the cases whose
``case.json`` says ok and whose drawn values are the ones drawn now (a Sobol' or
random design with a larger ``--n`` keeps its first cases), and redoes the others.
A spec that differs in anything but ``n`` is refused for the same folder.  A failing
case is recorded (status, error) and the others go on; the exit code is 1 when any
case failed.
"""

from __future__ import annotations

import json
from pathlib import Path
import sys
import time
from typing import Any, Sequence

from ttb_sim.commands.dataset_case import DatasetCase, DONE, is_finished, run_dataset_case
from ttb_sim.commands.pool import check_workers, make_pool, run_cases
from ttb_sim.commands.signals import signal_name
from ttb_sim.errors import ScenarioError
from ttb_sim.io.table import flatten, write_table
from ttb_sim.report.output import write_json
from ttb_sim.twin.spec import DatasetSpec, read_spec

__all__ = ['dataset', 'plan_dataset']

EXIT_OK, EXIT_FAILURE = 0, 1
TABLE, SETTINGS = 'dataset.parquet', 'dataset.json'


def case_name(index: int) -> str:
    """Return the folder name of case ``index`` (``case00017``)."""
    return f'case{index:05d}'


def plan_dataset(spec: DatasetSpec, out: Path, force: bool = False) -> list[DatasetCase]:
    """Return the cases of a data set (the spec already checked)."""
    cases = []
    for i, values in enumerate(spec.draw()):
        cases.append(DatasetCase(
            case_name(i), i, str(out / case_name(i)), spec.scenario, spec.overrides,
            tuple(spec.case_values(values)), tuple(values.items()), spec.features,
            spec.keep_bags, spec.storage, force))
    return cases


def _settings(spec: DatasetSpec) -> dict[str, Any]:
    """Return what a folder's data set must share with a rerun (all of the spec but n)."""
    plain = spec.to_dict()
    plain.pop('n')
    return plain


def _check_folder(out: Path, settings: dict[str, Any]) -> None:
    """Refuse a folder that holds another data set, or is not a data set at all."""
    if out.exists() and not out.is_dir():
        raise ScenarioError(f'--out {str(out)!r} is a file; give a folder for the data set')
    saved = out / SETTINGS
    if saved.is_file():
        try:
            previous = json.loads(saved.read_text()).get('settings', {})
        except (OSError, ValueError, AttributeError):
            previous = {}
        if previous and previous != json.loads(json.dumps(settings)):
            changed = sorted(k for k in set(previous) | set(settings)
                             if previous.get(k) != json.loads(json.dumps(settings.get(k))))
            raise ScenarioError(f'--out {str(out)!r} holds a data set of another spec '
                                f'({", ".join(changed)} differ); give a new folder')
    elif out.is_dir() and any(p for p in out.iterdir() if not p.name.startswith('case')):
        raise ScenarioError(f'--out {str(out)!r} is a non-empty folder that is not a data set '
                            f'(no {SETTINGS}); give a new or empty folder')


def _finished(case: DatasetCase) -> dict[str, Any] | None:
    """Return a finished case's record when its drawn values are this case's, else None."""
    folder = Path(case.folder)
    if not is_finished(folder):
        return None
    record = json.loads((folder / DONE).read_text())
    same = record.get('parameters') == json.loads(json.dumps(dict(case.parameters)))
    return record if same else None


def _lost(case: DatasetCase, error: BaseException) -> dict[str, Any]:
    """Return the failed record of a case whose worker died."""
    return {'case': case.name, 'index': case.index, 'parameters': dict(case.parameters),
            'status': 'failed', 'error': f'worker lost: {type(error).__name__}: {error}'}


def table_row(record: dict[str, Any], keys: Sequence[str]) -> dict[str, Any]:
    """Return a case's row: identity, status, parameters by key, labels, features, PSDs."""
    row: dict[str, Any] = {'case': record['case'], 'index': record['index'],
                           'status': record['status'], 'error': record.get('error', ''),
                           'wall_time_s': record.get('wall_time_s')}
    parameters = record.get('parameters', {})
    row.update({k: parameters.get(k) for k in keys})
    row.update(flatten(record.get('labels') or {}, 'labels.'))
    row.update(flatten(record.get('features') or {}, 'features.'))
    row.update(flatten(record.get('truth') or {}, 'truth.'))
    row.update({f'psd.{k}': v for k, v in (record.get('psd') or {}).items()})
    return row


def _need_pyarrow() -> None:
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        raise ScenarioError('ttb-sim dataset writes Parquet through pyarrow: pip install '
                            '"ttb_sim[twin]" (or pip install pyarrow)') from None


def dataset(spec_path: str | Path, *, out: str | Path | None = None, n: int | None = None,
            workers: int | None = None, scheduler: str | None = None,
            force: bool = False) -> int:
    """Run ``ttb-sim dataset``; return 0 when every case succeeded, 1 otherwise."""
    start = time.perf_counter()
    check_workers(workers, scheduler)
    _need_pyarrow()
    spec = read_spec(spec_path, n)
    target = Path(out) if out is not None else Path('runs') / f'dataset-{Path(spec_path).stem}'
    settings = _settings(spec)
    _check_folder(target, settings)
    cases = plan_dataset(spec, target, force)
    records: dict[str, dict[str, Any]] = {}
    for case in cases:
        record = _finished(case)
        if record is not None:
            records[case.name] = record
    todo = [c for c in cases if c.name not in records]
    if records:
        print(f'ttb-sim: dataset: {len(records)} of {len(cases)} cases already finished, '
              'skipped', file=sys.stderr)
    pool = make_pool(run_dataset_case, len(todo), workers, scheduler) if todo else None
    target.mkdir(parents=True, exist_ok=True)
    grid = spec.features.frequencies().tolist()
    write_json(target / SETTINGS, {'settings': settings, 'n': spec.n,
                                   'psd_frequencies_hz': grid,
                                   'cases': [c.name for c in cases]})
    if pool is not None:
        stop = run_cases(pool, todo, _lost, 'dataset',
                         lambda case, record: records.__setitem__(case.name, record))
        if stop is not None:
            print(f'ttb-sim: stopped by {signal_name(stop.signum)}; {len(records)} of '
                  f'{len(cases)} cases finished in {target} (rerun the same command to '
                  'resume)', file=sys.stderr)
            return 128 + stop.signum
    keys = [p.key for p in spec.priors]
    rows = [table_row(records[c.name], keys) for c in cases if c.name in records]
    write_table(target / TABLE, rows, {'spec': spec.to_dict(), 'psd_frequencies_hz': grid})
    failed = [r['case'] for r in rows if r['status'] != 'ok']
    print(f'{target}: {len(cases)} cases ({len(cases) - len(todo)} skipped as finished, '
          f'{len(todo) - len(failed)} run, {len(failed)} failed), {TABLE} '
          f'({time.perf_counter() - start:.1f} s)')
    if failed:
        print(f'ttb-sim: dataset: failed cases: {", ".join(failed[:20])}'
              f'{" ..." if len(failed) > 20 else ""} (rerun the same command to retry them)',
              file=sys.stderr)
        return EXIT_FAILURE
    return EXIT_OK
