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
Fuzzing the inputs of ``ttb-sim run`` with hypothesis: nothing may crash, hang or half-write.

Four input kinds, each drawn by hypothesis from a strategy that mixes plausible
and hostile values:

* scenario mappings (keys of the schema and junk keys, values in and out of
  range, wrong types, nested junk): 200 examples validated, 40 run;
* ``--set KEY=VALUE`` strings: 200 examples;
* YAML texts (keys, YAML punctuation, anchors, aliases, tags, deep brackets,
  odd scalars): 200 examples;
* irregularity CSV bytes (headers, numbers including nan, inf and huge ones,
  ragged rows, quotes, BOM and NUL bytes, random bytes): 200 examples read,
  30 run under a quarter car.

That is 870 examples per run of this module. Every example must end like the
command line does: a scenario or profile, or a ScenarioError (exit 2) with a
short message; the runs must exit 0, 1 (divergence) or 2 with a one-line
message, and leave either no output directory (exit 2) or a closed bag with
``summary.json`` (0, 1). Any other exception, a message without the
``ttb-sim:`` prefix or a long message fails. Hangs are bounded by the
per-example ``deadline`` (a bound against hangs, not a speed check: it is
generous for a loaded 2-core machine). Runs stay tiny: the base scenario is
``moving_force_beam`` or ``sprung_mass_beam`` and ``--duration`` is at most 5 ms
at a step of at least 0.1 ms. The examples are derandomised, so CI tries the
same ones every time; raise ``max_examples`` locally to search further.
"""

from __future__ import annotations

import contextlib
from datetime import timedelta
import io
import json
import math
from pathlib import Path
import tempfile
from typing import Any

from hypothesis import event, given, HealthCheck, settings, strategies as st
from hypothesis.control import currently_in_test_context
import pytest
from ttb_sim.cli import main
from ttb_sim.config import iter_keys, load_scenario, parse_override, Scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity import load_csv, TrackIrregularity
import yaml

MAX_MESSAGE = 2000
"""Longest acceptable error message (characters)."""

VALIDATE = settings(max_examples=200, deadline=timedelta(seconds=30), derandomize=True,
                    database=None, suppress_health_check=[HealthCheck.too_slow])
RUN = settings(max_examples=40, deadline=timedelta(seconds=120), derandomize=True,
               database=None, suppress_health_check=[HealthCheck.too_slow])
RUN_CSV = settings(RUN, max_examples=30)

KEYS = [(key, typ, spec) for key, typ, _, spec in iter_keys()]
SECTIONS = sorted({key.split('.')[0] for key, _, _ in KEYS if '.' in key})

# -- value strategies ------------------------------------------------------------------------

SCALARS = st.one_of(
    st.none(), st.booleans(), st.integers(-10**6, 10**6), st.integers(),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
    st.text(max_size=300), st.sampled_from(['', 'car', 'slab', 'none', 'springs', 'paper',
                                            'a=girder@1', 'x=rail_left@0', '1e6', '.nan']))
JUNK = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4)
                    | st.dictionaries(st.text(max_size=8), inner, max_size=4), max_leaves=12)


def _plausible(typ: Any, spec: Any) -> st.SearchStrategy[Any]:
    """Values near the declared range: mostly accepted, sometimes just outside."""
    if spec.choices is not None:
        return st.sampled_from(spec.choices)
    if typ is bool:
        return st.booleans()
    low = -1e6 if spec.low is None else spec.low
    high = 1e6 if spec.high is None else spec.high
    if typ is int:
        return st.integers(int(max(low, -10**6)) - 1, int(min(high, 10**6)) + 1)
    if typ is float:
        return st.floats(low, high) | st.sampled_from([low, high, low - 1.0, high * 2 + 1])
    if typ == tuple[float, ...]:
        return st.lists(st.floats(0.0, 100.0), max_size=5)
    if typ == tuple[str, ...]:
        return st.lists(st.sampled_from(['a=girder@1', 'b=girder@16', 'c=slab@3', 'bad']),
                        max_size=3)
    return st.text(max_size=10)


@st.composite
def key_values(draw: Any, keys: list[tuple[str, Any, Any]] = KEYS) -> tuple[str, Any]:
    """One (dotted key, value) pair: a schema key with a plausible or junk value, or junk."""
    if draw(st.integers(0, 9)) == 0:
        return draw(st.sampled_from(SECTIONS + ['nope', 'bridge.nope', 'train'])), draw(JUNK)
    key, typ, spec = draw(st.sampled_from(keys))
    value = draw(_plausible(typ, spec)) if draw(st.integers(0, 3)) else draw(JUNK)
    return key, value


def _nest(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """Nest dotted keys into a mapping (a later pair replaces what is in its way)."""
    root: dict[str, Any] = {}
    for key, value in pairs:
        node = root
        parts = key.split('.')
        for part in parts[:-1]:
            if not isinstance(node.get(part), dict):
                node[part] = {}
            node = node[part]
        node[parts[-1]] = value
    return root


# -- checks ----------------------------------------------------------------------------------

def _event(name: str) -> None:
    """Count an outcome in hypothesis' statistics (--hypothesis-show-statistics)."""
    if currently_in_test_context():
        event(name)


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

@VALIDATE
@given(st.lists(key_values(), max_size=8))
def test_fuzz_scenario_mappings_validate(pairs: list[tuple[str, Any]]) -> None:
    """Any mapping loads as a scenario or is refused with a short message."""
    data = _nest(pairs)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_text(yaml.safe_dump(data), encoding='utf-8')
        result = _validated(lambda: load_scenario(path))
    assert isinstance(result, (Scenario, ScenarioError))


CHEAP_KEYS = [(k, t, s) for k, t, s in KEYS if k in {
    'bridge.span_length', 'bridge.bending_stiffness', 'bridge.mass_per_length',
    'bridge.damping_ratio', 'train.speed_kmh', 'train.axle_load', 'train.start_position',
    'train.sprung_mass', 'train.unsprung_mass', 'train.suspension_stiffness',
    'train.suspension_damping', 'train.axle_offsets', 'irregularity.spectrum',
    'irregularity.seed', 'irregularity.scale', 'solver.divergence_limit', 'output.rate_hz',
    'output.observers', 'solver.variant', 'bearings.model', 'description'}]


@RUN
@given(st.lists(key_values(CHEAP_KEYS), max_size=6),
       st.sampled_from(['moving_force_beam', 'sprung_mass_beam']),
       st.floats(1e-4, 1e-3), st.floats(1e-4, 5e-3))
def test_fuzz_scenario_mappings_run(pairs: list[tuple[str, Any]], base: str, dt: float,
                                    duration: float) -> None:
    """Mappings over the cheap keys of a one-span scenario, run for a few steps."""
    data = yaml.safe_load(Path(__file__).resolve().parents[1].joinpath(
        'config', f'{base}.yaml').read_text())
    for key, value in pairs:
        data = _merge(data, _nest([(key, value)]))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_text(yaml.safe_dump(data), encoding='utf-8')
        _cli([str(path), '--duration', repr(duration), '--set', f'solver.dt={dt!r}'],
             Path(tmp) / 'out' / 'bag')


def _merge(base: Any, extra: dict[str, Any]) -> dict[str, Any]:
    out = dict(base) if isinstance(base, dict) else {}
    for key, value in extra.items():
        out[key] = _merge(out.get(key), value) if isinstance(value, dict) else value
    return out


# -- --set strings ---------------------------------------------------------------------------

SET_VALUES = st.one_of(
    st.text(max_size=40),
    st.sampled_from(['1e6', '-1', '.inf', '.nan', '[1, 2]', '{a: 1}', '&a [*a]', '*a',
                     '!!binary x', '2001-13-45', '1' * 5000, '[' * 100 + ']' * 100, 'yes',
                     '~', '"', "'",
                     'a: b: c', '- x', '| block', '0x1F', '1_000', '!!python/name:os.system']))


@VALIDATE
@given(st.one_of(
    st.text(max_size=60),
    key_values().map(lambda kv: f'{kv[0]}={_flow(kv[1])}'),
    st.tuples(st.sampled_from([k for k, _, _ in KEYS] + ['', 'nope', 'bridge', '.']),
              SET_VALUES).map(lambda kv: f'{kv[0]}={kv[1]}')))
def test_fuzz_set_strings(text: str) -> None:
    """Any --set string is applied to moving_force_beam or refused with a short message."""
    result = _validated(lambda: load_scenario('moving_force_beam', [text]))
    assert isinstance(result, (Scenario, ScenarioError))
    try:
        parse_override(text)
    except ScenarioError:
        pass


def _flow(value: Any) -> str:
    """Write a value as one line of YAML (as a user types it after KEY=)."""
    return yaml.safe_dump(value, default_flow_style=True, width=10**9).strip().removesuffix(
        '\n...').replace('\n', ' ')


# -- YAML texts ------------------------------------------------------------------------------

YAML_TOKENS = st.sampled_from([
    'bridge', 'train', 'solver', 'span_length', 'speed_kmh', 'dt', 'name', 'description',
    'output', 'observers', ':', ': ', '\n', '\n  ', '\n    ', '- ', '[', ']', '{', '}', ',',
    '&a ', '*a', '&b ', '*b', '<<: ', '!!binary ', '!!str ', '!!float ', '!!python/tuple ',
    '!foo ', '? ', '|', '>', '#', '"', "'", '\\', '%YAML 1.1\n', '---\n', '...\n', '\t',
    '1', '1e6', '-0.5', '.nan', '.inf', '0x10', '2001-12-14', '2001-13-45', '~', 'null',
    'true', '1' * 5000, '\x00', '\ufeff', 'é', '\u2028', '@', '`'])


@VALIDATE
@given(st.one_of(st.lists(YAML_TOKENS, max_size=40).map(''.join), st.text(max_size=200),
                 st.integers(1, 6000).map(lambda n: 'a: ' + '[' * n + ']' * n)))
def test_fuzz_yaml_texts(text: str) -> None:
    """Any text in a scenario file is loaded or refused with a short message, quickly."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.yaml'
        path.write_bytes(text.encode('utf-8', errors='surrogatepass'))
        result = _validated(lambda: load_scenario(path))
    assert isinstance(result, (Scenario, ScenarioError))


# -- irregularity CSV bytes ------------------------------------------------------------------

HEADERS = st.sampled_from(['x,z_left,z_right,y_left,y_right', 'x,z_left,z_right,y_left,y_right',
                           'z_left,x,y_right,y_left,z_right',
                           'x,z_left,z_right,y_left', 'x,z_left,z_right,y_left,y_right,note',
                           'x,x,z_left,z_right,y_left,y_right', '', '# comment', '"x",z_left'])
CELLS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-1e-3, 1e-3).map(repr), st.integers(-10**30, 10**30).map(str),
    st.sampled_from(['', 'nan', 'inf', '-inf', '1e308', '1e-320', 'abc', '"', '"1"', ' 1 ',
                     '\x00', '1e999', '0x1', '1_0']))


@st.composite
def csv_bytes(draw: Any) -> bytes:
    """Draw a CSV file: a header (or none) and rows of cells, or raw bytes."""
    if draw(st.integers(0, 4)) == 0:
        return draw(st.binary(max_size=400))
    clean = draw(st.booleans())  # half the files are well formed (with or without a header)
    if clean:
        rows = draw(st.sampled_from([['x,z_left,z_right,y_left,y_right'], [],
                                     ['# measured', 'z_left,x,z_right,y_left,y_right']]))
    else:
        rows = [draw(HEADERS)]
    n = draw(st.integers(0, 30))
    monotone = clean or draw(st.booleans())
    step = draw(st.sampled_from([0.25, 1e-9, 1e6, 0.1]))
    for i in range(n):
        if clean:
            cells = [repr(draw(st.floats(-1e-3, 1e-3))) for _ in range(5)]
        else:
            width = draw(st.sampled_from([5, 5, 5, 4, 6]))
            cells = [draw(CELLS) for _ in range(width)]
        if monotone and cells:
            cells[0] = repr(i * step)
        rows.append(','.join(cells))
    text = '\n'.join(rows) + draw(st.sampled_from(['\n', '', '\r\n']))
    prefix = draw(st.sampled_from([b'', b'', b'', b'\xef\xbb\xbf', b'\xff']))
    return prefix + text.encode('utf-8')


@VALIDATE
@given(csv_bytes())
def test_fuzz_irregularity_csv_bytes(data: bytes) -> None:
    """Any bytes are read as a finite profile or refused with a short message."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / 'fuzz.csv'
        path.write_bytes(data)
        result = _validated(lambda: load_csv(path))
    assert isinstance(result, (TrackIrregularity, ScenarioError))
    if isinstance(result, TrackIrregularity):
        assert math.isfinite(result.dx) and result.dx > 0


@RUN_CSV
@given(csv_bytes(), st.floats(1e-4, 5e-3))
def test_fuzz_irregularity_csv_runs(data: bytes, duration: float) -> None:
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
