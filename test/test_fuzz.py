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
Fuzzing the inputs of ``ttb-sim`` with hypothesis: nothing may crash, hang or half-write.

Six input kinds, each drawn by hypothesis from a strategy that mixes plausible
and hostile values (``fuzz_inputs.py``):

* scenario mappings (keys of the schema and junk keys, values in and out of
  range, wrong types, nested junk): 200 examples validated, 40 run;
* ``--set KEY=VALUE`` strings: 200 examples;
* YAML texts (keys, YAML punctuation, anchors, aliases, tags, deep brackets,
  odd scalars): 200 examples;
* irregularity CSV bytes (headers, numbers including nan, inf and huge ones,
  ragged rows, quotes, BOM and NUL bytes, random bytes): 200 examples read,
  30 run under a quarter car;
* command lines ``ttb-sim run BASE --set KEY=VALUE ...`` through
  :func:`ttb_sim.cli.main` in this process: every key of the schema (and
  sections and junk keys) with a value its declaration must refuse, and any
  value for the cheap keys, run for a few steps: 120 examples;
* argument vectors of every verb (its options, values, missing files, long
  names, link loops, broken and truncated bags, NUL bytes, junk), with the
  expensive step after each verb's argument checks replaced by a stub
  (building or stepping a model, the validation suite, a sweep's workers, a
  benchmark run, a bag's metrics): 300 examples; and a few refusals as
  subprocesses of ``python -m ttb_sim.cli``.

That is 1290 examples per run of this module: each test's id carries its count
and a line printed at the end of the module (visible with ``-s``) gives the
examples run and their outcomes. Every example must end like the command line
does: a scenario or profile, or a ScenarioError (exit 2) with a short message;
the command lines exit 0, 1 (divergence) or 2 with a one-line message and no
traceback, and a refusal writes nothing (the runs leave either no output
directory or a closed bag with ``summary.json``). Any other exception, a
message without the ``ttb-sim:`` prefix or a long message fails. Hangs are
bounded by the per-example ``deadline`` (a bound against hangs, not a speed
check: it is generous for a loaded 2-core machine) and, for the command line,
by an alarm that stops an example after :data:`HANG_SECONDS`. Runs stay tiny:
the base scenario is ``moving_force_beam`` or ``sprung_mass_beam`` and
``--duration`` is at most 5 ms at a step of at least 0.1 ms. The examples are
derandomised, so CI tries the same ones every time; raise ``max_examples``
locally to search further.
"""

from __future__ import annotations

import collections
import contextlib
from datetime import timedelta
import functools
import io
import json
import math
import os
from pathlib import Path
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from typing import Any, Callable, Iterator
from unittest import mock

from fuzz_inputs import (argvs, CHEAP_KEYS, csv_bytes, flow, key_values, KEYS, merge, nest,
                         options, refused_pairs, SET_VALUES, YAML_TOKENS)
from hypothesis import event, given, HealthCheck, settings, strategies as st
from hypothesis.control import currently_in_test_context
import pytest
from ttb_sim.cli import _parser, main
from ttb_sim.config import load_scenario, parse_override, Scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity import load_csv, TrackIrregularity
import yaml

MAX_MESSAGE = 2000
"""Longest acceptable error message (characters)."""

HANG_SECONDS = 60
"""An example of the command line still running after this long has hung (an alarm ends it)."""

VALIDATE = settings(max_examples=200, deadline=timedelta(seconds=30), derandomize=True,
                    database=None, suppress_health_check=[HealthCheck.too_slow])
RUN = settings(max_examples=40, deadline=timedelta(seconds=120), derandomize=True,
               database=None, suppress_health_check=[HealthCheck.too_slow])
RUN_CSV = settings(RUN, max_examples=30)
SET_CLI = settings(RUN, max_examples=120)
ARGV = settings(VALIDATE, max_examples=300)

EXAMPLES: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
"""Examples run and their outcomes per test, printed at the end of the module (``-s``)."""
_CURRENT = ['']


def examples(settings_: settings) -> Any:
    """Give a test its example count in its id: ``test_fuzz_yaml_texts[200-examples]``."""
    n = settings_.max_examples
    return pytest.mark.parametrize('examples', [n], ids=[f'{n}-examples'])


def counted(test: Callable[..., None]) -> Callable[..., None]:
    """Count the examples a hypothesis test runs (below ``@given``)."""
    @functools.wraps(test)
    def wrapper(*args: Any, **kwargs: Any) -> None:
        _CURRENT[0] = test.__name__
        EXAMPLES[test.__name__]['examples'] += 1
        test(*args, **kwargs)
    return wrapper


@pytest.fixture(scope='module', autouse=True)
def _report_examples() -> Iterator[None]:
    """Print the examples of every test and the module's time once it has run."""
    start = time.perf_counter()
    yield
    for name, counts in EXAMPLES.items():
        outcomes = ', '.join(f'{k}: {v}' for k, v in sorted(counts.items()) if k != 'examples')
        print(f'\nfuzz: {name}: {counts["examples"]} examples ({outcomes})', end='')
    total = sum(c['examples'] for c in EXAMPLES.values())
    print(f'\nfuzz: {total} examples in {time.perf_counter() - start:.1f} s')


# -- checks ----------------------------------------------------------------------------------

def _event(name: str) -> None:
    """Count an outcome in hypothesis' statistics (--hypothesis-show-statistics) and here."""
    if currently_in_test_context():
        event(name)
        EXAMPLES[_CURRENT[0]][name] += 1


def _validated(load: Any) -> Any:
    """Call a loader: it returns a result or raises ScenarioError with a short message."""
    try:
        result = load()
        _event('accepted')
        return result
    except ScenarioError as exc:
        _event('refused')
        message = str(exc)
        assert message and len(message) < MAX_MESSAGE, message[:500]
        return exc


def _cli(args: list[str], out: Path) -> int:
    """Run the command line; check the exit code, the message and the output directory."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(['run', *args, '--out', str(out)])
    text = err.getvalue()
    assert code in (0, 1, 2), text[-2000:]
    _event(f'exit {code}')
    problems = [line for line in text.splitlines() if line.startswith('ttb-sim: ')
                and not line.startswith('ttb-sim: plan: ')]
    if code == 0:
        assert not problems, text[-2000:]
    else:
        assert len(problems) == 1 and len(problems[0]) < MAX_MESSAGE, text[-2000:]
        assert problems[0].startswith('ttb-sim: error: ' if code == 2 else 'ttb-sim: failed: ')
    if code == 2:
        assert not out.exists(), 'exit 2 must write nothing'
    else:
        assert (out / 'metadata.yaml').is_file()
        summary = json.loads((out / 'summary.json').read_text())
        assert summary['status'] == ('ok' if code == 0 else 'diverged')
    return code


# -- scenario mappings -----------------------------------------------------------------------

@examples(VALIDATE)
@VALIDATE
@given(st.lists(key_values(), max_size=8))
@counted
def test_fuzz_scenario_mappings_validate(examples: int, pairs: list[tuple[str, Any]]) -> None:
    """Any mapping loads as a scenario or is refused with a short message."""
    data = nest(pairs)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_text(yaml.safe_dump(data), encoding='utf-8')
        result = _validated(lambda: load_scenario(path))
    assert isinstance(result, (Scenario, ScenarioError))


@examples(RUN)
@RUN
@given(st.lists(key_values(CHEAP_KEYS), max_size=6),
       st.sampled_from(['moving_force_beam', 'sprung_mass_beam']),
       st.floats(1e-4, 1e-3), st.floats(1e-4, 5e-3))
@counted
def test_fuzz_scenario_mappings_run(examples: int, pairs: list[tuple[str, Any]], base: str,
                                    dt: float, duration: float) -> None:
    """Mappings over the cheap keys of a one-span scenario, run for a few steps."""
    data = yaml.safe_load(Path(__file__).resolve().parents[1].joinpath(
        'config', f'{base}.yaml').read_text())
    for key, value in pairs:
        data = merge(data, nest([(key, value)]))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_text(yaml.safe_dump(data), encoding='utf-8')
        _cli([str(path), '--duration', repr(duration), '--set', f'solver.dt={dt!r}'],
             Path(tmp) / 'out' / 'bag')


# -- --set strings ---------------------------------------------------------------------------

@examples(VALIDATE)
@VALIDATE
@given(st.one_of(
    st.text(max_size=60),
    key_values().map(lambda kv: f'{kv[0]}={flow(kv[1])}'),
    st.tuples(st.sampled_from([k for k, _, _ in KEYS] + ['', 'nope', 'bridge', '.']),
              SET_VALUES).map(lambda kv: f'{kv[0]}={kv[1]}')))
@counted
def test_fuzz_set_strings(examples: int, text: str) -> None:
    """Any --set string is applied to moving_force_beam or refused with a short message."""
    result = _validated(lambda: load_scenario('moving_force_beam', [text]))
    assert isinstance(result, (Scenario, ScenarioError))
    try:
        parse_override(text)
    except ScenarioError:
        pass


# -- YAML texts ------------------------------------------------------------------------------

@examples(VALIDATE)
@VALIDATE
@given(st.one_of(st.lists(YAML_TOKENS, max_size=40).map(''.join), st.text(max_size=200),
                 st.integers(1, 6000).map(lambda n: 'a: ' + '[' * n + ']' * n)))
@counted
def test_fuzz_yaml_texts(examples: int, text: str) -> None:
    """Any text in a scenario file is loaded or refused with a short message, quickly."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_bytes(text.encode('utf-8', errors='surrogatepass'))
        result = _validated(lambda: load_scenario(path))
    assert isinstance(result, (Scenario, ScenarioError))


# -- irregularity CSV bytes ------------------------------------------------------------------

@examples(VALIDATE)
@VALIDATE
@given(csv_bytes())
@counted
def test_fuzz_irregularity_csv_bytes(examples: int, data: bytes) -> None:
    """Any bytes are read as a finite profile or refused with a short message."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.csv'
        path.write_bytes(data)
        result = _validated(lambda: load_csv(path))
    assert isinstance(result, (TrackIrregularity, ScenarioError))
    if isinstance(result, TrackIrregularity):
        assert math.isfinite(result.dx) and result.dx > 0


@examples(RUN_CSV)
@RUN_CSV
@given(csv_bytes(), st.floats(1e-4, 5e-3))
@counted
def test_fuzz_irregularity_csv_runs(examples: int, data: bytes, duration: float) -> None:
    """A quarter car on any CSV profile exits 0, 1 or 2, never half-writing."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.csv'
        path.write_bytes(data)
        _cli(['sprung_mass_beam', '--duration', repr(duration), '--set', 'solver.dt=1e-4',
              '--set', f'irregularity.file={path}'], Path(tmp) / 'bag')


def test_the_fuzz_strategies_reach_every_outcome() -> None:
    """The checks are not vacuous: these fixed cases give exit 0, 1 and 2."""
    with tempfile.TemporaryDirectory() as tmp:
        good = Path(tmp) / 'good.csv'
        good.write_text('\n'.join(f'{i * 0.25},0,0,0,0' for i in range(200)) + '\n')
        assert _cli(['sprung_mass_beam', '--duration', '0.002', '--set',
                     f'irregularity.file={good}'], Path(tmp) / 'a') == 0
        assert _cli(['moving_force_beam', '--duration', '0.005', '--set',
                     'solver.divergence_limit=1e-12'], Path(tmp) / 'b') == 1
        assert _cli(['sprung_mass_beam', '--duration', '0.002', '--set',
                     f'irregularity.file={tmp}'], Path(tmp) / 'c') == 2


@pytest.mark.parametrize('text', ['!!float ', 'a: &a [x]\nb: *a\n', 'a: ' + '[' * 40 + ']' * 40])
def test_known_hostile_texts_stay_refused(text: str) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'f.yaml'
        path.write_text(text)
        assert isinstance(_validated(lambda: load_scenario(path)), ScenarioError)


# -- the command line ------------------------------------------------------------------------

class _Accepted(BaseException):
    """Raised by the stub of a verb's expensive step: the verb accepted its arguments."""


class _Hung(BaseException):
    """Raised by the alarm: an example ran longer than HANG_SECONDS."""


EXPENSIVE = ('ttb_sim.sim.make_runner', 'ttb_sim.commands.validate.run_cases',
             'ttb_sim.commands.pool.LocalPool', 'ttb_sim.commands.pool.DaskPool',
             'ttb_sim.commands.bench.measure', 'ttb_sim.commands.bench.measure_isolated',
             'ttb_sim.sim.build_structure', 'ttb_sim.report.metrics.bag_metrics')
"""The first step of each verb after its argument checks: building or stepping a model,
the validation suite, a sweep's workers, a benchmark run, a bag's metrics."""


def _accept(*args: Any, **kwargs: Any) -> Any:
    raise _Accepted()


@contextlib.contextmanager
def _alarm(seconds: float) -> Iterator[None]:
    """Stop the block with _Hung after ``seconds`` (SIGALRM; the verbs handle INT and TERM)."""
    def ring(signum: int, frame: Any) -> None:
        raise _Hung(f'no answer after {seconds} s')
    previous = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def _main(argv: list[str], stub: bool) -> tuple[int | str, str]:
    """Run ``main(argv)`` in this process: (exit code, or 'accepted' at a stub; stderr)."""
    err = io.StringIO()
    with contextlib.ExitStack() as stack:
        if stub:
            for target in EXPENSIVE:
                stack.enter_context(mock.patch(target, _accept))
        stack.enter_context(contextlib.redirect_stderr(err))
        stack.enter_context(contextlib.redirect_stdout(io.StringIO()))
        stack.enter_context(_alarm(HANG_SECONDS))
        try:
            code: int | str = main(argv)
        except SystemExit as exc:   # the argument parser: usage errors, --help, --version
            code = exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 2
        except _Accepted:
            code = 'accepted'
    return code, err.getvalue()


def _tree(root: Path) -> dict[str, tuple[int, int]]:
    """Return every path under ``root`` with its size and time of change (0, 0 for folders)."""
    out = {}
    for folder, dirs, files in os.walk(root):   # (links are not followed)
        for name in dirs + files:
            path = Path(folder, name)
            info = path.lstat()
            out[str(path.relative_to(root))] = (0, 0) if name in dirs else \
                (info.st_size, info.st_mtime_ns)
    return out


def _answer(code: int | str, err: str, before: dict[str, tuple[int, int]],
            after: dict[str, tuple[int, int]]) -> None:
    """Check the property: exit 0/1/2 (or a stub reached); exit 2 is one line, writes nothing."""
    assert code in (0, 1, 2, 'accepted'), (code, err[-2000:])
    _event(f'exit {code}')
    assert 'Traceback' not in err, err[-2000:]
    lines = [line for line in err.splitlines() if line and not line.startswith('ttb-sim: plan: ')]
    if code == 2:
        assert len(lines) == 1 and lines[0].startswith('ttb-sim: error: '), err[-2000:]
        assert len(lines[0]) < MAX_MESSAGE
        assert after == before, 'exit 2 must write nothing'


@pytest.fixture(scope='module')
def template(tmp_path_factory: Any) -> Path:
    """Make a working folder: scenario files, a CSV, a link loop, a tiny bag, broken bags."""
    root = tmp_path_factory.mktemp('workspace')
    (root / 'file.txt').write_text('not a scenario\n')
    (root / 'empty.yaml').write_text('# nothing\n')
    (root / 'twice.yaml').write_text('name: a\nname: b\n')
    (root / 'bad.csv').write_text('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n1,abc,0,0,0\n')
    (root / 'dir').mkdir()
    (root / 'dir' / 'keep.txt').write_text('mine\n')
    (root / 'loop').symlink_to('loop')   # a link to itself: ELOOP
    with contextlib.redirect_stderr(io.StringIO()), contextlib.redirect_stdout(io.StringIO()):
        assert main(['run', 'moving_force_beam', '--duration', '0.005', '--out',
                     str(root / 'bag')]) == 0
    storage = next((root / 'bag').glob('*.mcap'))
    for name in ('broken_bag', 'cut_bag', 'killed_bag'):
        shutil.copytree(root / 'bag', root / name)
    (root / 'broken_bag' / 'metadata.yaml').write_text('rosbag2_bagfile_information: [\n')
    cut = root / 'cut_bag' / storage.name
    cut.write_bytes(cut.read_bytes()[:cut.stat().st_size // 2])
    (root / 'killed_bag' / 'metadata.yaml').unlink()
    return root


class _Workspace:
    """A working folder for the examples of one test, put back as it was after each example."""

    def __init__(self, root: Path, template: Path | None) -> None:
        self.root, self.template = root, template
        self._reset()

    def _reset(self) -> None:
        shutil.rmtree(self.root, ignore_errors=True)
        if self.template is None:
            self.root.mkdir(parents=True)
        else:
            shutil.copytree(self.template, self.root, symlinks=True)
        self.clean = _tree(self.root)

    @contextlib.contextmanager
    def example(self) -> Iterator[Path]:
        """Run an example with the folder as the working directory; undo what it wrote."""
        here = os.getcwd()
        os.chdir(self.root)
        try:
            yield self.root
        finally:
            os.chdir(here)
            if _tree(self.root) != self.clean:   # an accepted example wrote (a refusal may not)
                self._reset()


@pytest.fixture(scope='module')
def workspace(template: Path, tmp_path_factory: Any) -> _Workspace:
    """Return the working folder of the argument vectors: a copy of the template."""
    return _Workspace(tmp_path_factory.mktemp('argv') / 'w', template)


@pytest.fixture(scope='module')
def empty(tmp_path_factory: Any) -> _Workspace:
    """Return an empty working folder (the runs write their bags there)."""
    return _Workspace(tmp_path_factory.mktemp('set') / 'w', None)


@examples(SET_CLI)
@SET_CLI
@given(st.lists(st.one_of(key_values(CHEAP_KEYS).map(lambda kv: (kv[0], flow(kv[1]), False)),
                          refused_pairs(but=('solver.duration',)).map(lambda kv: (*kv, True))),
                min_size=1, max_size=4),
       st.sampled_from(['moving_force_beam', 'sprung_mass_beam']), st.floats(1e-4, 3e-3))
@counted
def test_fuzz_cli_set_pairs(examples: int, empty: _Workspace, pairs: list[tuple[str, str, bool]],
                            base: str, duration: float) -> None:
    """``ttb-sim run BASE --set K=V ...``: any key refused in one line, cheap keys run."""
    argv = ['run', base, '--duration', repr(duration), '--set', 'solver.dt=2e-4']
    for key, value, _ in pairs:
        argv.extend(['--set', f'{key}={value}'])
    with empty.example() as root:
        before = _tree(root)
        code, err = _main([*argv, '--out', 'out/bag'], stub=False)
        _answer(code, err, before, _tree(root))
    if any(refused for _, _, refused in pairs):
        assert code == 2, (pairs, err)   # a value its declaration refuses, or no such key
    else:
        assert code in (0, 1, 2)


FLAGS = options(_parser())


@examples(ARGV)
@ARGV
@given(argvs(FLAGS))
@counted
def test_fuzz_cli_argument_vectors(examples: int, workspace: _Workspace, argv: list[str]) -> None:
    """Any argument vector of any verb: exit 0, 1 or 2 (one line, nothing written)."""
    with workspace.example() as root:
        before = _tree(root)
        code, err = _main(argv, stub=True)
        _answer(code, err, before, _tree(root))


@pytest.mark.parametrize('argv', [
    ['analyze', 'broken_bag'], ['analyze', 'cut_bag'],
    ['run', 'moving_force_beam', '--set', 'train=5'], ['run', 'twice.yaml'],
    ['sweep', 'empty.yaml', '--speeds-kmh', '1'], ['compare', 'bag'], ['dataset', 'empty.yaml'],
    ['run', 'sprung_mass_beam', '--set', 'irregularity.file=bad.csv'], ['modes', 'a\x01b'],
], ids=lambda argv: ' '.join(argv))
def test_the_program_refuses_in_one_line(workspace: _Workspace, argv: list[str]) -> None:
    """A few refusals as the installed program gives them: a subprocess, one line, exit 2."""
    with workspace.example() as root:
        before = _tree(root)
        result = subprocess.run([sys.executable, '-m', 'ttb_sim.cli', *argv], cwd=root,
                                capture_output=True, text=True, timeout=300,
                                env={**os.environ, 'PYTHONPATH': os.pathsep.join(sys.path)})
        _answer(result.returncode, result.stderr, before, _tree(root))
    assert result.returncode == 2
