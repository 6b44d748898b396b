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

"""`ttb-sim` exit codes, refusals that leave nothing behind, and clean interruption."""

import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

from mcap_ros2.reader import read_ros2_messages
import pytest
from ttb_sim.cli import main


@pytest.mark.parametrize('args, match', [
    (['--set', 'bridge.spam=1'], "unknown key 'bridge.spam'"),
    (['--set', 'train.speed_kmh=abc'], 'expected a number'),
    (['--set', 'bridge.span_length=-3'], 'bridge.span_length = -3.0 is out of range'),
    (['--speed-kmh', '0'], 'train.speed_kmh = 0.0 is out of range'),
])
def test_bad_input_exit_2_nothing_written(tmp_path: Path, capsys, args, match):
    out = tmp_path / 'out'
    assert main(['run', 'moving_force_beam', '--out', str(out), *args]) == 2
    assert match in capsys.readouterr().err
    assert not out.exists()


def test_a_section_given_to_set_is_named_as_a_section(tmp_path: Path, capsys):
    out = tmp_path / 'out'
    assert main(['run', 'moving_force_beam', '--out', str(out), '--set', 'train=5']) == 2
    assert capsys.readouterr().err == (
        'ttb-sim: error: train = 5: train is a section, not a value; set one of its keys, e.g. '
        'train.speed_kmh (its 12 keys: train.vehicle, train.speed_kmh, train.start_position, '
        'train.axle_offsets, ...; see `ttb-sim scenarios --keys`)\n')
    assert not out.exists()


def test_unreadable_scenario_exit_2(tmp_path: Path, capsys):
    assert main(['run', str(tmp_path / 'missing.yaml'), '--out', str(tmp_path / 'o')]) == 2
    assert 'does not exist' in capsys.readouterr().err
    assert not (tmp_path / 'o').exists()


def test_bad_storage_is_usage_error(tmp_path: Path):
    with pytest.raises(SystemExit) as exc:
        main(['run', 'moving_force_beam', '--storage', 'zip', '--out', str(tmp_path / 'o')])
    assert exc.value.code == 2


@pytest.mark.parametrize('args, message', [
    (['run', 'moving_force_beam', '--storage', 'zip'], 'argument --storage: invalid choice: '
     "'zip' (choose from 'mcap', 'sqlite3'); see `ttb-sim run --help`"),
    ([], 'the following arguments are required: COMMAND; see `ttb-sim --help`'),
    (['run', 'x', '--duration', 'abc'], "argument --duration: invalid float value: 'abc'; see "
     '`ttb-sim run --help`'),
    (['sweep', 'x', '--speeds-kmh', '1', '--workers', '1', '--scheduler', 'y'],
     'argument --scheduler: not allowed with argument --workers; see `ttb-sim sweep --help`'),
])
def test_usage_errors_are_one_line(capsys, args, message):
    with pytest.raises(SystemExit) as exc:
        main(args)
    assert exc.value.code == 2
    assert capsys.readouterr().err == f'ttb-sim: error: {message}\n'


def test_a_path_error_a_verb_did_not_check_is_one_line(tmp_path: Path, capsys):
    """The command line's last net: an OSError for a path given is exit 2, one line."""
    (tmp_path / 'file.txt').write_text('x')
    out = tmp_path / 'file.txt' / 'sweep'
    assert main(['sweep', 'moving_force_beam', '--speeds-kmh', '1', '--out', str(out)]) == 2
    assert capsys.readouterr().err == f'ttb-sim: error: {str(out)!r}: Not a directory\n'


def test_refuses_to_overwrite(tmp_path: Path, capsys):
    out = tmp_path / 'exists'
    out.mkdir()
    (out / 'keep.txt').write_text('mine')
    assert main(['run', 'moving_force_beam', '--out', str(out)]) == 2
    assert 'refusing to overwrite' in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ['keep.txt']


def test_divergence_exit_1_bag_readable(tmp_path: Path, capsys):
    out = tmp_path / 'div'
    code = main(['run', 'moving_force_beam', '--out', str(out),
                 '--set', 'solver.divergence_limit=1e-5'])
    assert code == 1
    assert 'diverged' in capsys.readouterr().err
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['status'] == 'diverged' and summary['frames'] > 0
    n = sum(1 for _ in read_ros2_messages(str(next(out.glob('*.mcap'))),
                                          topics=['/ttb_sim/bridge/span01/midspan']))
    assert n == summary['frames']


def test_scenarios_and_keys_listing(capsys):
    assert main(['scenarios']) == 0
    listing = capsys.readouterr().out
    assert 'moving_force_beam' in listing and 'sprung_mass_beam' in listing
    assert main(['scenarios', '--keys']) == 0
    assert 'bridge.span_length' in capsys.readouterr().out


def test_validate_rejects_unknown_case(capsys):
    assert main(['validate', 'V99']) == 2
    assert 'unknown validation case' in capsys.readouterr().err


@pytest.mark.parametrize('sig, code', [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_closes_bag(tmp_path: Path, sig, code):
    """A long run stopped by a signal exits non-zero and leaves a readable bag."""
    out = tmp_path / 'long'
    proc = subprocess.Popen(
        [sys.executable, '-m', 'ttb_sim.cli', 'run', 'ten_span_train', '--out', str(out),
         '--duration', '1000'], stderr=subprocess.PIPE, env={**os.environ})
    deadline = time.monotonic() + 60
    while not list(out.glob('*.mcap')) and time.monotonic() < deadline:
        time.sleep(0.1)
    time.sleep(1.0)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == code, err.decode()
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['status'] == 'interrupted'
    mcap_file = next(out.glob('*.mcap'))
    n = sum(1 for _ in read_ros2_messages(str(mcap_file),
                                          topics=['/ttb_sim/bridge/span01/midspan']))
    assert n == summary['frames'] > 0
