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

"""The ``scenarios`` verb: list the built-in scenarios or every scenario key."""

from __future__ import annotations

from ttb_sim.config import builtin_scenarios, iter_keys, read_yaml, to_plain
from ttb_sim.config.schema import ALIASES, record_item

EXIT_OK = 0


def scenarios(*, keys: bool = False) -> int:
    """Run ``ttb-sim scenarios``: the built-ins, or with ``keys`` every key and its range."""
    if keys:
        for key, typ, default, spec in iter_keys():
            item = record_item(typ)
            if item is not None:
                print(f'{key:34s} {"list":9s} default {len(default)} entries\n'
                      f'{"":34s} {spec.description}')
                for sub_key, _t, sub_default, sub_spec in iter_keys(item, prefix=f'{key}[].'):
                    print(f'{sub_key:34s} {sub_spec.unit:9s} default {sub_default!r:14} '
                          f'{sub_spec.allowed()}\n{"":34s} {sub_spec.description}')
                continue
            dyn = ' (dynamic)' if spec.dynamic else ''
            shown_default = to_plain(default)
            print(f'{key:34s} {spec.unit:9s} default {shown_default!r:14} {spec.allowed()}'
                  f'{dyn}\n{"":34s} {spec.description}')
        for old, new in ALIASES.items():
            print(f'{old:34s} alias of {new}')
        return EXIT_OK
    for name, path in builtin_scenarios().items():
        try:
            description = (read_yaml(path.read_text(encoding='utf-8')) or {}).get(
                'description', '')
        except Exception:  # noqa: B902 - listing must not fail on one bad file
            description = '(unreadable)'
        print(f'{name:22s} {description}')
    return EXIT_OK
