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

"""The observers of ``output.observers``: named displacement points ``name=component@x``."""

from __future__ import annotations

from dataclasses import dataclass
import math
import re
from typing import Sequence

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

__all__ = ['Observer', 'OBSERVER_COMPONENTS', 'parse_observers']

OBSERVER_COMPONENTS = ('rail_left', 'rail_right', 'slab', 'base', 'girder')
_OBSERVER = re.compile(r'^([A-Za-z][A-Za-z0-9_]*)=([a-z_]+)@(.+)$')


@dataclass(frozen=True)
class Observer:
    """A named displacement observation point (``output.observers``)."""

    name: str
    component: str
    x: float


def parse_observers(entries: Sequence[str]) -> tuple[Observer, ...]:
    """
    Parse ``output.observers`` entries of the form ``name=component@x``.

    Raises
    ------
    ScenarioError
        Naming the entry and what is allowed, for a malformed entry, an unknown
        component, a non-finite position or a repeated name.

    """
    out: list[Observer] = []
    for i, entry in enumerate(entries):
        path = f'output.observers[{i}] = {shown(entry)}'
        match = _OBSERVER.match(entry.strip())
        if not match:
            raise ScenarioError(f"{path}: expected 'name=component@x' with a name of "
                                'letters, digits and _ (starting with a letter)')
        name, component, x_text = match.groups()
        if component not in OBSERVER_COMPONENTS:
            raise ScenarioError(f'{path}: component {shown(component)} is unknown; allowed: '
                                f'{", ".join(OBSERVER_COMPONENTS)}')
        try:
            x = float(x_text)
        except ValueError:
            x = math.nan
        if not math.isfinite(x):
            raise ScenarioError(f'{path}: position {shown(x_text)} is not a finite number (m)')
        if any(o.name == name for o in out):
            raise ScenarioError(f'{path}: observer name {shown(name)} is used twice')
        out.append(Observer(name, component, x))
    return tuple(out)
