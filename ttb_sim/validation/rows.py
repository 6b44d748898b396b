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

"""Rows and cases of the validation table (VALIDATION.md)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class Row:
    """One line of the validation table."""

    case: str
    quantity: str
    computed: float
    reference: float
    error: float
    tolerance: float
    passed: bool
    unit: str = ''
    error_kind: str = 'relative'


def relative_row(case: str, quantity: str, computed: float, reference: float,
                 tolerance: float, unit: str = '') -> Row:
    """Build a row judged by the relative error |computed - reference| / |reference|."""
    error = abs(computed - reference) / abs(reference)
    return Row(case, quantity, computed, reference, error, tolerance, error <= tolerance, unit)


def report_row(case: str, quantity: str, computed: float, unit: str = '',
               reference: float = 0.0) -> Row:
    """
    Build an information row: judged by nothing, so it always passes.

    With a nonzero ``reference`` its relative difference is shown as the error.
    """
    error = abs(computed - reference) / abs(reference) if reference else 0.0
    return Row(case, quantity, computed, reference, error, 0.0, True, unit, 'report')


@dataclass(frozen=True)
class Case:
    """A validation case: an id, a title and a function producing rows."""

    case_id: str
    title: str
    run: Callable[[], list[Row]]
