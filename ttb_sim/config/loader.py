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

from pathlib import Path
import re
import sys
import sysconfig
from typing import Any, Sequence

from ttb_sim.config.records import Scenario
from ttb_sim.config.schema import canonical_key, from_mapping, key_spec
from ttb_sim.errors import ScenarioError
import yaml


class YamlLoader(yaml.SafeLoader):
    """Safe YAML loader that also reads 1e6 and 1.5e-3 as floats (as YAML 1.2 does)."""


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


def read_yaml(text: str) -> Any:
    """Parse YAML text with :class:`YamlLoader`."""
    return yaml.load(text, Loader=YamlLoader)  # noqa: S506 - a SafeLoader subclass


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
    if path.suffix in ('.yaml', '.yml') or path.exists():
        if not path.is_file():
            raise ScenarioError(f'scenario file {str(path)!r} does not exist')
        return path
    builtins = builtin_scenarios()
    if str(source) in builtins:
        return builtins[str(source)]
    names = ', '.join(sorted(builtins)) or '(none found)'
    raise ScenarioError(f'no scenario {str(source)!r}: give a YAML path or a built-in name '
                        f'({names})')


def parse_override(text: str) -> tuple[str, Any]:
    """
    Split a ``KEY=VALUE`` override; the value is read as a YAML scalar.

    Raises
    ------
    ScenarioError
        If the text has no '=' or the value is not valid YAML.

    """
    if '=' not in text:
        raise ScenarioError(f'--set {text!r}: expected KEY=VALUE, e.g. bridge.span_length=25')
    key, raw = text.split('=', 1)
    key = key.strip()
    try:
        value = read_yaml(raw) if raw.strip() else ''
    except yaml.YAMLError as exc:
        raise ScenarioError(f'--set {text!r}: value is not valid YAML ({exc})') from None
    return key, value


def apply_overrides(data: dict[str, Any], overrides: Sequence[tuple[str, Any]]) -> None:
    """
    Set dotted keys in nested plain data, in place.

    Raises
    ------
    ScenarioError
        If a key does not exist in the schema.

    """
    for key, value in overrides:
        key_spec(key)  # raises on unknown keys
        key = canonical_key(key)
        node = data
        parts = key.split('.')
        for part in parts[:-1]:
            child = node.get(part)
            if not isinstance(child, dict):
                child = {}
                node[part] = child
            node = child
        node[parts[-1]] = value


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
        If the file cannot be read or parsed, or any key is invalid.

    """
    path = resolve(source)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f'cannot read scenario file {str(path)!r}: {exc}') from None
    try:
        data = read_yaml(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(f'scenario file {str(path)!r} is not valid YAML: {exc}') from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ScenarioError(f'scenario file {str(path)!r} must hold a mapping of keys')
    data.setdefault('name', path.stem)
    apply_overrides(data, [parse_override(o) for o in overrides] + list(values))
    return from_mapping(data)
