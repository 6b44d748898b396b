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

"""The ``validate`` verb: run validation cases and print the table."""

from __future__ import annotations

import sys
from typing import Sequence

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.validation.cases.registry import CASES, format_table, run_cases
from ttb_sim.validation.rows import Row

EXIT_OK, EXIT_FAILURE = 0, 1
MAX_UNKNOWN_SHOWN = 5
"""Most unknown case ids named in the refusal."""


def _progress(i: int, n: int, case_id: str, rows: list[Row] | None, seconds: float) -> None:
    """Tell stderr which case runs, and how it ended, as the suite goes."""
    if rows is None:
        print(f'[{i}/{n}] {case_id} {CASES[case_id].title} ...', file=sys.stderr, flush=True)
        return
    failed = sum(not r.passed for r in rows)
    verdict = 'pass' if failed == 0 else f'FAIL ({failed} of {len(rows)} rows)'
    print(f'[{i}/{n}] {case_id} {verdict} in {seconds:.1f} s', file=sys.stderr, flush=True)


def validate(cases: Sequence[str] = (), *, list_only: bool = False) -> int:
    """Run ``ttb-sim validate``; return 0 only if every case passes."""
    if list_only:
        for case_id, case in CASES.items():
            print(f'{case_id:5s} {case.title}')
        return EXIT_OK
    unknown = [c for c in cases if c not in CASES]
    if unknown:
        # every value through shown(): bounded, quoted, control characters escaped
        named = ', '.join(shown(c) for c in unknown[:MAX_UNKNOWN_SHOWN])
        more = f' and {len(unknown) - MAX_UNKNOWN_SHOWN} more' if (
            len(unknown) > MAX_UNKNOWN_SHOWN) else ''
        raise ScenarioError(f'unknown validation case(s) {named}{more}; allowed: '
                            f'{", ".join(CASES)} (see `ttb-sim validate --list`)')
    rows = run_cases(cases or list(CASES), progress=_progress)
    print(format_table(rows))
    failed = sum(not r.passed for r in rows)
    print(f'{len(rows) - failed} passed, {failed} failed')
    return EXIT_OK if failed == 0 else EXIT_FAILURE
