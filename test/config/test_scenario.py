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

"""Scenario schema: loading, overrides and refusals that name the key, value and range."""

from pathlib import Path

import pytest
from ttb_sim.config import (builtin_scenarios, from_mapping, iter_keys, key_spec, load_scenario,
                            Scenario)
from ttb_sim.errors import ScenarioError

CONTRACT_KEYS = ('bridge.span_length', 'bridge.bending_stiffness', 'bridge.mass_per_length',
                 'bridge.damping_ratio', 'train.speed_kmh', 'train.axle_load',
                 'train.sprung_mass', 'train.suspension_stiffness',
                 'train.suspension_damping', 'solver.dt', 'irregularity.seed',
                 'irregularity.scale')


def test_contract_builtins_and_keys_exist():
    names = builtin_scenarios()
    assert {'moving_force_beam', 'sprung_mass_beam'} <= set(names)
    for key in CONTRACT_KEYS:
        key_spec(key)


def test_every_key_has_unit_and_description():
    for key, _typ, _default, spec in iter_keys():
        assert spec.unit, key
        assert spec.description.endswith('.'), key


def test_every_builtin_loads():
    for name in builtin_scenarios():
        assert isinstance(load_scenario(name), Scenario)


def test_overrides_are_yaml_scalars():
    s = load_scenario('moving_force_beam', ['bridge.span_length=25', 'train.axle_load=1e5',
                                            'bridge.n_spans=3'])
    assert s.bridge.span_length == 25.0 and isinstance(s.bridge.span_length, float)
    assert s.train.axle_load == 1e5
    assert s.bridge.n_spans == 3


@pytest.mark.parametrize('override, match', [
    ('bridge.spam=3', r"unknown key 'bridge.spam'"),
    ('bridge.span_length=-3', r'bridge.span_length = -3.0 is out of range: allowed \(0, 500\]'),
    ('train.speed_kmh=0', r'train.speed_kmh = 0.0 is out of range: allowed \(0, 10000\] km/h'),
    ('bridge.span_length=abc', r"bridge.span_length = 'abc': expected a number"),
    ('bridge.n_spans=2.5', r'bridge.n_spans = 2.5: expected an integer'),
    ('bridge.damping_ratio=true', r'bridge.damping_ratio = True: expected a number'),
    ('train.vehicle=tram', r"train.vehicle = 'tram': allowed values are one of"),
    ('bridge.elements_per_span=15', r'must be even'),
    ('foundation.model=springs', r"needs bearings.model = 'elastic'"),
    ('bridge.span_length', r'expected KEY=VALUE'),
    ('train=5', r'train = 5: train is a section, not a value; set one of its keys, e\.g\. '
     r'train\.speed_kmh \(its 12 keys: train\.vehicle, '),
    ('soil.mesh={h: 1}', r"soil.mesh = \{'h': 1\}: soil.mesh is a section, not a value; set one "
     r'of its keys, e\.g\. soil\.mesh\.h \(its 7 keys'),
    ('output=', r"output = '': output is a section, not a value; .* 5 keys: output.rate_hz, "
     r'output.observers, output.soil_points, output.soil_grid_spacing, \.\.\.; see'),
])
def test_refusals_name_key_value_and_range(override, match):
    with pytest.raises(ScenarioError, match=match):
        load_scenario('moving_force_beam', [override])


def test_key_spec_names_a_section_and_its_keys():
    with pytest.raises(ScenarioError, match=r'^car is a section, not a value; set one of its '
                       r'keys, e\.g\. car\.car_body_mass \(its 37 keys: '):
        key_spec('car')
    with pytest.raises(ScenarioError, match=r"^unknown key 'cars'"):
        key_spec('cars')


def test_unknown_key_in_file(tmp_path: Path):
    path = tmp_path / 'bad.yaml'
    path.write_text('bridge:\n  span_lenght: 30\n')
    with pytest.raises(ScenarioError, match=r"unknown key 'bridge.span_lenght'; allowed here"):
        load_scenario(path)


def test_unreadable_and_missing_files(tmp_path: Path):
    with pytest.raises(ScenarioError, match='does not exist'):
        load_scenario(tmp_path / 'nope.yaml')
    with pytest.raises(ScenarioError, match='no scenario'):
        load_scenario('no_such_builtin')
    bad = tmp_path / 'broken.yaml'
    bad.write_text('bridge: [1, 2\n')
    with pytest.raises(ScenarioError, match='not valid YAML'):
        load_scenario(bad)
    binary = tmp_path / 'binary.yaml'
    binary.write_bytes(b'\xff\xfe\x00')
    with pytest.raises(ScenarioError, match='cannot read'):
        load_scenario(binary)


def test_axle_layout_from_car_geometry():
    s = load_scenario('moving_force_beam', ['train.axle_offsets=[]', 'train.n_cars=2'])
    axles = s.axle_positions()
    assert len(axles) == 8
    # Wheelbase 2 l_t, bogie centres 2 l_c apart, cars 25 m apart.
    assert axles[1] - axles[0] == pytest.approx(2.5)
    assert axles[2] - axles[0] == pytest.approx(15.7)
    assert axles[4] - axles[0] == pytest.approx(25.0)


def test_old_car_geometry_keys_still_set_the_car_record():
    """train.bogie_semi_spacing / wheelbase_semi are aliases of the car record's keys."""
    s = load_scenario('moving_force_beam', ['train.bogie_semi_spacing=7.0',
                                            'train.wheelbase_semi=1.5', 'train.axle_offsets=[]',
                                            'train.n_cars=1'])
    assert (s.car.bogie_semi_spacing, s.car.wheelbase_semi) == (7.0, 1.5)
    axles = s.axle_positions()
    assert axles[1] - axles[0] == pytest.approx(3.0)
    assert axles[2] - axles[0] == pytest.approx(14.0)
    with pytest.raises(ScenarioError, match='old name of car.wheelbase_semi'):
        from_mapping({'train': {'wheelbase_semi': 1.5}, 'car': {'wheelbase_semi': 1.2}})
    last = load_scenario('moving_force_beam', ['train.wheelbase_semi=1.5',
                                               'car.wheelbase_semi=1.2'])
    assert last.car.wheelbase_semi == 1.2  # --set values apply in order
