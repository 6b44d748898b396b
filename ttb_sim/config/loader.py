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

"""Scenario files: the YAML reader, built-in scenarios, ``--set`` overrides, loading."""

from __future__ import annotations

import dataclasses
from pathlib import Path
import re
import sys
import sysconfig
import typing
from typing import Any, Sequence, TYPE_CHECKING

from ttb_sim.config.schema import (canonical_key, coerce_value, from_mapping, key_spec,
                                   record_item, section_problem, to_plain)
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import MAX_SHOWN, read_user_file, shown
import yaml

if TYPE_CHECKING:
    from ttb_sim.config.records import Scenario  # loaded by from_mapping once the file is read

DEFAULT_SCENARIO = 'live_coupled'
"""The built-in scenario of ``ttb-sim run`` without one and of the node without a ``scenario``."""
MAX_SCENARIO_BYTES = 1 << 20
"""Largest scenario file read (bytes): built-ins are about 2 kB."""
MAX_YAML_DEPTH = 32
"""Deepest nesting of YAML collections accepted (a scenario needs three levels)."""


class YamlLoader(yaml.SafeLoader):
    """
    Safe YAML loader for scenarios: bounded, and 1e6 and 1.5e-3 read as floats (as YAML 1.2).

    Anchors and aliases (``&name``, ``*name``, ``<<: *name``) are refused: a
    scenario never needs them, and aliases nested a few levels deep (a
    "billion laughs" text of a few hundred bytes) expand to more items than
    memory holds. Collections nested deeper than :data:`MAX_YAML_DEPTH` are
    refused before the recursive composer can exhaust the stack. A key given
    twice in one mapping is refused naming the key path and both lines (YAML
    requires unique keys; PyYAML would keep the last value silently).
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._root: yaml.Node | None = None

    def construct_document(self, node: yaml.Node) -> Any:
        """Construct the document, remembering its root for key paths in messages."""
        self._root = node
        return super().construct_document(node)

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        """Construct a mapping, refusing a key given twice (both lines named)."""
        if isinstance(node, yaml.MappingNode):
            seen: dict[Any, yaml.Node] = {}
            for key_node, _ in node.value:
                if key_node.tag == 'tag:yaml.org,2002:merge':
                    continue
                key = self.construct_object(key_node, deep=False)
                try:
                    first = seen.setdefault(key, key_node)
                except TypeError:  # an unhashable key: PyYAML's own message follows
                    continue
                if first is not key_node:
                    raise yaml.constructor.ConstructorError(
                        None, None, self._duplicate(node, key, first, key_node), None)
        return super().construct_mapping(node, deep=deep)

    def _duplicate(self, node: yaml.MappingNode, key: Any, first: yaml.Node,
                   again: yaml.Node) -> str:
        """Return the message for a key given twice: its path and where both are."""
        parents = _key_path(self._root, node) if self._root is not None else None
        path = '.'.join([*(parents or []), str(key)]) if parents is not None else str(key)
        a, b = first.start_mark, again.start_mark
        where = (f'line {a.line + 1}, columns {a.column + 1} and {b.column + 1}'
                 if a.line == b.line else f'lines {a.line + 1} and {b.line + 1}')
        message = f'key {shown(path)} is given twice, on {where}; give it once'
        return message

    def compose_node(self, parent: Any, index: Any) -> Any:
        """Compose one node, refusing anchors, aliases and deep nesting."""
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(event, 'anchor', None) is not None:
            raise yaml.composer.ComposerError(
                None, None, 'anchors and aliases (&name, *name) are not allowed in scenario '
                'YAML; write the value out', event.start_mark)
        collection = isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent))
        if collection:
            self._depth += 1
            if self._depth > MAX_YAML_DEPTH:
                raise yaml.composer.ComposerError(
                    None, None, f'collections nested deeper than {MAX_YAML_DEPTH} levels',
                    event.start_mark)
        try:
            return super().compose_node(parent, index)
        finally:
            if collection:
                self._depth -= 1


def _key_path(root: yaml.Node, target: yaml.Node) -> list[str] | None:
    """Return the keys leading from ``root`` to the node ``target`` (None if not found)."""
    stack: list[tuple[yaml.Node, list[str]]] = [(root, [])]
    while stack:
        node, path = stack.pop()
        if node is target:
            return path
        if isinstance(node, yaml.MappingNode):
            stack.extend((value, [*path, str(key.value) if isinstance(key, yaml.ScalarNode)
                                  else '?']) for key, value in node.value)
        elif isinstance(node, yaml.SequenceNode):
            stack.extend((item, path[:-1] + [f'{path[-1]}[{i}]'] if path else [f'[{i}]'])
                         for i, item in enumerate(node.value))
    return None


YamlLoader.yaml_implicit_resolvers = {
    key: [(tag, rx) for tag, rx in resolvers if tag != 'tag:yaml.org,2002:float']
    for key, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
YamlLoader.add_implicit_resolver(
    'tag:yaml.org,2002:float',
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                |[-+]?\.(?:inf|Inf|INF)
                |\.(?:nan|NaN|NAN))$""", re.X),
    list('-+0123456789.'))


def read_yaml(text: str, name: str = '<text>') -> Any:
    """
    Parse YAML text with :class:`YamlLoader`.

    Parameters
    ----------
    text : str
        The YAML text.
    name : str
        What the text is (a file name), for positions in error messages.

    Raises
    ------
    yaml.YAMLError
        For invalid YAML, anchors or aliases, or nesting deeper than
        :data:`MAX_YAML_DEPTH`; also for a value YAML cannot construct (a
        timestamp such as 2001-13-45, an integer of over 4300 digits, an empty
        ``!!float``), which PyYAML reports as ValueError or IndexError.

    """
    loader = YamlLoader(text)
    loader.name = name
    try:
        return loader.get_single_data()
    except (ValueError, IndexError, TypeError, OverflowError) as exc:
        # A scalar PyYAML's constructors fail on: an over-long integer or a bad timestamp
        # (ValueError), an empty '!!float' (IndexError).
        raise yaml.YAMLError(f'a value cannot be read ({shown(str(exc))})') from None
    except RecursionError:  # pragma: no cover - the depth bound comes first
        raise yaml.YAMLError('nesting too deep') from None
    finally:
        loader.dispose()


def yaml_problem(exc: yaml.YAMLError) -> str:
    """
    Return a YAML error as one bounded line: what is wrong, and where (file, line, column).

    PyYAML's own text spans several lines and quotes the offending line, which
    may be arbitrarily long.
    """
    if not isinstance(exc, yaml.MarkedYAMLError):
        return _one_line(str(exc))
    parts = [p for p in (exc.context, exc.problem) if p]
    what = _one_line('; '.join(parts)) if parts else 'invalid YAML'
    mark = exc.problem_mark or exc.context_mark
    if mark is None:
        return what
    return f'{what} (in "{mark.name}", line {mark.line + 1}, column {mark.column + 1})'


def _one_line(text: str) -> str:
    """
    Return a message on one line (control characters escaped), cut to a few hundred characters.

    PyYAML's messages may quote a long piece of the input; ours quote values through
    :func:`shown` already, so the bound is a few times ``MAX_SHOWN``.
    """
    limit = 3 * MAX_SHOWN
    if len(text) > limit:
        text = f'{text[:limit // 2]}...{text[-limit // 2:]} ({len(text)} characters)'
    return repr(text)[1:-1]


def config_dirs() -> list[Path]:
    """Return the folders searched for built-in scenarios, in order."""
    dirs = [Path(__file__).resolve().parents[2] / 'config']
    for scheme_key in ('data',):
        base = sysconfig.get_paths().get(scheme_key)
        if base:
            dirs.append(Path(base) / 'share' / 'ttb_sim' / 'config')
    dirs.append(Path(sys.prefix) / 'share' / 'ttb_sim' / 'config')
    try:  # a colcon / ament install
        from ament_index_python.packages import get_package_share_directory
        dirs.append(Path(get_package_share_directory('ttb_sim')) / 'config')
    except Exception:  # noqa: B902 - ament absent or package not in the index
        pass
    seen: list[Path] = []
    for d in dirs:
        if d not in seen:
            seen.append(d)
    return seen


def builtin_scenarios() -> dict[str, Path]:
    """Map built-in scenario names to their YAML files."""
    found: dict[str, Path] = {}
    for d in config_dirs():
        if d.is_dir():
            for p in sorted(d.glob('*.yaml')):
                if p.stem not in found and _is_scenario_file(p):
                    found[p.stem] = p
    return found


def _is_scenario_file(path: Path) -> bool:
    try:
        with path.open(encoding='utf-8') as fh:
            head = fh.read(4096)
    except OSError:
        return False
    return 'ros__parameters' not in head and 'Panels:' not in head


def resolve(source: str | Path) -> Path:
    """
    Find a scenario file from a path or a built-in name.

    Raises
    ------
    ScenarioError
        If neither a readable file nor a built-in of that name exists.

    """
    path = Path(source)
    yaml_name = path.suffix in ('.yaml', '.yml')
    try:
        is_file, is_dir, exists = path.is_file(), path.is_dir(), path.exists()
    except OSError as exc:  # a name too long for the file system, say
        message = f'scenario file {shown(str(source))} cannot be reached ({exc.strerror})'
        raise ScenarioError(message) from None
    if is_file or (yaml_name and not is_dir):
        return path  # read_user_file refuses what is missing or not a regular file
    builtins = builtin_scenarios()
    if not yaml_name and str(source) in builtins:
        return builtins[str(source)]  # a folder named like a built-in does not hide it
    if exists:
        read_user_file(path, 'scenario file', MAX_SCENARIO_BYTES)  # says what it is instead
    names = ', '.join(sorted(builtins)) or '(none found)'
    raise ScenarioError(f'no scenario {shown(str(source))}: give a YAML path or a built-in '
                        f'name ({names})')


def parse_override(text: str) -> tuple[str, Any]:
    """
    Split a ``KEY=VALUE`` override; the value is read as a YAML scalar.

    Raises
    ------
    ScenarioError
        If the text has no '=' or the value is not valid YAML.

    """
    if '=' not in text:
        raise ScenarioError(f'--set {shown(text)}: expected KEY=VALUE, e.g. '
                            'bridge.span_length=25')
    key, raw = text.split('=', 1)
    key = key.strip()
    try:
        value = read_yaml(raw, f'--set {key}') if raw.strip() else ''
    except yaml.YAMLError as exc:
        raise ScenarioError(f'--set {shown(text)}: value is not valid YAML '
                            f'({yaml_problem(exc)})') from None
    return key, value


def apply_overrides(data: dict[str, Any], overrides: Sequence[tuple[str, Any]]) -> None:
    """
    Set dotted keys in nested plain data, in place.

    Every value is checked against its key's declaration as it is applied, so a
    bad value is refused even where a later override of the same key (``--set
    solver.duration=abc --duration 2``) would replace it.

    Raises
    ------
    ScenarioError
        If a key does not exist in the schema, names a section (a group of
        keys such as ``train``) instead of a key, or is given a value of the
        wrong type or out of range (the message names the key, the value and
        what is allowed).

    """
    for key, value in overrides:
        if ITEM_KEY.match(key):
            _apply_item_override(data, key, value)
            continue
        problem = section_problem(canonical_key(key))
        if problem is not None:
            message = f'{key} = {shown(value)}: {problem}'
            raise ScenarioError(message)
        typ, _, spec = key_spec(key)  # raises on unknown keys
        key = canonical_key(key)
        coerce_value(key, value, typ, spec)  # raises on a bad value, whatever follows
        node = data
        parts = key.split('.')
        for part in parts[:-1]:
            child = node.get(part)
            if not isinstance(child, dict):
                child = {}
                node[part] = child
            node = child
        node[parts[-1]] = value


ITEM_KEY = re.compile(r'^(?P<list>[a-z_][a-z0-9_.]*)\[(?P<index>\d+)\]'
                      r'(?:\.(?P<field>[A-Za-z_][A-Za-z0-9_]*))?$')
"""A key into one entry of a list-valued key: ``damage.girders[0].loss``,
``environment.soil_modulus_scale[1]``."""


def _apply_item_override(data: dict[str, Any], key: str, value: Any) -> None:
    """
    Set one entry of a list-valued key (or one field of it), in place.

    The list is the one given so far (in the file or by an earlier override), or the
    key's default; the index must name an entry of it.  The value is checked against
    the entry's declaration (the field's for a list of records, the key's for a list
    of numbers); the whole list is checked again when the scenario is built.

    Raises
    ------
    ScenarioError
        For an unknown list key or field, an index past the list's end, or a bad value.

    """
    match = ITEM_KEY.match(key)
    assert match is not None
    list_key, index, field = match['list'], int(match['index']), match['field']
    typ, default, spec = key_spec(list_key)   # raises on unknown keys
    list_key = canonical_key(list_key)
    record = record_item(typ)
    if record is None and field is not None:
        raise ScenarioError(f'{key} = {shown(value)}: {list_key} is a list of values, not of '
                            f'records; set {list_key}[{index}] itself')
    if record is not None and field is None:
        fields = ', '.join(f.name for f in dataclasses.fields(record))
        raise ScenarioError(f'{key} = {shown(value)}: {list_key}[{index}] is a record; set one '
                            f'of its keys, e.g. {list_key}[{index}].{fields.split(", ")[0]} '
                            f'(keys: {fields})')
    if typing.get_origin(typ) is not tuple:
        raise ScenarioError(f'{key} = {shown(value)}: {list_key} is not a list; set it as '
                            f'{list_key}=VALUE')
    node = data
    parts = list_key.split('.')
    for part in parts[:-1]:
        child = node.get(part)
        if not isinstance(child, dict):
            child = {}
            node[part] = child
        node = child
    current = node.get(parts[-1], [_plain_entry(e) for e in to_plain(default or [])])
    if not isinstance(current, (list, tuple)):
        raise ScenarioError(f'{key} = {shown(value)}: {list_key} is {shown(current)}, not a '
                            'list; give the list first')
    entries = [dict(e) if isinstance(e, dict) else e for e in current]
    if index >= len(entries):
        have = f'has {len(entries)} entries (index 0 to {len(entries) - 1})' if entries \
            else 'has no entries'
        raise ScenarioError(f'{key} = {shown(value)}: {list_key} {have}; give the entry in '
                            f'the scenario (or as {list_key}=[...]) before setting a key of it')
    if record is not None:
        names = {f.name: f for f in dataclasses.fields(record)}
        if field not in names:
            raise ScenarioError(f'{key} = {shown(value)}: unknown key {field!r} in an entry of '
                                f'{list_key}; allowed: {", ".join(names)}')
        hints = typing.get_type_hints(record)
        coerce_value(key, value, hints[field], names[field].metadata['spec'])
        if not isinstance(entries[index], dict):
            raise ScenarioError(f'{key}: {list_key}[{index}] is {shown(entries[index])}, not '
                                'a mapping')
        entries[index][field] = value
    else:
        element = typing.get_args(typ)[0] if typing.get_args(typ) else float
        if element not in (int, float):
            raise ScenarioError(f'{key}: the entries of {list_key} are not numbers')
        coerce_value(key, [value], typ, spec)
        entries[index] = value
    node[parts[-1]] = entries


def _plain_entry(entry: Any) -> Any:
    """Return one entry of a list default as plain data (a record as its mapping)."""
    if dataclasses.is_dataclass(entry) and not isinstance(entry, type):
        return dataclasses.asdict(entry)
    return entry


def load_scenario(source: str | Path, overrides: Sequence[str] = (),
                  values: Sequence[tuple[str, Any]] = ()) -> Scenario:
    """
    Load, override and validate a scenario.

    Parameters
    ----------
    source
        Path to a YAML file, or the name of a built-in scenario.
    overrides
        ``KEY=VALUE`` strings (values are YAML scalars), applied in order.
    values
        Already-typed ``(key, value)`` pairs, applied after ``overrides``.

    Returns
    -------
    Scenario
        The validated scenario.

    Raises
    ------
    ScenarioError
        If the file cannot be read or parsed, is empty (only blank lines or
        comments), gives a key twice, or any key is invalid.

    """
    path = resolve(source)
    text = read_user_file(path, 'scenario file', MAX_SCENARIO_BYTES)
    name = shown(str(path))
    try:
        data = read_yaml(text, str(path))
    except yaml.YAMLError as exc:
        raise ScenarioError(f'scenario file {name} is not valid YAML: '
                            f'{yaml_problem(exc)}') from None
    if data is None:
        message = (f'scenario file {name} is empty (no keys, only blank lines or comments); '
                   'give the keys to set, e.g. "train: {speed_kmh: 250}", or run a built-in '
                   'scenario (ttb-sim scenarios)')
        raise ScenarioError(message)
    if not isinstance(data, dict):
        raise ScenarioError(f'scenario file {name} must hold a mapping of keys, got '
                            f'{shown(data)}')
    data.setdefault('name', path.stem)
    apply_overrides(data, [parse_override(o) for o in overrides] + list(values))
    scenario = from_mapping(data)
    from ttb_sim.config.conditions import check_conditions  # imports the model records
    check_conditions(scenario)
    return scenario
