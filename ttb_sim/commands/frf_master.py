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
``ttb-sim frf SCENARIO --at master``: what a piled pier's column stands on.

The dynamic stiffness of the tied cap-pile-soil block at the cap's master
(:mod:`ttb_sim.model.foundation.master_response`), of the unreduced mesh (with
the scenario's boundary or a matched layer), of its halved mesh with
``--refine``, and of the reduced substructure the time stepping uses, with the
differences of each from the finest unreduced case: the reduced-against-
reference table of the piled piers.
"""

from __future__ import annotations

import logging
import math
from typing import Any, Optional, Sequence

import numpy as np

from ttb_sim.errors import ScenarioError

log = logging.getLogger(__name__)

SHOWN = (('Z_uz', 2), ('Z_ux', 0), ('Z_ry', 4))
"""Impedance entries the terminal table shows (name, index): vertical, sway, rocking."""


def master_report(loaded: Any, spec: Any, values: list[float], *, pml: Optional[float],
                  refine: bool, solver: str, progress: Any, halved: Any,
                  reduced: bool = True) -> dict[str, Any]:
    """
    Return the master impedances of every case and their differences from the finest.

    ``loaded`` is the scenario, ``spec`` its piled piers' substructure,
    ``progress(label)`` a solve's progress callback, ``halved(spec)`` the
    spec with every element size halved; ``reduced`` False leaves the reduced
    substructure out.
    """
    from ttb_sim.model.foundation.frequency_response import MatchedLayer
    from ttb_sim.model.foundation.master_response import (master_errors, master_response,
                                                          MasterResponse)

    layer = MatchedLayer(pml) if pml is not None else None
    cases: list[tuple[str, MasterResponse, str]] = []
    specs = [('scenario', spec)] + ([('halved', halved(spec))] if refine else [])
    for label, s in specs:
        r = master_response(s, values, layer=layer, method=solver, progress=progress(label))
        cases.append((label, r, f'unknowns per symmetry class {list(r.unknowns)}, '
                      f'{r.method}, {sum(r.seconds):.1f} s'))
    block = _reduced_response(loaded, values) if reduced else None
    if block is not None:
        cases.append(('reduced', block, f'{block.unknowns[0]} coordinates (the time '
                      "stepping's substructure, the scenario's mesh and boundary)"))
    reference = cases[len(specs) - 1]
    out = []
    for label, r, about in cases:
        errors = master_errors(r, reference[1]) if r is not reference[1] else {}
        out.append({'label': label, 'about': about, 'impedance': r.impedance(),
                    'errors': errors})
    return {'scenario': loaded.name, 'frequencies_hz': values, 'at': 'master',
            'far_field': 'pml' if pml is not None else spec.soil.boundary,
            'pml_thickness_m': pml, 'reference': reference[0], 'cases': out}


def _reduced_response(loaded: Any, values: Sequence[float]) -> Any:
    """Return the reduced substructure's master response (None: no piled piers)."""
    if loaded.foundation.model != 'piled' or not loaded.foundation.piled:
        return None
    from ttb_sim.model.foundation.master_response import dense_master_response
    from ttb_sim.model.foundation.reduction import substructure_block
    from ttb_sim.sim import build_foundation, pier_column_parameters

    op = build_foundation(loaded)
    m, c, k, heads, points = substructure_block(op, *pier_column_parameters(loaded))
    return dense_master_response(m, c, k, heads, points, values, op.soil_point_names)


def format_master(report: dict[str, Any]) -> str:
    """Return the master report as a terminal table."""
    cases = report['cases']
    lines = [f'{report["scenario"]}: dynamic stiffness of the piled pier\'s ground at the '
             f'cap\'s master, far field {report["far_field"]}; differences |Z / Z_ref - 1| '
             f'from "{report["reference"]}" (largest over the 6 diagonal entries and the '
             'sway-rocking couplings)']
    lines += [f'  {c["label"]}: {c["about"]}' for c in cases]
    ref = next(c for c in cases if c['label'] == report['reference'])
    title = f'{"f (Hz)":>8s}' + ''.join(f' {"|" + name + "|":>12s}' for name, _ in SHOWN)
    others = [c for c in cases if c['errors']]
    title += ''.join(f' {c["label"] + " max":>14s} {"(entry)":>9s}' for c in others)
    lines += [title, '-' * len(title)]
    for i, f in enumerate(report['frequencies_hz']):
        row = f'{f:8.3f}' + ''.join(f' {abs(ref["impedance"][i, j, j]):12.4e}'
                                    for _, j in SHOWN)
        for c in others:
            name, worst = _worst(c['errors'], i)
            row += f' {100 * worst:13.1f}% {name:>9s}'
        lines.append(row)
    return '\n'.join(lines)


def _worst(errors: dict[str, np.ndarray], i: int) -> tuple[str, float]:
    entries = {k: float(v[i]) for k, v in errors.items() if k.startswith('Z_')}
    name = max(entries, key=lambda k: entries[k] if math.isfinite(entries[k]) else -1.0)
    return name[2:], entries[name]


def jsonable_master(report: dict[str, Any]) -> dict[str, Any]:
    """Return the master report with complex arrays as [real, imaginary] pairs."""
    def pairs(z: np.ndarray) -> Any:
        return np.stack([np.real(z), np.imag(z)], axis=-1).tolist()

    out = dict(report)
    out['cases'] = [{'label': c['label'], 'about': c['about'],
                     'impedance': pairs(c['impedance']),
                     'errors': {k: [float(x) for x in v] for k, v in c['errors'].items()}}
                    for c in report['cases']]
    out['complex'] = ('impedance: per frequency a 6 x 6 matrix (ux, uy, uz, rx, ry, rz) of '
                      '[real, imaginary], N/m, N/rad, N m/m, N m/rad')
    return out


def check_master_scenario(loaded: Any) -> None:
    """Refuse a scenario whose substructure has no cap or piles to tie a master to."""
    if not loaded.cap.enabled or loaded.piles is None or loaded.piles.count == 0:
        raise ScenarioError(f'--at master: {loaded.name} has no pile cap to stand a pier on; '
                            'allowed: a scenario with piles and cap.enabled: true (e.g. '
                            'paper_ttbcpsi, live_coupled)')


def plot_master(report: dict[str, Any], path: Any) -> Any:
    """Draw |Z| of the vertical, sway and rocking entries against frequency, every case."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 7.0), layout='constrained')
    FigureCanvasAgg(fig)
    axes = fig.subplots(len(SHOWN), 1, sharex=True)
    f = np.asarray(report['frequencies_hz'])
    for ax, (name, j) in zip(axes, SHOWN):
        for c in report['cases']:
            ax.plot(f, np.abs(c['impedance'][:, j, j]), marker='.', label=c['label'])
        ax.set_ylabel(f'|{name}|')
        ax.set_yscale('log')
    axes[0].legend()
    axes[0].set_title(f'{report["scenario"]}: ground at the cap master, far field '
                      f'{report["far_field"]}')
    axes[-1].set_xlabel('frequency (Hz)')
    fig.savefig(path, dpi=110)
    return path
