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

"""Argument checks and the grid tolerance shared by the irregularity modules (package-internal)."""

from __future__ import annotations

import math

from ttb_sim.errors import ModelError

#: Tolerance, in grid steps, for positions and lengths.
GRID_SLACK = 1e-9


def to_float(name: str, value: float) -> float:
    """
    Return ``value`` as a float.

    Raises
    ------
    ModelError
        If it is not a number; the message names ``name``.

    """
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ModelError(f'{name} must be a number, got {value!r}') from None


def check_positive(name: str, value: float) -> float:
    """
    Return ``value`` as a float, checked to be finite and > 0.

    Raises
    ------
    ModelError
        If it is not; the message names ``name``.

    """
    number = to_float(name, value)
    if not (math.isfinite(number) and number > 0.0):
        raise ModelError(f'{name} must be a finite number > 0, got {value!r}')
    return number
