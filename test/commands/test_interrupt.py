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
Ctrl-C (SIGINT) and SIGTERM at any moment of ``ttb-sim run``, and the destination checks.

A signal during set-up (loading, building the model) stops the run at once with
one line on stderr and exit 128 + signal, and nothing is written; a signal
while recording closes the bag (test_cli.py). A bad ``--out`` is refused before
the model is built. The runs are subprocesses of the real command line.
"""

import json
import os
from pathlib import Path
import signal
import subprocess
import sys
import time

import pytest
from ttb_sim.cli import main
from ttb_sim.config import builtin_scenarios
from ttb_sim.io.bag import check_destination

ROOT = Path(__file__).resolve().parents[2]
HANG_BOUND = 120.0
"""Seconds after which a run is taken as hung (a bound, not a speed check)."""


def _start(*args: str) -> subprocess.Popen:
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(
        [str(ROOT), os.environ.get('PYTHONPATH', '')])}
    return subprocess.Popen([sys.executable, '-m', 'ttb_sim.cli', '-v', 'run', *args],
                            stderr=subprocess.PIPE, stdout=subprocess.PIPE, env=env,
                            text=True)


@pytest.mark.parametrize('sig, code', [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_during_set_up_writes_nothing(tmp_path: Path, sig: int, code: int) -> None:
    out = tmp_path / 'bag'
    proc = _start('paper_ttbi', '--duration', '0.01', '--out', str(out))
    assert proc.stderr is not None
    deadline = time.monotonic() + HANG_BOUND
    seen = []
    for line in proc.stderr:  # wait until the model is being built
        seen.append(line)
        if 'set-up: building' in line or time.monotonic() > deadline:
            break
    proc.send_signal(sig)
    rest = proc.communicate(timeout=HANG_BOUND)[1]
    err = ''.join(seen) + rest
    assert proc.returncode == code, err
    name = signal.Signals(sig).name
    assert f'ttb-sim: stopped by {name} during set-up; nothing written\n' in err
    assert 'Traceback' not in err
    assert not out.exists()


@pytest.mark.parametrize('delay', [0.6, 1.2, 1.8, 2.6])
def test_ctrl_c_at_any_moment_leaves_nothing_half_written(tmp_path: Path, delay: float) -> None:
    """Whatever the moment: exit 130 (or 0 if done), no traceback, no bag or a whole one."""
    out = tmp_path / 'bag'
    proc = _start('moving_force_beam', '--set', 'solver.duration=0.3', '--out', str(out))
    time.sleep(delay)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=HANG_BOUND)
    assert proc.returncode in (0, 130), err
    assert 'Traceback' not in err
    if proc.returncode == 130:
        assert err.strip().splitlines()[-1].startswith('ttb-sim: stopped by SIGINT')
    if out.exists():
        summary = json.loads((out / 'summary.json').read_text())
        assert summary['status'] in ('ok', 'interrupted')
        assert (out / 'metadata.yaml').is_file()


@pytest.mark.parametrize('where, words', [
    ('file/bag', 'which is a file, not a directory'),
    ('existing', 'exists; refusing to overwrite'),
])
def test_a_bad_destination_is_refused_before_building(tmp_path: Path, capsys, where: str,
                                                      words: str) -> None:
    (tmp_path / 'file').write_text('x')
    (tmp_path / 'existing').mkdir()
    start = time.process_time()
    assert main(['run', 'paper_ttbi', '--duration', '0.01', '--out',
                 str(tmp_path / where)]) == 2
    assert time.process_time() - start < 5.0  # refused before building (which takes more)
    err = capsys.readouterr().err
    assert words in err and err.count('\n') == 1


def test_an_unwritable_parent_is_refused(tmp_path: Path) -> None:
    locked = tmp_path / 'locked'
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK) and os.geteuid() == 0:
            target = Path('/proc/ttb_sim_bag')  # not writable even for root
            if not Path('/proc').is_dir():
                pytest.skip('running as root without /proc: nothing is unwritable')
        else:
            target = locked / 'bag'
        with pytest.raises(Exception, match='is not writable'):
            check_destination(target, 'mcap')
    finally:
        locked.chmod(0o700)


def test_missing_parents_are_made(tmp_path: Path, capsys) -> None:
    out = tmp_path / 'a' / 'b' / 'bag'
    assert main(['run', 'moving_force_beam', '--duration', '0.01', '--out', str(out)]) == 0
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['wall_time'] == pytest.approx(summary['setup_time']
                                                 + summary['stepping_time'])
    assert summary['setup_time'] > 0.0


@pytest.mark.parametrize('argv, expected', [(['scenarios'], 0),
                                            (['run', '/nonexistent.yaml'], 2)])
def test_the_program_ends_when_its_verb_returns(tmp_path: Path, argv: list[str],
                                                expected: int) -> None:
    """
    No interpreter finalisation after the verb: its exit code, complete output, no window.

    Finalisation restores the default signal dispositions and tears down the extension
    modules; a Ctrl-C there killed a finished run by SIGINT (exit -2). The program now
    ends with os._exit once the verb has returned and the output is flushed, so atexit
    hooks never run, and the one-line handler is in place until that moment.
    """
    code = ('import atexit, signal, sys\n'
            'atexit.register(lambda: print("finalised", file=sys.stderr))\n'
            f'sys.argv = ["ttb-sim", *{argv!r}]\n'
            'from ttb_sim.cli import entry\n'
            'entry()\n')
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(
        [str(ROOT), os.environ.get('PYTHONPATH', '')])}
    done = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          env=env, timeout=HANG_BOUND, check=False)
    assert done.returncode == expected, done.stderr
    assert 'finalised' not in done.stderr
    if expected == 0:  # the output was flushed before the process ended
        assert all(name in done.stdout for name in builtin_scenarios())
