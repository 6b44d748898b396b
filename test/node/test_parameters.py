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

"""Tests of the node's parameters: table from the schema, validation, start-up values."""

from __future__ import annotations

import math

import pytest
from ttb_sim.config import key_spec
from ttb_sim.errors import ScenarioError
from ttb_sim.node.parameters import (descriptor_range, initial_values, parameter_table,
                                     SCENARIO_KEYS,
                                     validate_changes, validate_parameter)
from ttb_sim.node.rates import RATE_PARAMETERS

CONTRACT_PARAMETERS = {
    'scenario', 'train.speed_kmh', 'irregularity.spectrum', 'irregularity.seed',
    'irregularity.file', 'irregularity.scale', 'publish_rate_hz', 'real_time_factor', 'loop',
    'publish_clock', 'bag.enabled', 'bag.path', 'bag.storage'}
NODE_PARAMETERS = CONTRACT_PARAMETERS | set(RATE_PARAMETERS) | {
    'qos.reliability', 'environment.temperature', 'train.passenger_load', 'damage'}


# -- parameter table ------------------------------------------------------------------------

def test_parameter_names_are_the_contract_and_the_node_extras(beam):
    assert set(parameter_table(beam)) == NODE_PARAMETERS


def test_scenario_parameters_come_from_the_schema(beam):
    table = parameter_table(beam)
    kinds = {float: 'double', int: 'integer', str: 'string'}
    for key in SCENARIO_KEYS:
        typ, _, spec = key_spec(key)
        p = table[key]
        assert p.spec is spec
        assert p.kind == kinds[typ]
        assert p.scenario_key == key
        assert p.read_only is not spec.dynamic
        assert spec.description in p.description()
    # defaults follow the loaded scenario, not the schema
    assert table['train.speed_kmh'].default == 200.0
    assert parameter_table()['train.speed_kmh'].default == key_spec('train.speed_kmh')[1]


def test_descriptions_carry_unit_range_and_when_changes_apply(beam):
    table = parameter_table(beam)
    speed = table['train.speed_kmh'].description()
    assert 'Unit: km/h' in speed and '(0, 10000] km/h' in speed and 'immediately' in speed
    assert 'next passage' in table['irregularity.seed'].description()
    assert 'Unit: Hz' in table['publish_rate_hz'].description()
    assert 'Read-only' in table['bag.storage'].description()
    assert "'mcap', 'sqlite3'" in table['bag.storage'].description()


def test_read_only_parameters_are_structural(beam):
    ro = {n for n, p in parameter_table(beam).items() if p.read_only}
    assert ro == {'scenario', 'bag.enabled', 'bag.path', 'bag.storage', 'qos.reliability'}


def test_spectrum_choices_are_read_from_the_schema(beam):
    p = parameter_table(beam)['irregularity.spectrum']
    assert p.spec.choices == key_spec('irregularity.spectrum')[2].choices
    for choice in p.spec.choices:
        assert validate_parameter(p, choice) == (True, '')


# -- validation -----------------------------------------------------------------------------

@pytest.mark.parametrize('value', [350, 350.0, 1, 10000])
def test_integer_and_float_speed_accepted(beam, value):
    assert validate_parameter(parameter_table(beam)['train.speed_kmh'], value) == (True, '')


@pytest.mark.parametrize('name, value, fragments', [
    ('train.speed_kmh', -5, ['train.speed_kmh', '-5', 'out of range', '(0, 10000] km/h']),
    ('train.speed_kmh', 0.0, ['train.speed_kmh', '0.0', '(0, 10000] km/h']),
    ('train.speed_kmh', 10000.5, ['train.speed_kmh', '10000.5', '(0, 10000] km/h']),
    ('train.speed_kmh', 'fast', ['train.speed_kmh', "'fast'", 'a number', '(0, 10000]']),
    ('train.speed_kmh', True, ['train.speed_kmh', 'True', 'a number']),
    ('train.speed_kmh', None, ['train.speed_kmh', 'None', 'a number']),
    ('train.speed_kmh', math.nan, ['train.speed_kmh', 'nan', 'finite']),
    ('irregularity.seed', -1, ['irregularity.seed', '-1', '[0, 2147483647]']),
    ('irregularity.seed', 1.5, ['irregularity.seed', '1.5', 'an integer']),
    ('irregularity.scale', 101, ['irregularity.scale', '101', '[0, 100]']),
    ('irregularity.spectrum', 'no_such', ['irregularity.spectrum', "'no_such'", "one of 'none'"]),
    ('irregularity.file', '/no/such/profile.csv', ['irregularity.file', 'no such file']),
    ('publish_rate_hz', -1.0, ['publish_rate_hz', '-1.0', '[0, 10000] Hz']),
    ('real_time_factor', -0.5, ['real_time_factor', '-0.5', '[0, 1000]']),
    ('loop', 'yes', ['loop', "'yes'", 'true or false']),
    ('publish_clock', 1, ['publish_clock', 'a bool']),
    ('scenario', 'sprung_mass_beam', ['scenario', 'read-only']),
    ('bag.enabled', True, ['bag.enabled', 'read-only']),
    ('bag.storage', 'sqlite3', ['bag.storage', 'read-only', "'mcap', 'sqlite3'"]),
])
def test_refusals_name_parameter_value_and_range(beam, name, value, fragments):
    ok, reason = validate_parameter(parameter_table(beam)[name], value)
    assert not ok
    for fragment in fragments:
        assert fragment in reason, reason


def test_changes_are_checked_all_or_nothing(beam):
    table = parameter_table(beam)
    ok, reason = validate_changes(table, {'train.speed_kmh': 350, 'irregularity.scale': -1})
    assert not ok and 'irregularity.scale' in reason
    ok, reason = validate_changes(table, {'no.such': 1})
    assert not ok and "unknown parameter 'no.such'" in reason
    assert validate_changes(table, {'train.speed_kmh': 350, 'loop': True}) == (True, '')


def test_start_up_values_validated_and_normalised(beam):
    table = parameter_table(beam)
    values = initial_values(table, {'train.speed_kmh': 350, 'bag.enabled': True})
    assert values['train.speed_kmh'] == 350.0 and isinstance(values['train.speed_kmh'], float)
    assert values['bag.enabled'] is True  # read-only values may be set at start-up
    assert values['publish_rate_hz'] == 50.0
    with pytest.raises(ScenarioError, match=r'train\.speed_kmh = -5 .*\(0, 10000\] km/h'):
        initial_values(table, {'train.speed_kmh': -5})
    with pytest.raises(ScenarioError, match=r"bag\.storage = 'zip'.*'mcap', 'sqlite3'"):
        initial_values(table, {'bag.storage': 'zip'})


# -- descriptor ranges ----------------------------------------------------------------------

PARAM_REL_TOL = 1e-6
"""rclpy's Node.PARAM_REL_TOL (jazzy): a value this close to a bound is always accepted."""


def rclpy_accepts(rng, value) -> bool:
    """Emulate rclpy's range check of a descriptor (jazzy node.py _apply_*_range)."""
    if isinstance(rng.step, int):   # IntegerRange
        return rng.from_value <= value <= rng.to_value
    if (math.isclose(value, rng.from_value, rel_tol=PARAM_REL_TOL)
            or math.isclose(value, rng.to_value, rel_tol=PARAM_REL_TOL)):
        return True
    return rng.from_value < value < rng.to_value


def probes(param):
    spec = param.spec
    out = [0, 1, -1, 0.5, 1e-300, -1e-300, 350, 1e9, -1e9]
    for bound in (spec.low, spec.high):
        if bound is not None:
            out += [bound, bound + 1, bound - 1, bound * (1 + 1e-3) + 1e-3,
                    bound * (1 - 1e-3) - 1e-3]
    if param.kind == 'integer':
        return sorted({int(v) for v in out})
    return sorted({float(v) for v in out})


def test_the_speed_range_says_zero_is_refused(beam):
    param = parameter_table(beam)['train.speed_kmh']
    rng = descriptor_range(param)
    assert rng.from_value > 0 and rng.from_value == math.nextafter(0.0, 1.0)
    assert not rclpy_accepts(rng, 0.0)
    assert not validate_parameter(param, 0.0)[0]
    assert validate_parameter(param, rng.from_value)[0]
    assert rng.to_value == 10000.0 and rng.step == 0.0


@pytest.mark.parametrize('name', sorted(NODE_PARAMETERS))
def test_descriptor_range_is_exactly_what_validation_accepts(beam, name):
    param = parameter_table(beam)[name]
    rng = descriptor_range(param)
    if param.kind not in ('double', 'integer'):
        assert rng is None
        return
    assert rng is not None, f'{name} has a numeric range but no descriptor range'
    for value in probes(param):
        if name == 'irregularity.file':
            continue
        ok = validate_parameter(param, value, initial=True)[0]
        assert ok == rclpy_accepts(rng, value), (name, value, rng)
