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
``ttb-sim bench``: speed, memory and accuracy of the solver variants, side by side.

For each workload (a scenario and a simulated time) every solver variant runs
the same passage, by default each in its own Python process so that the peak
resident memory is that run's alone. The report gives, per run: the DOF counts,
the time step, the threads of the parallel kernels, the build time (assembly and
factorisation), the start time (static equilibrium, first frame), the time numba spent
compiling the kernels on their first use (or loading them from its disk cache), the
stepping wall time, milliseconds per step (wall and CPU time of the process: on a
shared machine the CPU time is the steadier of the two), the real-time factor of the
stepping (simulated time / stepping wall time), the peak memory, and the RMS and peak
difference from the ``reference`` variant of the wheel-rail forces (and of the dynamic
part of Fz, each wheel's force less its time mean), the bearing forces, the car-body
vertical acceleration, the girder mid-span displacements and the pile-head
displacements. The stepping is timed after a warm-up that compiles what it steps
(:mod:`ttb_sim.commands.bench_runs`), so the milliseconds per step and the real-time
factor are those of stepping, not of compiling.

``threads`` runs every variant at each of several ``solver.threads`` counts, as
separate rows (each compared with the ``reference`` row of the same count).

A pile-soil substructure on its own (``single_pile``, ``pile_harmonic``: a
scenario whose ``load.type`` is set) is measured through the same functions:
its DOF counts are those of the soil, piles, cap, interface and boundary, and
the report adds the bricks and the CPU microseconds per brick per step. Where
the ``reference`` variant (fully implicit) is refused for the size of the mesh,
the other variants run alone and the table says so.

What is timed is the stepping core and the frames it yields; writing a bag
is not included (``ttb-sim run`` reports its own wall time with the bag).
The runs of one invocation follow each other on the same machine, so their
ratios are meaningful even where absolute times are noisy; ``repeat`` runs
every variant several times, interleaved, and keeps the fastest.

This module plans the workloads, runs the variants and prints the report;
:mod:`ttb_sim.commands.bench_runs` measures one run and its difference.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import logging
import math
import os
from pathlib import Path
import sys
from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.commands.bench_runs import compare, COMPARED, measure, measure_isolated, Traces
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Workload:
    """Default settings of a built-in workload."""

    duration: float | None = None
    """Simulated time (s); None = the scenario's own."""
    overrides: tuple[str, ...] = ()
    """``KEY=VALUE`` overrides applied before the user's."""
    variants: tuple[str, ...] = ()
    """Variants run when none are named (empty = all)."""


DEFAULT_WORKLOADS: dict[str, Workload] = {
    'live_coupled': Workload(2.0),
    'ten_span_train': Workload(),
    'paper_ttbi': Workload(0.05),
    'paper_ttbcpsi': Workload(0.05),
    'single_pile': Workload(0.2, ('load.type=harmonic', 'load.frequency=5')),
    'pile_harmonic': Workload(0.02, variants=('qdldl',)),
}
"""Built-in workloads: the default ``live_coupled`` for 2 s; ``single_pile`` under a 5 Hz
harmonic head load for 0.2 s (every variant; ``reference`` steps it fully implicit);
``pile_harmonic`` (752 k DOFs, too large for the implicit ``reference``) for 20 steps with the
default variant alone, since every other variant runs the same mixed scheme and differs only
in the small pile-block factorisation."""
REFERENCE = 'reference'
"""The variant every other one is compared with."""
ACCURACY_TARGET = 0.01
"""Relative RMS difference from the reference accepted for a default variant."""


def variant_names() -> tuple[str, ...]:
    """Return every value of ``solver.variant``, from the scenario schema."""
    from ttb_sim.config import key_spec

    choices = key_spec('solver.variant')[2].choices
    assert choices is not None
    return choices


def check_variants(names: Sequence[str]) -> list[str]:
    """
    Validate variant names; return them with ``reference`` first (added if absent).

    Raises
    ------
    ScenarioError
        For an unknown name; the message names it and the allowed values.

    """
    allowed = variant_names()
    for name in names:
        if name not in allowed:
            choices = ', '.join(repr(c) for c in allowed)
            raise ScenarioError(f'solver.variant = {shown(name)}: allowed values are one of '
                                f'{choices}')
    ordered = [REFERENCE] + [n for n in dict.fromkeys(names) if n != REFERENCE]
    return ordered


def check_threads(counts: Sequence[int]) -> list[int | None]:
    """
    Validate ``solver.threads`` counts; return them in order (``[None]``: none named).

    None stands for the scenario's own ``solver.threads`` (0, auto, by default).

    Raises
    ------
    ScenarioError
        For a count that is not an integer in the key's range; the message names it.

    """
    from ttb_sim.config import key_spec

    spec = key_spec('solver.threads')[2]
    for count in counts:
        if isinstance(count, bool) or not isinstance(count, int) or not spec.contains(count):
            raise ScenarioError(f'--threads: {shown(count)} is not a thread count; allowed: '
                                f'integers {spec.allowed()} (0 = auto)')
    return list(dict.fromkeys(counts)) or [None]


def parse_threads(text: str | None) -> list[int]:
    """
    Parse ``--threads 1,2`` into counts (empty for None).

    Raises
    ------
    ScenarioError
        For an item that is not an integer (the message names the value and the rule).

    """
    counts = []
    for item in (text or '').split(','):
        if not item.strip():
            continue
        try:
            counts.append(int(item.strip()))
        except ValueError:
            raise ScenarioError(f'--threads = {shown(text)}: expected comma-separated thread '
                                'counts, e.g. 1,2 (integers, 0 = auto)') from None
    if text is not None and not counts:
        raise ScenarioError(f'--threads = {shown(text)}: expected comma-separated thread '
                            'counts, e.g. 1,2 (integers, 0 = auto)')
    return counts


def bench(scenarios: Sequence[str] = (), variants: Sequence[str] = (),
          duration: float | None = None, *, overrides: Sequence[str] = (),
          repeat: int = 1, isolate: bool = True, threads: Sequence[int] = (),
          progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """
    Measure every variant on every workload.

    Parameters
    ----------
    scenarios : sequence of str
        Built-in names or YAML paths; empty = :data:`DEFAULT_WORKLOADS`.
    variants : sequence of str
        Values of ``solver.variant``; empty = all (or the workload's own
        default, :data:`DEFAULT_WORKLOADS`). ``reference`` always runs (first),
        since the others are compared with it, unless it is refused for the
        workload's size: then its row has status 'refused' and the message.
    duration : float, optional
        Simulated time of every workload (s); None = the workload's default
        (:data:`DEFAULT_WORKLOADS`, or the scenario's own).
    overrides : sequence of str
        ``KEY=VALUE`` overrides applied to every workload (after a built-in
        workload's own).
    repeat : int
        Rounds; every variant runs once per round (interleaved) and the
        fastest stepping is kept.
    isolate : bool
        Run each measurement in its own process (default; peak memory is then
        per run). False runs in this process (faster; the peak memory is the
        process's so far).
    threads : sequence of int
        ``solver.threads`` counts: every variant runs at each, as its own row
        (``threads_requested``), compared with the ``reference`` of the same
        count; empty = the scenario's own setting (auto by default), once.
    progress : callable, optional
        Called with a short line before each run.

    Returns
    -------
    dict
        ``{'machine': {...}, 'runs': [metrics + 'difference', ...]}``.

    Raises
    ------
    ScenarioError
        For an unknown variant, a bad scenario, thread count or ``repeat``
        (every workload is checked before the first run).

    """
    if repeat < 1:
        raise ScenarioError(f'--repeat = {repeat}: must be at least 1')
    counts = check_threads(threads)
    named = scenarios or tuple(DEFAULT_WORKLOADS)
    plans = [_plan(s, variants, duration, overrides) for s in named]
    run = measure_isolated if isolate else measure
    runs: list[dict[str, Any]] = []
    for plan in plans:
        runs.extend(_bench_plan(plan, counts, repeat, run, progress))
    return {'machine': machine(), 'runs': runs}


_Measure = Callable[..., tuple[dict[str, Any], Traces]]
""":func:`~ttb_sim.commands.bench_runs.measure` or its isolated twin."""


def _bench_plan(plan: _Plan, counts: Sequence[int | None], repeat: int, run: _Measure,
                progress: Callable[[str], None] | None) -> list[dict[str, Any]]:
    """Run one workload's variants at every thread count; return their report rows."""
    best: dict[tuple[str, int | None], tuple[dict[str, Any], Traces]] = {}
    for _round in range(repeat):
        for count in counts:
            sets = plan.overrides if count is None else [*plan.overrides,
                                                         f'solver.threads={count}']
            for name in plan.variants:
                if name in plan.refusals:
                    continue
                if progress is not None:
                    at = '' if count is None else f' / threads {count}'
                    progress(f'{plan.scenario} / {name}{at}')
                metrics, traces = run(plan.scenario, name, plan.duration, sets)
                metrics['threads_requested'] = count
                kept = best.get((name, count))
                if kept is None or _faster(metrics, kept[0]):
                    best[(name, count)] = (metrics, traces if kept is None else kept[1])
    rows: list[dict[str, Any]] = []
    for count in counts:
        base = best.get((REFERENCE, count))
        reference = base[1] if base is not None else {}
        for name in plan.variants:
            if (name, count) not in best:
                rows.append(_refused(plan.name, name, plan.refusals.get(name, ''), count))
                continue
            metrics, traces = best[(name, count)]
            metrics['difference'] = compare(traces, reference)
            rows.append(metrics)
    return rows


@dataclass(frozen=True)
class _Plan:
    """One workload, checked."""

    scenario: str
    name: str
    variants: list[str]
    duration: float | None
    overrides: list[str]
    refusals: dict[str, str]
    """Why a variant is refused for this workload, by variant (``reference`` for the
    model's size, another where it does not apply to the model)."""


def _plan(scenario: str, variants: Sequence[str], duration: float | None,
          overrides: Sequence[str]) -> _Plan:
    """Check one workload before anything runs (a bad scenario raises ScenarioError)."""
    from ttb_sim.config import load_scenario
    from ttb_sim.sim import reference_refusal

    workload = DEFAULT_WORKLOADS.get(scenario, Workload())
    names = check_variants(variants or workload.variants or variant_names())
    span = duration if duration is not None else workload.duration
    sets = [*workload.overrides, *overrides]
    values: list[tuple[str, Any]] = [('solver.variant', REFERENCE)]
    if span is not None:
        values.append(('solver.duration', span))
    loaded = load_scenario(scenario, sets, values)
    refusals: dict[str, str] = {}
    refusal = reference_refusal(loaded)
    if refusal is not None:
        refusals[REFERENCE] = refusal
    for name in names[1:]:
        try:
            load_scenario(scenario, sets, [('solver.variant', name), *values[1:]])
        except ScenarioError as exc:
            refusals[name] = str(exc)
    return _Plan(scenario, loaded.name, names, span, sets, refusals)


def _refused(name: str, variant: str, message: str, threads: int | None) -> dict[str, Any]:
    """Return the report row of a variant refused for the workload."""
    return {'scenario': name, 'variant': variant, 'status': 'refused', 'message': message,
            'threads': None, 'threads_requested': threads,
            'difference': {q: {'rms': None, 'peak': None, 'rms_rel': None, 'peak_rel': None}
                           for q in COMPARED}}


def _faster(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Tell whether run ``a`` stepped faster than ``b`` (an untimed run is never faster)."""
    slow = math.inf
    return float(a['ms_per_step'] or slow) < float(b['ms_per_step'] or slow)


def machine() -> dict[str, Any]:
    """Describe the machine and the numerical libraries (for the JSON report)."""
    import platform

    import scipy

    info: dict[str, Any] = {'platform': platform.platform(), 'python': platform.python_version(),
                            'cpus': os.cpu_count(), 'numpy': np.__version__,
                            'scipy': scipy.__version__, 'processor': platform.processor()}
    try:
        with open('/proc/cpuinfo', encoding='utf-8') as f:
            for line in f:
                if line.startswith('model name'):
                    info['processor'] = line.split(':', 1)[1].strip()
                    break
    except OSError:
        pass
    for package in ('cholespy', 'qdldl', 'threadpoolctl', 'numba'):
        try:
            from importlib.metadata import version
            info[package] = version(package)
        except Exception:  # noqa: B902 - any failure means 'not available'
            info[package] = None
    return info


def _fmt(value: float | None, spec: str) -> str:
    """Format a number with a spec like '8.3f'; '-' (as wide) for None or non-finite."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        width = int(spec.split('.')[0] or 0)
        return '-'.rjust(width)
    return format(value, spec)


DIFFERENCES = (('Fz RMS %', 'wheel_rail_vertical'), ('Fz dyn %', 'wheel_rail_vertical_dynamic'),
               ('Fy RMS %', 'wheel_rail_lateral'), ('bearing %', 'bearings'),
               ('body az %', 'body_vertical_acceleration'), ('mid RMS %', 'midspan'),
               ('pile RMS %', 'pile_heads'))
"""The columns of the difference table: heading, quantity (RMS difference, % of the reference)."""


def _threads(r: dict[str, Any]) -> str:
    """Return a row's thread count for the table: '2', '1*' (auto), '-' (none)."""
    if r.get('threads') is None:
        return '-'
    auto = 'auto' in str(r.get('threads_choice') or '')
    return f'{r["threads"]}{"*" if auto else ""}'


def format_table(report: dict[str, Any]) -> str:
    """
    Return the report as fixed-width text: the times, then the differences from ``reference``.

    The first table gives the sizes and times of every run, the second the RMS
    difference (% of the reference's RMS) of every compared quantity and the mid-span
    peak difference (m). A thread count marked ``*`` was the automatic choice.
    """
    head = (f'{"scenario":17s} {"variant":11s} {"thr":>3s} {"solver":11s} {"DOFs":>7s} '
            f'{"solved":>7s} {"dt s":>7s} {"steps":>6s} {"build s":>7s} {"start s":>7s} '
            f'{"compile s":>9s} {"ms/step":>8s} {"CPU ms":>8s} {"RTF":>8s} {"peak MiB":>8s} '
            f'{"µs/brick":>8s}')
    lines = [head, '-' * len(head)]
    for r in report['runs']:
        if r['status'] == 'refused':
            lines.append(f'{r["scenario"]:17s} {r["variant"]:11s} {_threads(r):>3s} '
                         f'refused: {r["message"]}')
            continue
        status = '' if r['status'] == 'ok' else f'  ({r["status"]})'
        lines.append(
            f'{r["scenario"]:17s} {r["variant"]:11s} {_threads(r):>3s} {r["factorization"]:11s} '
            f'{r["dofs"]["total"]:7d} {r["dofs"]["solved"]:7d} {r["dt"]:7.1e} {r["steps"]:6d} '
            f'{r["build_time"]:7.2f} {r["start_time"]:7.2f} {r["compile_time"]:9.2f} '
            f'{_fmt(r["ms_per_step"], "8.3f")} {_fmt(r["cpu_ms_per_step"], "8.3f")} '
            f'{_fmt(r["real_time_factor"], "8.3g")} {_fmt(r["peak_rss_mib"], "8.0f")} '
            f'{_fmt(r.get("cpu_us_per_brick_step"), "8.3f")}{status}')
    return '\n'.join(lines) + '\n\n' + _difference_table(report)


def _difference_table(report: dict[str, Any]) -> str:
    """Return the second table: the RMS differences from ``reference`` (%), and the peak."""
    head = (f'{"scenario":17s} {"variant":11s} {"thr":>3s} '
            + ' '.join(f'{title:>10s}' for title, _ in DIFFERENCES) + f' {"mid peak m":>10s}')
    lines = ['difference from reference (RMS, % of its RMS; - : nothing to compare)', head,
             '-' * len(head)]
    for r in report['runs']:
        if r['status'] == 'refused':
            continue
        d = r['difference']
        cells = []
        for _, name in DIFFERENCES:
            rel = d[name]['rms_rel']
            cells.append(_fmt(None if rel is None else 100.0 * rel, '10.2g'))
        lines.append(f'{r["scenario"]:17s} {r["variant"]:11s} {_threads(r):>3s} '
                     + ' '.join(cells) + f' {_fmt(d["midspan"]["peak"], "10.2g")}')
    return '\n'.join(lines)


def write_json(report: dict[str, Any], path: str | Path) -> None:
    """Write the report as indented JSON."""
    Path(path).write_text(json.dumps(report, indent=2) + '\n', encoding='utf-8')


def bench_command(scenarios: Sequence[str], *, variants: str | None = None,
                  duration: float | None = None, json_path: Path | None = None,
                  repeat: int = 1, isolate: bool = True,
                  overrides: Sequence[str] = (), threads: str | None = None) -> int:
    """Run ``ttb-sim bench``: print the tables (and write JSON); return the exit code."""
    names = [v.strip() for v in (variants or '').split(',') if v.strip()]
    report = bench(scenarios, names, duration, overrides=overrides, repeat=repeat,
                   isolate=isolate, threads=parse_threads(threads),
                   progress=lambda line: print(f'bench: {line}', file=sys.stderr))
    print(format_table(report))
    if json_path is not None:
        write_json(report, json_path)
    return 0
