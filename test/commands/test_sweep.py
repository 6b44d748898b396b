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
``ttb-sim sweep``: cases in local processes and on a real local Dask cluster, resuming, failures.

Short ``moving_force_beam`` cases (0.1 s) keep the file at seconds. The
aggregate table is checked against each case's bag read independently with
``ttb_sim.io.read_bag``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from ttb_sim.cli import main
from ttb_sim.commands import pool as pool_module
from ttb_sim.io.reader import read_bag

ARGS = ['sweep', 'moving_force_beam', '--duration', '0.1']


def rows_of(out: Path) -> dict[str, dict[str, str]]:
    with (out / 'sweep.csv').open() as fh:
        return {r['case']: r for r in csv.DictReader(fh)}


def test_local_sweep_resume_and_redo(tmp_path, capsys):
    out = tmp_path / 'sw'
    assert main([*ARGS, '--speeds-kmh', '200,300', '--seeds', '2', '--workers', '2',
                 '--out', str(out)]) == 0
    rows = rows_of(out)
    assert sorted(rows) == ['v200_seed1', 'v200_seed2', 'v300_seed1', 'v300_seed2']
    for name, row in rows.items():
        assert row['status'] == 'ok'
        bag = read_bag(out / name / 'bag', ['/ttb_sim/bridge/span01/midspan'])
        z = next(iter(bag.values()))['vector'][:, 2]
        assert float(row['girder_displacement_peak_m']) == pytest.approx(np.abs(z).max(),
                                                                         rel=1e-12)
    assert (out / 'sweep_peaks.png').stat().st_size > 10_000
    stamps = {n: (out / n / 'case.json').stat().st_mtime_ns for n in rows}
    capsys.readouterr()
    # a rerun skips every finished case
    assert main([*ARGS, '--speeds-kmh', '200,300', '--seeds', '2', '--out', str(out)]) == 0
    assert '4 of 4 cases already finished' in capsys.readouterr().err
    assert stamps == {n: (out / n / 'case.json').stat().st_mtime_ns for n in rows}
    # a half-written case (no case.json) is redone, and only it
    (out / 'v300_seed2' / 'case.json').unlink()
    (out / 'v300_seed2' / 'junk').write_text('half')
    assert main([*ARGS, '--speeds-kmh', '200,300', '--seeds', '2', '--workers', '1',
                 '--out', str(out)]) == 0
    err = capsys.readouterr().err
    assert '3 of 4 cases already finished' in err and 'running 1 cases' in err
    assert not (out / 'v300_seed2' / 'junk').exists()
    assert (out / 'v300_seed2' / 'case.json').is_file()
    # other settings for the same folder are refused
    assert main([*ARGS, '--speeds-kmh', '200', '--set', 'bridge.damping_ratio=0.01',
                 '--out', str(out)]) == 2
    assert 'other settings' in capsys.readouterr().err


def test_a_failing_case_is_reported_and_the_others_go_on(tmp_path, capsys):
    out = tmp_path / 'sw'
    out.mkdir()
    (out / 'v300').write_text('a file where the case folder should be')
    assert main([*ARGS, '--speeds-kmh', '200,300', '--workers', '2', '--out', str(out)]) == 1
    err = capsys.readouterr().err
    assert 'v300 failed' in err and 'failed cases: v300' in err
    rows = rows_of(out)
    assert rows['v200']['status'] == 'ok' and rows['v300']['status'] == 'failed'
    (out / 'v300').unlink()
    assert main([*ARGS, '--speeds-kmh', '200,300', '--workers', '1', '--out', str(out)]) == 0
    assert '1 of 2 cases already finished' in capsys.readouterr().err
    assert rows_of(out)['v300']['status'] == 'ok'


@pytest.mark.parametrize('args, message', [
    (['--speeds-kmh', '300,abc'], "'abc' is not a number"),
    (['--speeds-kmh', '300,300'], 'repeats a speed'),
    (['--speeds-kmh', '-5'], 'outside (0, 10000]'),
    (['--speeds-kmh', '300', '--seeds', '0'], '--seeds 0'),
    (['--speeds-kmh', '300', '--set', 'bridge.no_such_key=1'], 'no_such_key'),
    (['--speeds-kmh', '300', '--workers', '0'], '--workers 0'),
])
def test_bad_arguments_exit_2_before_anything(tmp_path, capsys, args, message):
    out = tmp_path / 'sw'
    assert main([*ARGS, *args, '--out', str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_unreachable_scheduler_exit_2(tmp_path, capsys, monkeypatch):
    pytest.importorskip('dask.distributed', reason="Dask is an extra: pip install '.[dask]'")
    monkeypatch.setattr(pool_module, 'SCHEDULER_TIMEOUT_S', 1.0)
    out = tmp_path / 'sw'
    assert main([*ARGS, '--speeds-kmh', '300', '--scheduler', 'tcp://127.0.0.1:9',
                 '--out', str(out)]) == 2
    assert 'not reachable' in capsys.readouterr().err
    assert not out.exists()


def test_sweep_on_a_local_dask_cluster(tmp_path):
    distributed = pytest.importorskip('dask.distributed',
                                      reason="Dask is an extra: pip install '.[dask]'")
    out = tmp_path / 'sw'
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        assert main([*ARGS, '--speeds-kmh', '200,300', '--seeds', '2', '--scheduler',
                     cluster.scheduler_address, '--out', str(out)]) == 0
    rows = rows_of(out)
    assert len(rows) == 4 and all(r['status'] == 'ok' for r in rows.values())
    pids = {json.loads((out / n / 'case.json').read_text())['pid'] for n in rows}
    assert len(pids) >= 1


def test_ctrl_c_stops_the_workers_in_one_line(tmp_path):
    """SIGINT while cases run: one line, exit 130, no traceback from the workers."""
    import os
    import signal
    import subprocess
    import sys
    import time
    out = tmp_path / 'sw'
    proc = subprocess.Popen([sys.executable, '-m', 'ttb_sim.cli', 'sweep', 'ten_span_train',
                             '--speeds-kmh', '250,300,350,400', '--workers', '2', '--out',
                             str(out)], stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    assert proc.stderr is not None
    line = proc.stderr.readline()
    assert 'running 4 cases' in line, line
    time.sleep(1.0)
    os.killpg(proc.pid, signal.SIGINT)   # as a terminal does: the whole process group
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert 'Traceback' not in err
    assert 'stopped by SIGINT' in err and 'rerun the same command to resume' in err
    assert not (out / 'sweep.csv').exists()
