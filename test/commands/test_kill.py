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
``ttb-sim run`` killed by SIGKILL: ``analyze`` reads the bag it left, ``recover`` closes it.

The run is a subprocess of the real command line, killed once its storage file
has grown past 2 MiB (polled: no timing is assumed, the timeout only bounds a
hang). The messages read back must be the first messages of a complete run of
the same command, topic by topic, with the same stamps and bytes (exact: the
same command gives the same bits, in either storage).
"""

from __future__ import annotations

from collections import defaultdict
import os
from pathlib import Path
import signal
import subprocess
import sys

from polling import poll_until   # noqa: I100 - the helper in test/
import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.cli import main
from ttb_sim.io.salvage import salvage

ROOT = Path(__file__).resolve().parents[2]
RUN = ('ten_span_train', '--duration', '4')
"""About 9 MB of bag; the kill comes after 2 MiB, well before the end."""
GROWN = 2 * 2 ** 20
HANG_BOUND = 120.0
"""Seconds after which the run is taken as hung (a bound, not a speed check)."""


def _cli(*args: str, **kwargs) -> subprocess.Popen:
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(
        [str(ROOT), os.environ.get('PYTHONPATH', '')])}
    return subprocess.Popen([sys.executable, '-m', 'ttb_sim.cli', *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kwargs)


def _by_topic(items) -> dict[str, list[tuple[int, bytes]]]:
    out = defaultdict(list)
    for topic, stamp, data in items:
        out[topic].append((stamp, bytes(data)))
    return dict(out)


@pytest.fixture(scope='module')
def complete(tmp_path_factory) -> dict[str, list[tuple[int, bytes]]]:
    """Return the messages of a complete run of the command, by topic."""
    out = tmp_path_factory.mktemp('complete') / 'bag'
    proc = _cli('run', *RUN, '--out', str(out))
    _, err = proc.communicate(timeout=HANG_BOUND)
    assert proc.returncode == 0, err
    with AnyReader([out]) as reader:
        return _by_topic((c.topic, t, raw) for c, t, raw in reader.messages())


def _killed(tmp_path: Path, storage: str) -> Path:
    out = tmp_path / 'killed'
    proc = _cli('run', *RUN, '--storage', storage, '--out', str(out))
    file = out / f'killed.{"mcap" if storage == "mcap" else "db3"}'

    def grown() -> bool:
        return file.exists() and file.stat().st_size > GROWN

    def ended() -> str:
        return f'the run ended before it was killed: {proc.returncode}' \
            if proc.poll() is not None else ''
    try:
        poll_until(grown, HANG_BOUND, abort=ended)
        proc.send_signal(signal.SIGKILL)
        proc.communicate(timeout=HANG_BOUND)
    finally:
        proc.kill()
    assert proc.returncode == -signal.SIGKILL
    assert sorted(p.name for p in out.iterdir() if not p.name.endswith('-journal')) == \
        [file.name]                      # no metadata.yaml, no summary.json: as a kill leaves
    return out


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_killed_run_is_analysed_and_recovered(complete, tmp_path, capsys, storage):
    bag = _killed(tmp_path, storage)
    before = {p.name: p.read_bytes() for p in bag.iterdir()}
    found = salvage(next(p for p in bag.iterdir() if p.suffix in ('.mcap', '.db3')))
    part = _by_topic((c.topic, t, d) for c, t, d in found.messages())
    assert set(part) == set(complete)            # every topic's connection survived
    for topic, items in part.items():
        assert items == complete[topic][:len(items)], topic
    counts = [len(v) for k, v in part.items() if k != '/ttb_sim/labels']   # one at t = 0
    assert min(counts) > 0 and max(counts) - min(counts) <= 1   # whole frames, one split
    assert len(part['/ttb_sim/labels']) == 1
    # what reached the disk is read back but for the open chunk or commit (1 MiB at most)
    assert sum(len(d) for items in part.values() for _, d in items) > GROWN - 2 ** 20 - 2 ** 18

    assert main(['analyze', str(bag), '--out', str(tmp_path / 'analysis')]) == 0
    assert (tmp_path / 'analysis' / 'metrics.json').is_file()
    recovered = tmp_path / 'recovered'
    assert main(['recover', str(bag), '--out', str(recovered)]) == 0
    line = capsys.readouterr().out.strip().splitlines()[-1]
    total = sum(len(v) for v in part.values())
    assert line.startswith(f'{recovered}: {total} messages recovered from ')
    with AnyReader([recovered]) as reader:
        assert _by_topic((c.topic, t, raw) for c, t, raw in reader.messages()) == part
    assert {p.name: p.read_bytes() for p in bag.iterdir() if p.name != 'analysis'} == before
    assert main(['recover', str(bag), '--out', str(recovered)]) == 2   # never overwritten
    assert 'exists; refusing to overwrite' in capsys.readouterr().err


def test_recover_refuses_in_one_line(tmp_path, capsys):
    killed = tmp_path / 'early'
    killed.mkdir()
    (killed / 'early.mcap').write_bytes(b'\x89MCAP0\r\n')     # killed before a chunk
    (tmp_path / 'plain').mkdir()
    for args, message in (((str(killed),), 'nothing to recover in'),
                          ((str(tmp_path / 'plain'),), 'is not a rosbag2 directory'),
                          ((str(tmp_path / 'missing'),), 'does not exist')):
        assert main(['recover', *args]) == 2, args
        err = capsys.readouterr().err
        assert err.startswith('ttb-sim: error: ') and message in err, err
        assert err.count('\n') == 1
    assert not (tmp_path / 'early-recovered').exists()
