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
``ttb-sim modes``: the natural modes of a scenario's bridge (and track and piled piers).

The structure is assembled as ``ttb-sim run`` builds it, without the train;
piled piers enter monolithically ([P] Eq. 11), so their reduced coordinates
take part in the modes (:func:`ttb_sim.sensors.modal.structure_modes`, which
``ttb-sim analyze`` shares to set the model's modes beside those it identifies
from the sensors). For each mode the table gives the frequency, the
modal damping ratio, the vertical mid-span amplitude of every girder relative
to the largest, and the vertical pier-top amplitude of every piled pier
relative to the same girder amplitude: enough to tell a girder's bending mode
from a pier's, and to compare the model with measured frequencies.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

__all__ = ['modes_command', 'modes_report']

MAX_COUNT = 200
"""Most modes one call computes (ARPACK's shift-invert stays quick below this)."""


def _check(around: float, count: int) -> None:
    if not (isinstance(count, int) and 1 <= count <= MAX_COUNT):
        raise ScenarioError(f'--count = {shown(count)}: allowed values are 1 to {MAX_COUNT}')
    if not (math.isfinite(around) and 0.0 <= around <= 1e4):
        raise ScenarioError(f'--around = {shown(around)}: allowed values are 0 to 10000 Hz')


def modes_report(scenario: str | Path, *, around: float = 5.0, count: int = 20,
                 overrides: Sequence[str] = ()) -> dict[str, Any]:
    """
    Build a scenario's structure and return its modes nearest ``around`` Hz.

    Returns
    -------
    dict
        'scenario', 'free_dofs', 'around_hz' and 'modes': one dict per mode with
        'frequency_hz', 'damping_ratio', 'girders_uz' (relative mid-span
        amplitudes, signed) and 'piled_pier_tops_uz' (support number -> relative
        amplitude).

    Raises
    ------
    ScenarioError
        For bad options or a bad scenario, before anything is built.

    """
    _check(around, count)
    from ttb_sim.config import load_scenario

    loaded = load_scenario(scenario, overrides)
    from ttb_sim.sensors.modal import structure_modes   # the model: after the options

    structure, found = structure_modes(loaded, around, count)
    ext = np.vstack([found.shapes, np.zeros((1, found.shapes.shape[1]))])
    girders = ext[structure.midspan_dofs[:, 2]]
    tops = {p.support + 1: ext[p.block[2]] for p in structure.piled if p.block is not None}
    rows = []
    for k, f in enumerate(found.frequencies):
        scale = float(np.abs(girders[:, k]).max())
        scale = scale if scale > 0 else 1.0
        rows.append({'frequency_hz': float(f), 'damping_ratio': float(found.damping_ratios[k]),
                     'girders_uz': [float(g) for g in girders[:, k] / scale],
                     'piled_pier_tops_uz': {str(s): float(t[k] / scale)
                                            for s, t in tops.items()}})
    return {'scenario': loaded.name, 'free_dofs': structure.n_free, 'around_hz': around,
            'modes': rows}


def format_modes(report: dict[str, Any]) -> str:
    """Return the report as a terminal table."""
    lines = [f'{report["scenario"]}: {len(report["modes"])} modes nearest '
             f'{report["around_hz"]:g} Hz ({report["free_dofs"]} free DOFs); girder and '
             'pier-top columns: vertical amplitude relative to the largest girder mid-span']
    first = report['modes'][0] if report['modes'] else None
    n_girders = len(first['girders_uz']) if first else 0
    piers = list(first['piled_pier_tops_uz']) if first else []
    head = (f'{"mode":>4s} {"f (Hz)":>8s} {"zeta":>6s} '
            + ' '.join(f'{"g" + str(i + 1):>5s}' for i in range(n_girders))
            + ''.join(f' {"pier" + p:>7s}' for p in piers))
    lines += [head, '-' * len(head)]
    for i, m in enumerate(report['modes'], 1):
        lines.append(f'{i:4d} {m["frequency_hz"]:8.3f} {m["damping_ratio"]:6.3f} '
                     + ' '.join(f'{g:+5.2f}' for g in m['girders_uz'])
                     + ''.join(f' {m["piled_pier_tops_uz"][p]:+7.3f}' for p in piers))
    return '\n'.join(lines)


def modes_command(scenario: str, *, around: float = 5.0, count: int = 20,
                  overrides: Sequence[str] = (), json_path: Path | None = None) -> int:
    """Run ``ttb-sim modes``: print the table (and write JSON); return the exit code."""
    _check(around, count)
    if json_path is not None and (json_path.is_dir() or not json_path.parent.is_dir()):
        raise ScenarioError(f'--json = {shown(str(json_path))}: allowed values are a file path '
                            'in an existing folder')
    report = modes_report(scenario, around=around, count=count, overrides=overrides)
    print(format_modes(report))
    if json_path is not None:
        json_path.write_text(json.dumps(report, indent=1))
    return 0
