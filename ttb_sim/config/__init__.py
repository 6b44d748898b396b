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
Scenario configuration: the records, the schema walker and the YAML loader.

``records`` holds one frozen dataclass per scenario section, ``schema`` walks
their declarations (keys, types, ranges) and builds them from plain data, and
``loader`` reads YAML files, built-ins and ``--set`` overrides.

The names below are imported when first used (PEP 562): the records import the
model's parameter records (and through them scipy), about a second, which a verb
refusing a scenario path that does not exist should not wait for. The loader
reads and parses the file before it needs the records.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ttb_sim.lazy_face import lazy_face

if TYPE_CHECKING:
    from ttb_sim.config.loader import (apply_overrides, builtin_scenarios, config_dirs,
                                       DEFAULT_SCENARIO, load_scenario, parse_override,
                                       read_yaml, resolve)
    from ttb_sim.config.observers import Observer, OBSERVER_COMPONENTS, parse_observers
    from ttb_sim.config.records import (car_layout, IrregularityConfig, OutputConfig, Scenario,
                                        SolverConfig, TrainConfig)
    from ttb_sim.config.schema import from_mapping, iter_keys, key_spec, to_plain
    from ttb_sim.declarations import param, Spec

_FACE = {
    'ttb_sim.config.loader': ('apply_overrides', 'builtin_scenarios', 'config_dirs',
                              'DEFAULT_SCENARIO', 'load_scenario', 'parse_override',
                              'read_yaml', 'resolve'),
    'ttb_sim.config.observers': ('Observer', 'OBSERVER_COMPONENTS', 'parse_observers'),
    'ttb_sim.config.records': ('car_layout', 'IrregularityConfig', 'OutputConfig', 'Scenario',
                               'SolverConfig', 'TrainConfig'),
    'ttb_sim.config.schema': ('from_mapping', 'iter_keys', 'key_spec', 'to_plain'),
    'ttb_sim.declarations': ('param', 'Spec'),
}

__all__ = ['apply_overrides', 'builtin_scenarios', 'car_layout', 'config_dirs',
           'DEFAULT_SCENARIO', 'from_mapping',
           'IrregularityConfig', 'iter_keys', 'key_spec', 'load_scenario', 'Observer',
           'OBSERVER_COMPONENTS', 'OutputConfig', 'param', 'parse_observers',
           'parse_override', 'read_yaml', 'resolve', 'Scenario', 'SolverConfig', 'Spec',
           'to_plain', 'TrainConfig']

__getattr__, __dir__ = lazy_face(__name__, _FACE)
