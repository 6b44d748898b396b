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
Hypothesis strategies of the fuzz suite (``test_fuzz.py``): scenario keys and values, YAML, CSV.

Values mix plausible ones (near each key's declared range) and hostile ones
(wrong types, nested junk, odd YAML scalars); :func:`refused_value` draws,
for any key, a value its declaration must refuse.
"""

from __future__ import annotations

from typing import Any

from hypothesis import strategies as st
from ttb_sim.config import iter_keys
import yaml

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


def plausible(typ: Any, spec: Any) -> st.SearchStrategy[Any]:
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
    value = draw(plausible(typ, spec)) if draw(st.integers(0, 3)) else draw(JUNK)
    return key, value


def nest(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
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


CHEAP_KEYS = [(k, t, s) for k, t, s in KEYS if k in {
    'bridge.span_length', 'bridge.bending_stiffness', 'bridge.mass_per_length',
    'bridge.damping_ratio', 'train.speed_kmh', 'train.axle_load', 'train.start_position',
    'train.sprung_mass', 'train.unsprung_mass', 'train.suspension_stiffness',
    'train.suspension_damping', 'train.axle_offsets', 'irregularity.spectrum',
    'irregularity.seed', 'irregularity.scale', 'solver.divergence_limit', 'output.rate_hz',
    'output.observers', 'solver.variant', 'bearings.model', 'description'}]


def merge(base: Any, extra: dict[str, Any]) -> dict[str, Any]:
    out = dict(base) if isinstance(base, dict) else {}
    for key, value in extra.items():
        out[key] = merge(out.get(key), value) if isinstance(value, dict) else value
    return out


SET_VALUES = st.one_of(
    st.text(max_size=40),
    st.sampled_from(['1e6', '-1', '.inf', '.nan', '[1, 2]', '{a: 1}', '&a [*a]', '*a',
                     '!!binary x', '2001-13-45', '1' * 5000, '[' * 100 + ']' * 100, 'yes',
                     '~', '"', "'",
                     'a: b: c', '- x', '| block', '0x1F', '1_000', '!!python/name:os.system']))


def flow(value: Any) -> str:
    """Write a value as one line of YAML (as a user types it after KEY=)."""
    return yaml.safe_dump(value, default_flow_style=True, width=10**9).strip().removesuffix(
        '\n...').replace('\n', ' ')


YAML_TOKENS = st.sampled_from([
    'bridge', 'train', 'solver', 'span_length', 'speed_kmh', 'dt', 'name', 'description',
    'output', 'observers', ':', ': ', '\n', '\n  ', '\n    ', '- ', '[', ']', '{', '}', ',',
    '&a ', '*a', '&b ', '*b', '<<: ', '!!binary ', '!!str ', '!!float ', '!!python/tuple ',
    '!foo ', '? ', '|', '>', '#', '"', "'", '\\', '%YAML 1.1\n', '---\n', '...\n', '\t',
    '1', '1e6', '-0.5', '.nan', '.inf', '0x10', '2001-12-14', '2001-13-45', '~', 'null',
    'true', '1' * 5000, '\x00', '\ufeff', 'é', '\u2028', '@', '`'])


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


# -- values a key's declaration must refuse ----------------------------------------------

def refused_value(typ: Any, spec: Any) -> st.SearchStrategy[str]:
    """
    Return ``--set`` value texts (YAML) that the declaration (type, range, choices) refuses.

    Numbers beyond a bound, text where a number or a boolean is due, a mapping where a
    string or a list is due, NaN and infinities for floats, values not among the choices.
    """
    common = ['{a: 1}', '[[1], {b: 2}]', '!!binary eA==']
    if typ is bool:
        return st.sampled_from(['maybe', '2', '[true]', '~', *common])
    if spec.choices is not None:
        return st.sampled_from(['none_such', 'tram', '1.5', '[car]', '~', *common])
    if typ in (int, float):
        bad = ['abc', '[1]', 'true', '~', '', *common]
        if spec.low is not None:
            bad.append(repr(float(spec.low) - 1.0 - abs(float(spec.low))))
        if spec.high is not None:
            bad.append(repr(float(spec.high) * 2.0 + 1.0))
        if typ is float:
            bad.extend(['.nan', '.inf', '-.inf'])
        else:
            bad.extend(['2.5', '1e400'])
        return st.sampled_from(bad)
    if typ is str:
        return st.sampled_from(['5', '[1]', 'true', '~', *common])
    return st.sampled_from(['5', 'abc', 'true', '{a: 1}', '[[[1]]]', '~', '!!binary eA=='])


@st.composite
def refused_pairs(draw: Any, but: tuple[str, ...] = ()) -> tuple[str, str]:
    """
    Draw a ``KEY=VALUE`` the scenario must refuse: a key with a refused value, or no key.

    ``but`` are keys left out: those a later option of the command line sets again
    (``--duration`` sets solver.duration after the ``--set`` values).
    """
    if draw(st.integers(0, 5)) == 0:
        key = draw(st.sampled_from([*SECTIONS, 'soil.mesh', 'nope', 'bridge.nope', '',
                                    'train.speed_kmh.x', '.', 'bridge..span_length']))
        return key, draw(st.sampled_from(['5', '{speed_kmh: 1}', '', 'x']))
    key, typ, spec = draw(st.sampled_from([k for k in KEYS if k[0] not in but]))
    return key, draw(refused_value(typ, spec))


# -- command lines -------------------------------------------------------------------------

VERBS = ['run', 'validate', 'bench', 'modes', 'frf', 'analyze', 'compare', 'sweep',
         'scenarios']
"""The verbs of ``ttb-sim``."""

PATHS = ['missing', 'missing.yaml', 'file.txt', 'empty.yaml', 'twice.yaml', 'dir', 'bag',
         'broken_bag', 'cut_bag', 'killed_bag', 'out', 'out/deeper/x', 'bad.csv', 'loop',
         'loop/x', 'file.txt/x', 'dir/keep.txt', 'x' * 300, '/dev/null', '/nonexistent/x', '.',
         '']
"""Paths, relative to an example's working folder (see ``test_fuzz._workspace``)."""

VALUES = st.sampled_from([
    '0', '-1', '1e-3', '0.002', '3', 'nan', 'inf', '-inf', '1e308', 'abc', 'x' * 300, '\x00',
    'a\x00b', '1,2', '250,300', ',', '-', '--', 'moving_force_beam', 'sprung_mass_beam',
    'no_such', 'V1', 'V99', 'reference,nope', 'tcp://127.0.0.1:9', 'train=5',
    'train.speed_kmh=abc', 'bridge.span_length=-1', 'solver.dt=0', 'a=b', '=', 'x,y,z',
    'irregularity.file=bad.csv', 'solver.duration=0.001'])
"""Option values and positionals: numbers, junk, NUL bytes, scenario and case names."""


GOOD = {'--duration': ['0.002'], '--speed-kmh': ['250'], '--speeds-kmh': ['250,300', '300'],
        '--seeds': ['2'], '--workers': ['1'], '--storage': ['mcap', 'sqlite3'],
        '--set': ['train.speed_kmh=250', 'solver.dt=2e-4'], '--around': ['5'], '--count': ['3'],
        '--variants': ['reference'], '--repeat': ['1'], '--labels': ['a,b'],
        '--out': ['out/new'], '--json': ['out.json'], '--scheduler': ['tcp://127.0.0.1:9'],
        '--freqs': ['2', '1:3:1'], '--pml': ['3'], '--solver': ['superlu'],
        '--plot': ['out.png']}
"""A value each option accepts, so that some vectors pass the checks."""

# frf's good positional is refused (not a substructure run): a fuzzed frf must stay quick
POSITIONALS = {'run': ['moving_force_beam', 'sprung_mass_beam'], 'modes': ['moving_force_beam'],
               'frf': ['moving_force_beam'],
               'sweep': ['moving_force_beam'], 'bench': ['moving_force_beam'],
               'analyze': ['bag'], 'compare': ['bag', 'bag'], 'validate': ['V1']}
"""What each verb accepts as its positional argument(s)."""


def options(parser: Any) -> dict[str, list[str]]:
    """Return the option strings of each verb of the parser (and '' for the top level)."""
    def names(p: Any) -> list[str]:
        return [o for a in p._actions for o in a.option_strings if o not in ('-h', '--help')]
    out = {'': names(parser)}
    for action in parser._actions:
        for name, sub in (getattr(action, 'choices', None) or {}).items():
            if hasattr(sub, '_actions'):
                out[name] = names(sub)
    return out


@st.composite
def argvs(draw: Any, flags: dict[str, list[str]]) -> list[str]:
    """Draw an argument vector: a verb (or none, or junk), then options, values, paths."""
    verb = draw(st.sampled_from([*VERBS, *VERBS, '', 'nope', '--version', '-h', '-v']))
    value = st.one_of(VALUES, st.sampled_from(PATHS), st.text(max_size=10))
    head = [verb] if verb else []
    if verb in POSITIONALS and draw(st.integers(0, 3)):
        good = draw(st.booleans())
        head.extend(POSITIONALS[verb] if good else [draw(st.one_of(st.sampled_from(PATHS),
                                                                   VALUES))])
    tokens: list[str] = []
    for flag in draw(st.lists(st.sampled_from(flags.get(verb, flags['']) or ['-v']),
                              max_size=4)):
        tokens.append(flag)
        if flag in GOOD or draw(st.booleans()):
            tokens.append(draw(st.sampled_from(GOOD[flag]) if flag in GOOD and
                               draw(st.booleans()) else value))
    if draw(st.integers(0, 4)) == 0:   # a stray value anywhere
        tokens.insert(draw(st.integers(0, len(tokens))), draw(value))
    return head + tokens
