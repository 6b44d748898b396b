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
Declarations of user-settable parameters: :class:`Spec` and :func:`param`.

Every record field a user may set (in a scenario file, with ``--set`` or as a
ROS parameter) is declared once with :func:`param`, which stores its default,
unit, allowed range or choices and a description in the dataclass field's
metadata.  The records live with the code that uses them (the car record in
``model/vehicle``, the scenario sections in ``config/``); the configuration
layer walks the declarations to validate input, list keys and describe ROS
parameters.  This module depends on nothing else in the package.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import math
from typing import Any, Sequence

from ttb_sim.errors import ModelError
from ttb_sim.inputs import shown

__all__ = ['check_declared', 'param', 'Spec']


@dataclass(frozen=True)
class Spec:
    """The declaration of one scenario key."""

    unit: str
    description: str
    low: float | None = None
    high: float | None = None
    low_inclusive: bool = True
    high_inclusive: bool = True
    choices: tuple[str, ...] | None = None
    dynamic: bool = False

    def allowed(self) -> str:
        """Describe the allowed values in words, for error messages and help."""
        if self.choices is not None:
            return 'one of ' + ', '.join(repr(c) for c in self.choices)
        if self.low is None and self.high is None:
            return 'any value'
        lo = '(-inf' if self.low is None else ('[' if self.low_inclusive else '(') + _num(self.low)
        hi = 'inf)' if self.high is None else (
            _num(self.high) + (']' if self.high_inclusive else ')'))
        unit = f' {self.unit}' if self.unit not in ('', '-') else ''
        return f'{lo}, {hi}{unit}'

    def contains(self, value: float) -> bool:
        """Tell whether a number lies inside the declared range."""
        if self.low is not None:
            if value < self.low or (value == self.low and not self.low_inclusive):
                return False
        if self.high is not None:
            if value > self.high or (value == self.high and not self.high_inclusive):
                return False
        return True


def _num(value: float) -> str:
    if float(value).is_integer() and abs(value) < 1e10:
        return str(int(value))
    return f'{value:g}'


def param(default: Any, unit: str, description: str, *, low: float | None = None,
          high: float | None = None, low_inclusive: bool = True, high_inclusive: bool = True,
          choices: Sequence[str] | None = None, dynamic: bool = False) -> Any:
    """
    Declare a scenario key with its default, unit, range and description.

    Parameters
    ----------
    default
        Value used when the scenario file does not set the key.
    unit
        SI unit of the value ('-' when dimensionless).
    description
        One sentence for users, shown by ``ttb-sim scenarios --keys`` and ROS.
    low, high, low_inclusive, high_inclusive
        Allowed numeric range (each bound optional).
    choices
        Allowed strings, for enumerations.
    dynamic
        True when the running ROS node may change the key.

    Returns
    -------
    dataclasses.Field
        The field, carrying its :class:`Spec` in ``metadata['spec']``.

    """
    spec = Spec(unit=unit, description=description, low=low, high=high,
                low_inclusive=low_inclusive, high_inclusive=high_inclusive,
                choices=tuple(choices) if choices is not None else None, dynamic=dynamic)
    return field(default=default, metadata={'spec': spec})


def check_declared(record: Any, what: str, error: type[ModelError] = ModelError) -> None:
    """
    Check every declared field of a record instance against its :class:`Spec`.

    Numbers must be finite, of the declared kind (an integer where the field is
    ``int``; never a bool for a number) and inside the declared range; strings
    must be one of the declared choices; flags must be bools.

    Parameters
    ----------
    record
        A dataclass instance whose fields were declared with :func:`param`.
    what
        How to name the record in messages, e.g. ``'car parameter'``; a name
        ending in '.' is a key prefix (``'piles.'`` names ``piles.nu``).
    error
        The exception raised (a :class:`ModelError` subclass of the record's
        component).

    Raises
    ------
    ModelError
        Naming the field, the value and what is allowed.

    """
    for f in dataclasses.fields(record):
        spec = f.metadata.get('spec')
        if spec is None:
            continue
        value = getattr(record, f.name)
        name = f'{what}{f.name}' if what.endswith('.') else f'{what} {f.name}'
        kind = f.type if isinstance(f.type, str) else getattr(f.type, '__name__', '')
        if kind == 'bool':
            if not isinstance(value, bool):
                raise error(f'{name} = {shown(value)} is invalid; allowed: true or false')
        elif kind in ('int', 'float'):
            number = isinstance(value, (int, float)) and not isinstance(value, bool)
            if kind == 'int' and not isinstance(value, int):
                number = False
            if not number or not math.isfinite(value) or not spec.contains(value):
                integer = 'an integer in ' if kind == 'int' else ''
                raise error(f'{name} = {shown(value)} is invalid; allowed: '
                            f'{integer}{spec.allowed()}')
        elif kind == 'str' and spec.choices is not None and value not in spec.choices:
            raise error(f'{name} = {shown(value)} is invalid; allowed: {spec.allowed()}')
