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
The node's parameters: their table, validation, start-up values, passage scenarios.

:func:`parameter_table` derives the node's parameters from the scenario schema
(:func:`ttb_sim.config.key_spec`), adding a few node-only ones, so unit, range
and description are written once. :func:`validate_parameter` checks one
proposed value and returns ``(ok, reason)``; the reason names the parameter, the
value and what is allowed. :func:`validate_changes` checks a set at once (all or
nothing, as rclpy sets them), :func:`normalize_value` gives a value the
parameter's own type (``350`` -> ``350.0``), :func:`initial_values` merges the
start-up values with the defaults, and :func:`scenario_with` builds the scenario
of a passage from the current values.

Irregularity parameters (``irregularity.*``) apply from the next passage (a loop
restart or a reset), because the track irregularity of a passage is generated
when the passage starts; the speed (``train.speed_kmh``) applies at the next
solver step.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from pathlib import Path
import sys
from typing import Any, Mapping

from ttb_sim.config import apply_overrides, from_mapping, key_spec, Scenario, Spec
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.io.bag import STORAGES
from ttb_sim.node.rates import RATE_PARAMETERS

DEFAULT_SCENARIO = 'live_coupled'
"""Scenario loaded when the ``scenario`` parameter is not given."""

SCENARIO_KEYS = ('train.speed_kmh', 'irregularity.spectrum', 'irregularity.seed',
                 'irregularity.file', 'irregularity.scale', 'environment.temperature',
                 'train.passenger_load')
"""Node parameters that are scenario keys (same name, unit, range and description)."""

QOS_RELIABILITIES = ('reliable', 'best_effort')
"""Values of the ``qos.reliability`` parameter."""

INT64 = (-2 ** 63, 2 ** 63 - 1)
"""The range of a ROS integer parameter."""

IRREGULARITY_KEYS = tuple(k for k in SCENARIO_KEYS if k.startswith('irregularity.'))
"""The irregularity parameters (they apply from the next passage)."""

STATE_KEYS = ('environment.temperature', 'train.passenger_load')
"""Scenario keys of the structure's state and the train's load, set per passage."""

DAMAGE_PARAMETER = 'damage'
"""The node parameter holding the ``damage`` section as YAML ('' = the scenario's)."""

PASSAGE_KEYS = IRREGULARITY_KEYS + STATE_KEYS + (DAMAGE_PARAMETER,)
"""The parameters that apply from the next passage (its model is built with them)."""


@dataclass(frozen=True)
class NodeParameter:
    """
    One parameter of the node, as declared to ROS.

    Attributes
    ----------
    name : str
        Parameter name (dotted, as in the scenario schema).
    kind : str
        ROS parameter type: 'bool', 'integer', 'double' or 'string'.
    default : Any
        Declared default value.
    spec : Spec
        Unit, range or choices and description (shared with the scenario schema).
    read_only : bool
        True for structural parameters, fixed for the life of the node.
    applies : str
        When a change takes effect: 'immediately', 'next passage' or 'restart'.
    scenario_key : str or None
        The scenario key this parameter sets, if any.

    """

    name: str
    kind: str
    default: Any
    spec: Spec
    read_only: bool = False
    applies: str = 'immediately'
    scenario_key: str | None = None

    @property
    def accepts_integer(self) -> bool:
        """Tell whether an integer value is accepted (double parameters: ``350`` = 350.0)."""
        return self.kind == 'double'

    @property
    def unit(self) -> str:
        """Unit of the value ('-' when dimensionless)."""
        return self.spec.unit

    def allowed(self) -> str:
        """Describe the allowed values in words."""
        if self.kind == 'bool':
            return 'true or false'
        if self.kind == 'string' and self.spec.choices is None:
            return 'any string'
        return self.spec.allowed()

    def description(self) -> str:
        """Return the description shown by ``ros2 param describe`` (with unit and range)."""
        unit = self.unit if self.unit not in ('', '-') else 'dimensionless'
        if self.kind in ('bool', 'string'):
            unit_text = ''
        else:
            unit_text = f' Unit: {unit}.'
        when = {'immediately': 'Changes apply immediately.',
                'next passage': 'Changes apply from the next passage (loop restart or '
                                '~/reset).',
                'restart': 'Read-only: set it when starting the node.'}[self.applies]
        return f'{self.spec.description}{unit_text} Allowed: {self.allowed()}. {when}'


_NODE_ONLY: dict[str, tuple[str, Any, Spec, bool]] = {
    'scenario': ('string', DEFAULT_SCENARIO, Spec(
        '-', 'Scenario to simulate: a YAML path or a built-in name (ttb-sim scenarios).'),
        True),
    'publish_rate_hz': ('double', 50.0, Spec(
        'Hz', 'Rate of live messages in simulation time; 0 publishes every frame (the bag '
        'always gets every frame).', low=0.0, high=10000.0), False),
    **{name: ('double', 0.0, Spec(
        'Hz', f'Rate of the live {family}/... topics in simulation time; 0 = publish_rate_hz. '
        'Rounded to a whole number of output frames; above the output rate is refused.',
        low=0.0, high=10000.0), False) for name, family in RATE_PARAMETERS.items()},
    'qos.reliability': ('string', 'reliable', Spec(
        '-', "Reliability of the data topics: 'reliable' (ros2 bag record and echo get "
        "every message) or 'best_effort' (rclpy's sensor-data QoS: a slow subscriber "
        'misses messages instead of holding the publisher up).',
        choices=QOS_RELIABILITIES), True),
    'real_time_factor': ('double', 1.0, Spec(
        '-', 'Simulated seconds per wall-clock second; 0 = as fast as possible.',
        low=0.0, high=1000.0), False),
    'loop': ('bool', True, Spec(
        '-', 'Start a new passage when the train has left (otherwise the node idles).'),
        False),
    'publish_clock': ('bool', True, Spec(
        '-', 'Publish simulation time on /clock.'), False),
    'bag.enabled': ('bool', False, Spec(
        '-', 'Record every topic at the full output rate to a rosbag2.'), True),
    'bag.path': ('string', '', Spec(
        '-', "Bag directory to create (must not exist); '' = runs/<scenario>-<time>."), True),
    'bag.storage': ('string', 'mcap', Spec(
        '-', 'rosbag2 storage plugin.', choices=tuple(STORAGES)), True),
    DAMAGE_PARAMETER: ('string', '', Spec(
        '-', "The damage section as YAML, e.g. '{girders: [{span: 7, start: 14, length: 4, "
        "loss: 0.3}]}' (docs/damage.md); '' = the scenario's own. The labels and "
        'the bag show the switch.'), False),
}

_KIND_OF = {float: 'double', int: 'integer', str: 'string', bool: 'bool'}


def _scenario_value(scenario: Scenario, key: str) -> Any:
    value: Any = scenario
    for part in key.split('.'):
        value = getattr(value, part)
    return value


def parameter_table(scenario: Scenario | None = None) -> dict[str, NodeParameter]:
    """
    Return the node's parameters, in declaration order.

    Parameters
    ----------
    scenario : Scenario, optional
        The loaded scenario; the scenario-key parameters default to its values
        (the schema defaults when omitted).

    Returns
    -------
    dict
        Parameter name -> :class:`NodeParameter`.

    """
    table: dict[str, NodeParameter] = {}
    kind, default, spec, read_only = _NODE_ONLY['scenario']
    table['scenario'] = NodeParameter('scenario', kind, default, spec, read_only, 'restart')
    for key in SCENARIO_KEYS:
        typ, schema_default, spec = key_spec(key)
        value = schema_default if scenario is None else _scenario_value(scenario, key)
        applies = 'next passage' if key in PASSAGE_KEYS else 'immediately'
        table[key] = NodeParameter(key, _KIND_OF[typ], value, spec, not spec.dynamic,
                                   applies if spec.dynamic else 'restart', key)
    for name, (kind, default, spec, read_only) in _NODE_ONLY.items():
        if name != 'scenario':
            applies = 'next passage' if name in PASSAGE_KEYS else 'immediately'
            table[name] = NodeParameter(name, kind, default, spec, read_only,
                                        'restart' if read_only else applies)
    return table


def validate_parameter(param: NodeParameter, value: Any, *,
                       initial: bool = False) -> tuple[bool, str]:
    """
    Check one proposed parameter value.

    Parameters
    ----------
    param : NodeParameter
        The parameter's declaration.
    value : Any
        Proposed value (as rclpy delivers it: bool, int, float, str or None).
    initial : bool
        True when checking the value given at start-up, where read-only
        parameters may be set.

    Returns
    -------
    tuple of (bool, str)
        ``(True, '')`` when acceptable, else ``(False, reason)``; the reason
        names the parameter, the value and the allowed values.

    """
    name, allowed = param.name, param.allowed()
    if param.read_only and not initial:
        return False, (f'{name} is read-only (allowed {allowed}); set it when starting the '
                       f'node, e.g. --ros-args -p {name}:=...')
    if param.kind == 'bool':
        if not isinstance(value, bool):
            return False, f'{name} = {shown(value)}: expected a bool, allowed {allowed}'
        return True, ''
    if param.kind == 'string':
        if not isinstance(value, str):
            return False, f'{name} = {shown(value)}: expected a string, allowed {allowed}'
        if param.spec.choices is not None and value not in param.spec.choices:
            return False, f'{name} = {shown(value)} is not allowed: allowed {allowed}'
        if name == 'irregularity.file' and value and not Path(value).is_file():
            return False, (f'{name} = {shown(value)}: no such file (allowed: a readable CSV '
                           "path, or '' to synthesise from the spectrum)")
        return True, ''
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        kind = 'an integer' if param.kind == 'integer' else 'a number'
        return False, f'{name} = {shown(value)}: expected {kind}, allowed {allowed}'
    if param.kind == 'integer' and isinstance(value, float) and not value.is_integer():
        return False, f'{name} = {shown(value)}: expected an integer, allowed {allowed}'
    if not math.isfinite(value):
        return False, f'{name} = {shown(value)}: expected a finite number, allowed {allowed}'
    if not param.spec.contains(value):
        return False, f'{name} = {shown(value)} is out of range: allowed {allowed}'
    return True, ''


def validate_changes(table: Mapping[str, NodeParameter],
                     changes: Mapping[str, Any]) -> tuple[bool, str]:
    """
    Check a set of changes at once (all or nothing, as rclpy sets them).

    Parameters
    ----------
    table : mapping
        The parameter table.
    changes : mapping
        Parameter name -> proposed value.

    Returns
    -------
    tuple of (bool, str)
        The first refusal, or ``(True, '')``.

    """
    for name, value in changes.items():
        param = table.get(name)
        if param is None:
            return False, f'unknown parameter {shown(name)}; known: {", ".join(table)}'
        ok, reason = validate_parameter(param, value)
        if not ok:
            return ok, reason
    return True, ''


@dataclass(frozen=True)
class NumericRange:
    """
    The closed range (and step) of a numeric parameter, as a ROS descriptor states it.

    ``FloatingPointRange`` / ``IntegerRange`` bounds are inclusive, so an open bound
    of the schema becomes the next representable value inside it: the speed,
    refused at 0 km/h, has ``from_value`` 5e-324 (the least positive double), an
    integer refused at 0 starts at 1. A side without a bound is the largest
    double or the int64 limit.
    """

    from_value: float
    to_value: float
    step: float


def descriptor_range(param: NodeParameter) -> NumericRange | None:
    """
    Return the descriptor range of a numeric parameter that has a bound (None otherwise).

    Every value :func:`validate_parameter` accepts lies in the range, and every finite
    value in it that the schema's range holds is accepted (``test_parameters.py``).
    """
    spec = param.spec
    if param.kind not in ('double', 'integer') or (spec.low is None and spec.high is None):
        return None
    if param.kind == 'integer':
        low = INT64[0] if spec.low is None else math.ceil(spec.low)
        high = INT64[1] if spec.high is None else math.floor(spec.high)
        if spec.low is not None and not spec.low_inclusive and low == spec.low:
            low += 1
        if spec.high is not None and not spec.high_inclusive and high == spec.high:
            high -= 1
        return NumericRange(int(low), int(high), 1)
    big = sys.float_info.max
    flow = -big if spec.low is None else float(spec.low)
    fhigh = big if spec.high is None else float(spec.high)
    if spec.low is not None and not spec.low_inclusive:
        flow = math.nextafter(flow, math.inf)
    if spec.high is not None and not spec.high_inclusive:
        fhigh = math.nextafter(fhigh, -math.inf)
    return NumericRange(flow, fhigh, 0.0)


def normalize_value(param: NodeParameter, value: Any) -> Any:
    """Return a validated value in the parameter's own type (an int 350 -> 350.0)."""
    if param.kind == 'double':
        return float(value)
    if param.kind == 'integer':
        return int(value)
    return value


def initial_values(table: Mapping[str, NodeParameter],
                   given: Mapping[str, Any]) -> dict[str, Any]:
    """
    Merge start-up values with the defaults, validating each.

    Parameters
    ----------
    table : mapping
        The parameter table.
    given : mapping
        Values set at start-up (parameter overrides); missing names take defaults.

    Returns
    -------
    dict
        Every parameter's value, normalised to its type.

    Raises
    ------
    ScenarioError
        On the first invalid value (the message names the parameter and range).

    """
    values: dict[str, Any] = {}
    for name, param in table.items():
        value = given.get(name, param.default)
        ok, reason = validate_parameter(param, value, initial=True)
        if not ok:
            raise ScenarioError(reason)
        values[name] = normalize_value(param, value)
    return values


def scenario_with(scenario: Scenario, values: Mapping[str, Any]) -> Scenario:
    """
    Return a copy of a scenario with dotted keys replaced (validated again).

    Raises
    ------
    ScenarioError
        If a key is unknown or the combination is invalid.

    """
    data = scenario.to_dict()
    values = dict(values)
    damage = values.pop(DAMAGE_PARAMETER, '')
    apply_overrides(data, list(values.items()))
    if damage:
        data['damage'] = damage_section(damage)
    out = from_mapping(data)
    from ttb_sim.config.conditions import check_conditions
    check_conditions(out)   # what load_scenario checks beyond the records
    return out


def damage_section(text: str) -> Any:
    """
    Parse the ``damage`` parameter: a YAML (or JSON) mapping of the damage section.

    Raises
    ------
    ScenarioError
        Naming the parameter when the text is not YAML or not a mapping.

    """
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(f'{DAMAGE_PARAMETER} = {shown(text)}: not YAML '
                            f'({" ".join(str(exc).split())[:200]})') from None
    if not isinstance(data, dict):
        raise ScenarioError(f'{DAMAGE_PARAMETER} = {shown(text)}: expected a mapping such as '
                            "'{girders: [{span: 7, start: 14, length: 4, loss: 0.3}]}'")
    return data
