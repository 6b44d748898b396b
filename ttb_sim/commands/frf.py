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
``ttb-sim frf``: the pile-soil substructure's frequency response, and whether its mesh holds.

For a substructure scenario (``load.type`` not ``none``) the receptance of the
loaded pile head and of the soil points along the load's direction is solved
in the frequency domain (:mod:`ttb_sim.model.foundation.frequency_response`)
at the frequencies asked: the steady state a harmonic load of that frequency
reaches. ``--refine`` solves the same block with every element size halved
(``soil.mesh.h``, ``h_max`` and ``h_shaft``) and reports how much the answer
moved: the mesh holds at a frequency where it moves little.
``--pml THICKNESS`` replaces the scenario's boundary by a perfectly matched
layer of that thickness around the block, so that the far field does not
reflect (the reference the viscous-spring boundary approximates).
"""

from __future__ import annotations

from dataclasses import replace
import json
import logging
import math
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

import numpy as np

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

__all__ = ['frf_command', 'frf_report', 'parse_frequencies']

log = logging.getLogger(__name__)

MAX_FREQUENCIES = 200
"""Most frequencies one call solves."""

SOLVERS = ('auto', 'pardiso', 'superlu')

AT = ('load', 'master')
"""What ``--at`` may name: the scenario's load point, or the piled pier's cap master."""

SLOW_SECONDS = 20.0
"""Estimated time left (s) above which each solve is reported on the terminal."""


def parse_frequencies(text: str) -> list[float]:
    """Return the frequencies of ``--freqs`` ('1,2,5' or 'start:stop:step'), Hz."""
    text = str(text).strip()
    if text.count(':') == 2:
        try:
            start, stop, step = (float(p) for p in text.split(':'))
        except ValueError:
            raise ScenarioError(f'--freqs {shown(text)}: expected START:STOP:STEP in Hz, '
                                'e.g. 1:20:1') from None
        if not (math.isfinite(start) and math.isfinite(stop) and step > 0 and stop >= start):
            raise ScenarioError(f'--freqs {shown(text)}: START:STOP:STEP needs STEP > 0 and '
                                'STOP >= START')
        count = math.floor((stop - start) / step + 1e-9) + 1
        if count > MAX_FREQUENCIES:
            raise ScenarioError(f'--freqs {shown(text)}: {count} frequencies, over the '
                                f'{MAX_FREQUENCIES} allowed')
        values = [start + k * step for k in range(count)]
    else:
        values = []
        for part in text.split(','):
            try:
                values.append(float(part))
            except ValueError:
                raise ScenarioError(f'--freqs {shown(text)}: {shown(part.strip())} is not a '
                                    'number; give comma-separated Hz, e.g. 1,2,5,10, or '
                                    'START:STOP:STEP') from None
    if not values or len(values) > MAX_FREQUENCIES:
        raise ScenarioError(f'--freqs {shown(text)}: give 1 to {MAX_FREQUENCIES} frequencies')
    for v in values:
        if not (math.isfinite(v) and 0.0 <= v <= 1000.0):
            raise ScenarioError(f'--freqs {shown(text)}: {v:g} Hz is outside [0, 1000] Hz')
    return values


def _check_options(pml: Optional[float], solver: str, paths: Sequence[Optional[Path]]) -> None:
    if pml is not None and not (math.isfinite(pml) and 0.0 < pml <= 1000.0):
        raise ScenarioError(f'--pml = {shown(pml)}: allowed values are a thickness in '
                            '(0, 1000] m')
    if solver not in SOLVERS:
        raise ScenarioError(f'--solver = {shown(solver)}: allowed values are '
                            + ', '.join(SOLVERS))
    for path in paths:
        if path is not None and (path.is_dir() or not path.parent.is_dir()):
            raise ScenarioError(f'{shown(str(path))}: allowed values are a file path in an '
                                'existing folder')


def _halved(spec: Any) -> Any:
    """Return the substructure with every element size halved."""
    mesh = spec.soil.mesh
    finer = replace(mesh, h=0.5 * mesh.h, h_max=0.5 * mesh.h_max, h_shaft=0.5 * mesh.h_shaft)
    return replace(spec, soil=replace(spec.soil, mesh=finer))


def _progress(label: str, count: int) -> Callable[[int, float, float], None]:
    """Return a solve's progress report: on the terminal (WARNING) when it is long."""
    def progress(i: int, f: float, seconds: float) -> None:
        left = seconds * (count - i - 1)
        level = logging.WARNING if left > SLOW_SECONDS else logging.INFO
        log.log(level, 'frf %s: %g Hz solved in %.1f s (%d of %d; about %.0f s left)', label,
                f, seconds, i + 1, count, left)

    return progress


def _case(spec: Any, load: Any, freqs: list[float], pml: Optional[float], solver: str,
          label: str) -> dict[str, Any]:
    from ttb_sim.model.foundation.frequency_response import MatchedLayer, substructure_response

    layer = MatchedLayer(pml) if pml is not None else None
    r = substructure_response(spec, load, freqs, layer=layer, method=solver,
                              progress=_progress(label, len(freqs)))
    axis = 'xyz'.index(load.direction)
    head = r.heads[:, load.pile - 1, axis] if load.target in ('pile', 'cap') else \
        np.full(len(freqs), np.nan + 0j)
    return {'label': label, 'dofs': r.dofs, 'unknowns': r.unknowns, 'solver': r.method,
            'symmetry': [f'{p.axis} {p.parity}' for p in r.symmetry],
            'seconds': r.seconds, 'head': head,
            'points': {name: r.points[:, k, axis] for k, name in enumerate(r.point_names)}}


def _pier_load(loaded: Any) -> Any:
    """
    Return the load of a bridge scenario's piled piers: 1 N on the cap top, central pile seen.

    Every piled pier of a scenario stands on the same substructure; the force
    acts along ``load.direction`` as a uniform pressure on the cap top.
    """
    from ttb_sim.model.foundation.records import PileLoad

    piled = loaded.foundation.piled if loaded.foundation.model == 'piled' else ()
    if not piled:
        raise ScenarioError(f"load.type = 'none': {loaded.name} is neither a pile-soil "
                            'substructure run nor a bridge on piled piers; allowed: a scenario '
                            'with load.type static, harmonic or pulse (e.g. single_pile, '
                            'pile_harmonic), or foundation.model: piled (e.g. paper_ttbcpsi)')
    return PileLoad('static', 1.0, pile=loaded.piles.count // 2 + 1,
                    direction=loaded.load.direction, target='cap')


def frf_report(scenario: str | Path, freqs: Sequence[float], *, pml: Optional[float] = None,
               refine: bool = False, solver: str = 'auto',
               overrides: Sequence[str] = (), at: str = 'load',
               reduced: bool = True) -> dict[str, Any]:
    """
    Return the receptances of a substructure scenario (and of its halved mesh).

    Returns
    -------
    dict
        'scenario', 'frequencies_hz', 'load' (pile, direction, target), 'far_field'
        ('boundary' name or 'pml'), and 'cases': one per mesh ('scenario', then
        'halved'), each with 'dofs', 'unknowns', 'solver', 'symmetry', 'seconds'
        and complex receptances (m/N) 'head' (the loaded pile, along the load)
        and 'points' (name -> receptance along the load). With ``at='master'``
        the report of :func:`~.frf_master.master_report` instead, with the reduced
        substructure beside the meshes unless ``reduced`` is False.

    """
    _check_options(pml, solver, ())
    from ttb_sim.config import load_scenario

    loaded = load_scenario(scenario, overrides)
    spec = loaded.substructure('pier01')
    values = [float(f) for f in freqs]
    if pml is not None and min(values) <= 0:
        raise ScenarioError('--freqs: a perfectly matched layer (--pml) needs frequencies '
                            'above 0 Hz')
    if at == 'master':
        from ttb_sim.commands.frf_master import check_master_scenario, master_report

        check_master_scenario(loaded)
        return master_report(loaded, spec, values, pml=pml, refine=refine, solver=solver,
                             progress=lambda label: _progress(label, len(values)),
                             halved=_halved, reduced=reduced)
    load = loaded.load if loaded.substructure_only else _pier_load(loaded)
    cases = [_case(spec, load, values, pml, solver, 'scenario')]
    if refine:
        cases.append(_case(_halved(spec), load, values, pml, solver, 'halved'))
    return {'scenario': loaded.name, 'frequencies_hz': values,
            'load': {'pile': load.pile, 'direction': load.direction, 'target': load.target},
            'far_field': 'pml' if pml is not None else spec.soil.boundary,
            'pml_thickness_m': pml, 'cases': cases}


def change(report: dict[str, Any]) -> Optional[np.ndarray]:
    """Return |H_halved / H - 1| of the head per frequency, or None without a halved case."""
    if len(report['cases']) < 2:
        return None
    a, b = report['cases'][0]['head'], report['cases'][1]['head']
    with np.errstate(divide='ignore', invalid='ignore'):
        return np.asarray(np.abs(b / a - 1.0))


def format_frf(report: dict[str, Any]) -> str:
    """Return the report as a terminal table."""
    cases = report['cases']
    load = report['load']
    where = ' under a force on the cap top' if load['target'] == 'cap' else ''
    head = [f'{report["scenario"]}: receptance of pile {load["pile"]}\'s head along '
            f'{load["direction"]}{where} (m/N), far field {report["far_field"]}']
    for c in cases:
        head.append(f'  {c["label"]}: {c["dofs"]} DOFs, {c["unknowns"]} unknowns '
                    f'(symmetry: {", ".join(c["symmetry"]) or "none"}), {c["solver"]}, '
                    f'{sum(c["seconds"]):.1f} s')
    moved = change(report)
    title = f'{"f (Hz)":>8s}' + ''.join(f' {"|H| " + c["label"]:>17s} {"phase":>7s}'
                                        for c in cases)
    if moved is not None:
        title += f' {"change":>8s}'
    lines = head + [title, '-' * len(title)]
    for i, f in enumerate(report['frequencies_hz']):
        row = f'{f:8.3f}'
        for c in cases:
            h = complex(c['head'][i])
            row += f' {abs(h):17.4e} {math.degrees(math.atan2(h.imag, h.real)):7.1f}'
        if moved is not None:
            row += f' {100 * moved[i]:7.2f}%'
        lines.append(row)
    return '\n'.join(lines)


def _jsonable(report: dict[str, Any]) -> dict[str, Any]:
    def pairs(z: np.ndarray) -> list[list[float]]:
        return [[float(v.real), float(v.imag)] for v in np.asarray(z)]

    out = dict(report)
    out['cases'] = [{**c, 'head': pairs(c['head']),
                     'points': {k: pairs(v) for k, v in c['points'].items()}}
                    for c in report['cases']]
    out['complex'] = 'each receptance is a list of [real, imaginary] per frequency, m/N'
    return out


def plot_frf(report: dict[str, Any], path: Path) -> Path:
    """Draw amplitude and phase of the head receptance against frequency for every case."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.0, 5.0), layout='constrained')
    FigureCanvasAgg(fig)
    amp, phase = fig.subplots(2, 1, sharex=True)
    f = np.asarray(report['frequencies_hz'])
    for c in report['cases']:
        h = np.asarray(c['head'])
        amp.plot(f, np.abs(h), marker='.', label=f'{c["label"]} ({c["dofs"]} DOFs)')
        phase.plot(f, np.degrees(np.angle(h)), marker='.')
    amp.set_ylabel('|H| (m/N)')
    amp.set_yscale('log')
    amp.legend()
    amp.set_title(f'{report["scenario"]}: pile {report["load"]["pile"]} head, '
                  f'{report["load"]["direction"]}, far field {report["far_field"]}')
    phase.set_ylabel('phase (deg)')
    phase.set_xlabel('frequency (Hz)')
    fig.savefig(path, dpi=110)
    return path


def frf_command(scenario: str, freqs: str, *, pml: Optional[float] = None,
                refine: bool = False, solver: str = 'auto', overrides: Sequence[str] = (),
                json_path: Optional[Path] = None, plot_path: Optional[Path] = None,
                at: str = 'load', reduced: bool = True) -> int:
    """Run ``ttb-sim frf``: print the table (and write JSON and a figure); return 0."""
    values = parse_frequencies(freqs)
    _check_options(pml, solver, (json_path, plot_path))
    if at not in AT:
        raise ScenarioError(f'--at = {shown(at)}: allowed values are ' + ', '.join(AT))
    if not reduced and at != 'master':
        raise ScenarioError('--no-reduced: allowed only with --at master (the reduced '
                            'substructure is shown there alone)')
    report = frf_report(scenario, values, pml=pml, refine=refine, solver=solver,
                        overrides=overrides, at=at, reduced=reduced)
    if at == 'master':
        from ttb_sim.commands.frf_master import format_master, jsonable_master, plot_master

        print(format_master(report))
        if json_path is not None:
            json_path.write_text(json.dumps(jsonable_master(report), indent=1))
        if plot_path is not None:
            plot_master(report, plot_path)
        return 0
    print(format_frf(report))
    if json_path is not None:
        json_path.write_text(json.dumps(_jsonable(report), indent=1))
    if plot_path is not None:
        plot_frf(report, plot_path)
    return 0
