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
The schema walker: every declared key of the scenario tree, and typed, range-checked values.

:func:`iter_keys` and :func:`key_spec` walk the :func:`~ttb_sim.declarations.param`
declarations of the scenario records; :func:`from_mapping` builds the record
tree from plain (YAML) data, checking each value against its declaration and
naming the key path, the value and what is allowed when it refuses.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import typing
from typing import Any, Iterator, Mapping

from ttb_sim.declarations import Spec
from ttb_sim.errors import ModelError, ScenarioError
from ttb_sim.inputs import shown

__all__ = ['ALIASES', 'canonical_key', 'coerce_value', 'from_mapping', 'iter_keys', 'key_spec',
           'resolve_aliases', 'section_problem', 'to_plain']

ALIASES = {
    'train.bogie_semi_spacing': 'car.bogie_semi_spacing',
    'train.wheelbase_semi': 'car.wheelbase_semi',
}
"""Old key paths that still work, and the key each now sets (the car record owns the
car geometry since the records were unified; scenario files and ``--set`` using the old
paths keep working)."""

MAX_SECTION_KEYS_SHOWN = 4
"""Most keys of a section named when a section is given where a key is expected."""

MAX_LIST_ITEMS = 1000
"""Most entries of a list-valued key (axle offsets, observers)."""


def canonical_key(path: str) -> str:
    """Return the key path an alias stands for (the path itself when it is no alias)."""
    return ALIASES.get(path, path)


def resolve_aliases(data: Mapping[str, Any]) -> dict[str, Any]:
    """
    Return a copy of plain scenario data with aliased keys moved to their new place.

    Raises
    ------
    ScenarioError
        If an alias and its key are both given with different values.

    """
    out = {k: dict(v) if isinstance(v, Mapping) else v for k, v in data.items()}
    for old, new in ALIASES.items():
        old_section, old_key = old.split('.')
        section = out.get(old_section)
        if not isinstance(section, dict) or old_key not in section:
            continue
        value = section.pop(old_key)
        new_section, new_key = new.split('.')
        target = out.setdefault(new_section, {})
        if not isinstance(target, dict):
            continue  # from_mapping reports the malformed section
        if new_key in target and target[new_key] != value:
            raise ScenarioError(f'{old} = {value!r} and {new} = {target[new_key]!r} set the '
                                f'same key ({old} is the old name of {new}); give one')
        target[new_key] = value
    return out


def iter_keys(cls: type | None = None, prefix: str = '') -> Iterator[tuple[str, type, Any, Spec]]:
    """
    Yield every leaf key of the schema.

    Yields
    ------
    tuple
        (dotted key path, Python type, default, spec) for each leaf.

    """
    cls = _root(cls)
    hints = _hints(cls)
    for f in dataclasses.fields(cls):
        path = f'{prefix}{f.name}'
        if 'spec' in f.metadata:
            yield path, hints[f.name], f.default, f.metadata['spec']
        else:
            yield from iter_keys(hints[f.name], prefix=f'{path}.')


def key_spec(path: str) -> tuple[type, Any, Spec]:
    """
    Return (type, default, spec) of one dotted key.

    Raises
    ------
    ScenarioError
        If the key does not exist.

    """
    path = canonical_key(path)
    for key, typ, default, spec in iter_keys():
        if key == path:
            return typ, default, spec
    problem = section_problem(path)
    if problem is not None:
        raise ScenarioError(problem)
    raise ScenarioError(f'unknown key {shown(path)}; see `ttb-sim scenarios --keys` for the '
                        'list')


def section_problem(path: str) -> str | None:
    """
    Say that ``path`` is a section (a group of keys), not a key, and name its keys.

    Parameters
    ----------
    path : str
        A dotted path, e.g. ``'train'`` or ``'soil.mesh'``.

    Returns
    -------
    str or None
        The message, or None when ``path`` is not a section of the schema.

    """
    keys = [(key, spec) for key, _, _, spec in iter_keys() if key.startswith(f'{path}.')]
    if not keys:
        return None
    example = next((key for key, spec in keys if spec.dynamic), keys[0][0])
    names = ', '.join(key for key, _ in keys[:MAX_SECTION_KEYS_SHOWN])
    more = ', ...' if len(keys) > MAX_SECTION_KEYS_SHOWN else ''
    message = (f'{path} is a section, not a value; set one of its keys, e.g. {example} '
               f'(its {len(keys)} keys: {names}{more}; see `ttb-sim scenarios --keys`)')
    return message


def _root(cls: type | None) -> type:
    """Return ``cls``, or the scenario root record when it is None."""
    if cls is not None:
        return cls
    from ttb_sim.config.records import Scenario  # the records import this module
    return Scenario


def _hints(cls: type) -> dict[str, Any]:
    module = sys.modules[cls.__module__]
    out = {}
    for f in dataclasses.fields(cls):
        t = f.type
        out[f.name] = eval(t, vars(module)) if isinstance(t, str) else t  # noqa: S307
    return out


# --------------------------------------------------------------------------------------
# Building from plain data
# --------------------------------------------------------------------------------------

def from_mapping(data: Mapping[str, Any], cls: type | None = None, prefix: str = '') -> Any:
    """
    Build a (nested) config dataclass from plain data, validating every key.

    Raises
    ------
    ScenarioError
        On an unknown key, a wrong type or a value out of range; the message
        names the key path, the value and what is allowed.

    """
    if cls is None and isinstance(data, Mapping):
        data = resolve_aliases(data)
    cls = _root(cls)
    if not isinstance(data, Mapping):
        where = prefix[:-1] or 'the scenario'
        raise ScenarioError(f'{where} must be a mapping of keys, got {shown(data)}')
    hints = _hints(cls)
    names = {f.name: f for f in dataclasses.fields(cls)}
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        path = f'{prefix}{key}'
        if key not in names:
            allowed = ', '.join(sorted(names))
            raise ScenarioError(f'unknown key {shown(path)}; allowed here: {allowed}')
        f = names[key]
        if 'spec' in f.metadata:
            if isinstance(value, (list, tuple)) and not value and f.default == ():
                kwargs[key] = ()   # an optional list given empty: as if left out
                continue
            kwargs[key] = _coerce(path, value, hints[key], f.metadata['spec'])
        else:
            kwargs[key] = from_mapping(value, hints[key], prefix=f'{path}.')
    try:
        return cls(**kwargs)
    except ScenarioError:
        raise
    except ModelError as exc:  # a record's own cross-field check
        raise ScenarioError(f'{prefix[:-1] or "scenario"}: {exc}') from None
    except (TypeError, ValueError) as exc:  # pragma: no cover - defensive
        raise ScenarioError(f'{prefix[:-1] or "scenario"}: {exc}') from None


def _coerce(path: str, value: Any, typ: Any, spec: Spec) -> Any:
    """Check one value against its declared type and range, and return it typed."""
    if isinstance(value, (list, tuple)) and len(value) > MAX_LIST_ITEMS:
        raise ScenarioError(f'{path} = {shown(value)}: too many entries; at most '
                            f'{MAX_LIST_ITEMS}')
    record = _record_item(typ)
    if record is not None:
        if not isinstance(value, (list, tuple)) or not value:
            raise ScenarioError(f'{path} = {shown(value)}: expected a non-empty list of '
                                f'mappings with keys {_field_names(record)}')
        return tuple(from_mapping(item, record, prefix=f'{path}[{i}].')
                     for i, item in enumerate(value))
    if typ in (tuple[float, ...], tuple[int, ...]):
        kind = typing.get_args(typ)[0]
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(f'{path} = {shown(value)}: expected a list of '
                                f'{"integers" if kind is int else "numbers"} ({spec.unit})')
        items = tuple(_coerce_number(f'{path}[{i}]', v, kind, spec)
                      for i, v in enumerate(value))
        return items
    if typ in (tuple[tuple[float, ...], ...],):
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(f'{path} = {shown(value)}: expected a list of [x, y, z] points '
                                f'({spec.unit})')
        points = []
        for i, point in enumerate(value):
            if not isinstance(point, (list, tuple)) or len(point) != 3:
                raise ScenarioError(f'{path}[{i}] = {shown(point)}: expected a point [x, y, z] '
                                    f'of three numbers ({spec.unit})')
            points.append(tuple(_coerce_number(f'{path}[{i}][{j}]', v, float, spec)
                                for j, v in enumerate(point)))
        return tuple(points)
    if typ in (tuple[str, ...],):
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise ScenarioError(f'{path} = {shown(value)}: expected a list of strings')
        return tuple(value)
    if typ is bool:
        if not isinstance(value, bool):
            raise ScenarioError(f'{path} = {shown(value)}: expected true or false')
        return value
    if typ is str:
        if not isinstance(value, str):
            raise ScenarioError(f'{path} = {shown(value)}: expected a string, {spec.allowed()}')
        if spec.choices is not None and value not in spec.choices:
            raise ScenarioError(f'{path} = {shown(value)}: allowed values are {spec.allowed()}')
        return value
    if typ in (float, int):
        return _coerce_number(path, value, typ, spec)
    raise TypeError(f'unsupported schema type {typ!r} for {path}')  # pragma: no cover


def coerce_value(path: str, value: Any, typ: Any, spec: Spec) -> Any:
    """
    Check one value of key ``path`` against its declared type and range; return it typed.

    Raises
    ------
    ScenarioError
        Naming the key, the value and what is allowed.

    """
    return _coerce(path, value, typ, spec)


def _record_item(typ: Any) -> type | None:
    """Return X for a ``tuple[X, ...]`` of declared records, else None."""
    args = typing.get_args(typ)
    if (typing.get_origin(typ) is tuple and len(args) == 2 and args[1] is Ellipsis
            and dataclasses.is_dataclass(args[0]) and isinstance(args[0], type)):
        return args[0]
    return None


def record_item(typ: Any) -> type | None:
    """Return the record type X of a list-of-records key (``tuple[X, ...]``), else None."""
    return _record_item(typ)


def _field_names(record: type) -> str:
    return ', '.join(f.name for f in dataclasses.fields(record))


def _coerce_number(path: str, value: Any, typ: type, spec: Spec) -> float | int:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        kind = 'an integer' if typ is int else 'a number'
        raise ScenarioError(f'{path} = {shown(value)}: expected {kind}, allowed {spec.allowed()}')
    if typ is int:
        if isinstance(value, float):
            if not value.is_integer():
                raise ScenarioError(f'{path} = {shown(value)}: expected an integer, allowed '
                                    f'{spec.allowed()}')
        value = int(value)
    else:
        value = float(value)
        if not math.isfinite(value):
            raise ScenarioError(f'{path} = {shown(value)}: expected a finite number, allowed '
                                f'{spec.allowed()}')
    if not spec.contains(value):
        raise ScenarioError(f'{path} = {shown(value)} is out of range: allowed {spec.allowed()}')
    return value


def to_plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: to_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_plain(v) for v in value]
    return value
