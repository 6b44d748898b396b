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

"""Keys whose value is a list of records (e.g. soil layers): typed, defaulted, checked by path."""

from dataclasses import asdict, dataclass, field

import pytest
from ttb_sim.config import from_mapping, iter_keys, to_plain
from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ScenarioError


@dataclass(frozen=True)
class Layer:
    thickness: float = param(1.0, 'm', 'Layer thickness.', low=0.0, low_inclusive=False)
    E: float = param(5e6, 'Pa', 'Young modulus.', low=0.0, low_inclusive=False)
    c: float = param(1e4, 'Pa', 'Cohesion.', low=0.0)

    def __post_init__(self) -> None:
        check_declared(self, 'layer')


@dataclass(frozen=True)
class Ground:
    layers: tuple[Layer, ...] = param((Layer(),), '-', 'Layers, top down.')
    name: str = param('g', '-', 'A name.')


@dataclass(frozen=True)
class Root:
    ground: Ground = field(default_factory=Ground)


def test_a_list_of_mappings_builds_records_with_defaults_for_missing_keys():
    root = from_mapping({'ground': {'layers': [{'thickness': 2, 'E': 4e6},
                                               {'thickness': 20.0}]}}, Root)
    assert root.ground.layers == (Layer(2.0, 4e6, 1e4), Layer(20.0, 5e6, 1e4))
    assert to_plain(asdict(root))['ground']['layers'][1] == {
        'thickness': 20.0, 'E': 5e6, 'c': 1e4}
    assert [k for k, *_ in iter_keys(Root)] == ['ground.layers', 'ground.name']


@pytest.mark.parametrize('value, match', [
    ([], 'non-empty list of mappings with keys thickness, E, c'),
    (5, 'non-empty list'),
    ([{'thickness': 0.0}], r'ground.layers\[0\].thickness = 0.0 is out of range'),
    ([{'thickness': 1.0}, {'depth': 3}], r"unknown key 'ground.layers\[1\].depth'"),
    (['x' * 1000], 'must be a mapping'),
])
def test_refusals_name_the_item_path(value, match):
    with pytest.raises(ScenarioError, match=match):
        from_mapping({'ground': {'layers': value}}, Root)
