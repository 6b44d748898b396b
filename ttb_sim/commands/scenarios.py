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

from ttb_sim.config import builtin_scenarios, iter_keys, read_yaml
from ttb_sim.config.schema import ALIASES

EXIT_OK = 0


def scenarios(*, keys: bool = False) -> int:
    """Run ``ttb-sim scenarios``: the built-ins, or with ``keys`` every key and its range."""
    if keys:
        for key, _typ, default, spec in iter_keys():
            dyn = ' (dynamic)' if spec.dynamic else ''
            print(f'{key:34s} {spec.unit:9s} default {default!r:14} {spec.allowed()}{dyn}\n'
                  f'{"":34s} {spec.description}')
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
