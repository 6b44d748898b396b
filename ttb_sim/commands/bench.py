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
the time step, the build time (assembly and factorisation), the start time
(static equilibrium, first frame), the stepping wall time, milliseconds per
step (wall and CPU time of the process: on a shared machine the CPU time is the
steadier of the two), the real-time factor of the stepping (simulated time /
stepping wall time), the peak memory, and the RMS and peak difference from the ``reference``
variant of the wheel-rail forces, the girder mid-span displacements and the pile-head
displacements.

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
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import logging
import math
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time
from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.errors import DivergenceError, ScenarioError, SimulationError
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
    'ten_span_train': Workload(),
    'paper_ttbi': Workload(0.05),
    'paper_ttbcpsi': Workload(0.05),
    'single_pile': Workload(0.2, ('load.type=harmonic', 'load.frequency=5')),
    'pile_harmonic': Workload(0.02, variants=('qdldl',)),
}
"""Built-in workloads: ``single_pile`` under a 5 Hz harmonic head load for 0.2 s (every
variant; ``reference`` steps it fully implicit); ``pile_harmonic`` (752 k DOFs, too large for
the implicit ``reference``) for 20 steps with the default variant alone, since every other
variant runs the same mixed scheme and differs only in the small pile-block factorisation."""
REFERENCE = 'reference'
"""The variant every other one is compared with."""
QUANTITIES = ('wheel_rail_vertical', 'wheel_rail_lateral', 'midspan', 'pile_heads')
"""Compared traces: wheel-rail Fz and Fy of every wheel (N), girder mid-span z (m), pile-head
z of every pile of the piled piers (m; none without)."""
ACCURACY_TARGET = 0.01
"""Relative RMS difference from the reference accepted for a default variant."""

Traces = dict[str, np.ndarray]


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


def _dof_counts(sim: Any) -> dict[str, int]:
    """
    DOF counts per subsystem: track, bridge (girders, bearings, piers), vehicle.

    ``solved`` counts the track-bridge DOFs the time step solves (fewer than
    ``structure`` with the reduced track) plus the vehicle's.
    """
    st = sim.structure
    track = 0
    if st.track is not None:
        lines = (*st.track.rails, st.track.slab, st.track.base)
        full = np.unique(np.concatenate([line.dofs.ravel() for line in lines]))
        track = int(np.count_nonzero(st.full_to_free[full] < st.n_free))
    vehicle = sum(int(np.size(x)) for x in sim.coupling.monitored()[1:])
    solved = int(getattr(sim.coupling, 'n_free', st.n_free))
    # piled piers: their reduced coordinates (inside the structure when monolithic) and the
    # full FE DOFs they were reduced from
    inside = sum(p.operator.size for p in st.piled if p.block is not None)
    beside = sum(p.operator.size for p in st.piled if p.block is None)
    reduced_from = sum(int(p.operator.summary.get('full_dofs', p.operator.size))
                       for p in st.piled)
    return {'structure': st.n_free, 'track': track, 'bridge': st.n_free - track - inside,
            'vehicle': vehicle, 'substructures': inside + beside,
            'substructures_full': reduced_from,
            'total': st.n_free + vehicle + beside, 'solved': solved + vehicle + beside}


def _peak_rss_mib() -> float | None:
    """Peak resident memory of this process so far (MiB), where the OS reports it."""
    try:
        import resource
    except ImportError:  # pragma: no cover - Windows
        return None
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    scale = 1.0 if sys.platform == 'darwin' else 1024.0
    return peak * scale / 2**20


def measure(scenario: str, variant: str, duration: float | None = None,
            overrides: Sequence[str] = ()) -> tuple[dict[str, Any], Traces]:
    """
    Build and step one passage (or one substructure run) in this process.

    Parameters
    ----------
    scenario : str
        Built-in name or YAML path.
    variant : str
        Value of ``solver.variant``.
    duration : float, optional
        Simulated time (s); None keeps the scenario's.
    overrides : sequence of str
        ``KEY=VALUE`` scenario overrides.

    Returns
    -------
    (metrics, traces)
        Metrics as plain data (see the module docstring) and the compared
        traces, each of shape (n_frames, n_signals).

    Raises
    ------
    ScenarioError
        For a bad scenario, key or value, or a variant refused for the model's size.

    """
    from ttb_sim.config import load_scenario
    from ttb_sim.sim import make_runner, substructure_dof_counts

    values: list[tuple[str, Any]] = [('solver.variant', variant)]
    if duration is not None:
        values.append(('solver.duration', duration))
    loaded = load_scenario(scenario, overrides, values)
    t0 = time.perf_counter()
    sim: Any = make_runner(loaded)
    t1 = time.perf_counter()
    vertical: list[np.ndarray] = []
    lateral: list[np.ndarray] = []
    midspan: list[np.ndarray] = []
    piles: list[np.ndarray] = []
    status, message = 'ok', ''
    t2 = t1
    c2 = time.process_time()
    frames = 0
    try:
        for frame in sim.frames():
            if frames == 0:
                t2 = time.perf_counter()
                c2 = time.process_time()
            frames += 1
            vertical.append(frame.wheel_rail[..., 2].ravel())
            lateral.append(frame.wheel_rail[..., 1].ravel())
            midspan.append(frame.midspan[:, 2].copy())
            piles.append(frame.pile_displacement[:, 2].copy())
    except DivergenceError as exc:
        status, message = 'diverged', str(exc)
    t3 = time.perf_counter()
    cpu = time.process_time() - c2
    steps = max(frames - 1, 0) * sim.output_every
    stepping = t3 - t2
    simulated = steps * sim.dt
    substructure = loaded.substructure_only
    bricks = len(sim.model.mesh.cells) if substructure else None
    metrics: dict[str, Any] = {
        'scenario': loaded.name,
        'variant': variant,
        'model': 'pile_soil' if substructure else 'train_bridge',
        'load': sim.load.type if substructure else None,
        'scheme': sim.scheme if substructure else None,
        'factorization': sim.factorization if substructure else sim.integrator.method,
        'status': status,
        'message': message,
        'dofs': substructure_dof_counts(sim) if substructure else _dof_counts(sim),
        'bricks': bricks,
        'dt': sim.dt,
        'steps': steps,
        'frames': frames,
        'simulated_time': simulated,
        'build_time': t1 - t0,
        'start_time': t2 - t1,
        'step_time': stepping,
        'ms_per_step': 1e3 * stepping / steps if steps else None,
        'cpu_ms_per_step': 1e3 * cpu / steps if steps else None,
        'us_per_brick_step': 1e6 * stepping / (steps * bricks) if steps and bricks else None,
        'cpu_us_per_brick_step': 1e6 * cpu / (steps * bricks) if steps and bricks else None,
        'real_time_factor': simulated / stepping if stepping > 0 and steps else None,
        'peak_rss_mib': _peak_rss_mib(),
    }
    traces = {'wheel_rail_vertical': _stack(vertical), 'wheel_rail_lateral': _stack(lateral),
              'midspan': _stack(midspan), 'pile_heads': _stack(piles)}
    return metrics, traces


def _stack(rows: list[np.ndarray]) -> np.ndarray:
    if not rows:
        return np.zeros((0, 0))
    return np.vstack(rows)


def measure_isolated(scenario: str, variant: str, duration: float | None = None,
                     overrides: Sequence[str] = ()) -> tuple[dict[str, Any], Traces]:
    """
    Run :func:`measure` in a fresh Python process (honest peak memory).

    Raises
    ------
    ScenarioError
        When the child refused the scenario (its exit code 2).
    SimulationError
        When the child failed otherwise (the message carries its stderr).

    """
    import ttb_sim

    with tempfile.TemporaryDirectory(prefix='ttb-bench-') as tmp:
        out = Path(tmp) / 'traces.npz'
        job = json.dumps({'scenario': scenario, 'variant': variant, 'duration': duration,
                          'overrides': list(overrides), 'traces': str(out)})
        env = dict(os.environ)
        root = str(Path(ttb_sim.__file__).resolve().parents[1])
        env['PYTHONPATH'] = os.pathsep.join(p for p in (root, env.get('PYTHONPATH')) if p)
        code = 'import sys; from ttb_sim.commands.bench import worker; sys.exit(worker())'
        proc = subprocess.run([sys.executable, '-c', code, job], env=env,
                              capture_output=True, text=True, check=False)
        if proc.returncode == 2:
            raise ScenarioError(proc.stderr.strip().splitlines()[-1] if proc.stderr
                                else 'bench worker refused the scenario')
        if proc.returncode != 0:
            tail = '\n'.join(proc.stderr.strip().splitlines()[-5:])
            raise SimulationError(f'bench run {scenario} / {variant} failed '
                                  f'(exit {proc.returncode}):\n{tail}')
        metrics = json.loads(proc.stdout.strip().splitlines()[-1])
        with np.load(out) as data:
            traces = {k: data[k] for k in data.files}
    return metrics, traces


def worker(argv: Sequence[str] | None = None) -> int:
    """
    Entry point of the child process of :func:`measure_isolated`.

    Reads one JSON job from ``argv[0]``, prints the metrics as one JSON line and
    saves the traces to the job's ``traces`` path. Exit 2 on a bad scenario.
    """
    args = sys.argv[1:] if argv is None else argv
    job = json.loads(args[0])
    try:
        metrics, traces = measure(job['scenario'], job['variant'], job['duration'],
                                  job['overrides'])
    except ScenarioError as exc:
        sys.stderr.write(f'{exc}\n')
        return 2
    np.savez(job['traces'], wheel_rail_vertical=traces['wheel_rail_vertical'],
             wheel_rail_lateral=traces['wheel_rail_lateral'], midspan=traces['midspan'],
             pile_heads=traces['pile_heads'])
    sys.stdout.write(json.dumps(metrics) + '\n')
    return 0


def compare(traces: Traces, reference: Traces) -> dict[str, dict[str, float | None]]:
    """
    Return the difference of each traced quantity from the reference run.

    For each quantity: ``rms`` and ``peak`` of the difference (N or m, over
    every signal and frame the two runs share), and both relative to the RMS
    and to the peak of the reference (``rms_rel``, ``peak_rel``; None when the
    reference is zero).
    """
    out: dict[str, dict[str, float | None]] = {}
    for name in QUANTITIES:
        a, b = traces.get(name), reference.get(name)
        if a is None or b is None or a.size == 0 or b.size == 0 or a.shape[1] != b.shape[1]:
            out[name] = {'rms': None, 'peak': None, 'rms_rel': None, 'peak_rel': None}
            continue
        n = min(a.shape[0], b.shape[0])
        diff = a[:n] - b[:n]
        rms = float(np.sqrt(np.mean(diff**2)))
        peak = float(np.max(np.abs(diff)))
        ref_rms = float(np.sqrt(np.mean(b[:n]**2)))
        ref_peak = float(np.max(np.abs(b[:n])))
        out[name] = {'rms': rms, 'peak': peak,
                     'rms_rel': rms / ref_rms if ref_rms > 0 else None,
                     'peak_rel': peak / ref_peak if ref_peak > 0 else None}
    return out


def bench(scenarios: Sequence[str] = (), variants: Sequence[str] = (),
          duration: float | None = None, *, overrides: Sequence[str] = (),
          repeat: int = 1, isolate: bool = True,
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
    progress : callable, optional
        Called with a short line before each run.

    Returns
    -------
    dict
        ``{'machine': {...}, 'runs': [metrics + 'difference', ...]}``.

    Raises
    ------
    ScenarioError
        For an unknown variant, a bad scenario or a bad ``repeat`` (every
        workload is checked before the first run).

    """
    if repeat < 1:
        raise ScenarioError(f'--repeat = {repeat}: must be at least 1')
    named = scenarios or tuple(DEFAULT_WORKLOADS)
    plans = [_plan(s, variants, duration, overrides) for s in named]
    run = measure_isolated if isolate else measure
    runs: list[dict[str, Any]] = []
    for plan in plans:
        best: dict[str, tuple[dict[str, Any], Traces]] = {}
        for _round in range(repeat):
            for name in plan.variants:
                if name == REFERENCE and plan.refusal is not None:
                    continue
                if progress is not None:
                    progress(f'{plan.scenario} / {name}')
                metrics, traces = run(plan.scenario, name, plan.duration, plan.overrides)
                kept = best.get(name)
                if kept is None or _faster(metrics, kept[0]):
                    best[name] = (metrics, traces if kept is None else kept[1])
        reference = best[REFERENCE][1] if REFERENCE in best else {}
        for name in plan.variants:
            if name not in best:
                runs.append(_refused(plan.name, name, plan.refusal or ''))
                continue
            metrics, traces = best[name]
            metrics['difference'] = compare(traces, reference)
            runs.append(metrics)
    return {'machine': machine(), 'runs': runs}


@dataclass(frozen=True)
class _Plan:
    """One workload, checked."""

    scenario: str
    name: str
    variants: list[str]
    duration: float | None
    overrides: list[str]
    refusal: str | None
    """Why ``reference`` is refused for this workload (None: it runs)."""


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
    return _Plan(scenario, loaded.name, names, span, sets, reference_refusal(loaded))


def _refused(name: str, variant: str, message: str) -> dict[str, Any]:
    """Return the report row of a variant refused for the workload."""
    return {'scenario': name, 'variant': variant, 'status': 'refused', 'message': message,
            'difference': {q: {'rms': None, 'peak': None, 'rms_rel': None, 'peak_rel': None}
                           for q in QUANTITIES}}


def _faster(a: dict[str, Any], b: dict[str, Any]) -> bool:
    return float(a['step_time']) < float(b['step_time'])


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


def format_table(report: dict[str, Any]) -> str:
    """Return the report as a fixed-width text table."""
    head = (f'{"scenario":17s} {"variant":11s} {"solver":11s} {"DOFs":>7s} {"solved":>7s} '
            f'{"dt s":>7s} '
            f'{"steps":>6s} {"build s":>7s} {"start s":>7s} {"ms/step":>8s} {"CPU ms":>8s} '
            f'{"RTF":>8s} {"peak MiB":>8s} {"Fz RMS %":>9s} {"Fy RMS %":>9s} '
            f'{"mid RMS %":>9s} {"mid peak m":>10s} {"pile RMS %":>10s} {"µs/brick":>8s}')
    lines = [head, '-' * len(head)]
    for r in report['runs']:
        d = r['difference']
        if r['status'] == 'refused':
            lines.append(f'{r["scenario"]:17s} {r["variant"]:11s} refused: {r["message"]}')
            continue

        def pct(name: str) -> str:
            rel = d[name]['rms_rel']
            return _fmt(None if rel is None else 100.0 * rel, '9.2g')

        status = '' if r['status'] == 'ok' else f'  ({r["status"]})'
        lines.append(
            f'{r["scenario"]:17s} {r["variant"]:11s} {r["factorization"]:11s} '
            f'{r["dofs"]["total"]:7d} {r["dofs"]["solved"]:7d} {r["dt"]:7.1e} {r["steps"]:6d} '
            f'{r["build_time"]:7.2f} {r["start_time"]:7.2f} {_fmt(r["ms_per_step"], "8.3f")} '
            f'{_fmt(r["cpu_ms_per_step"], "8.3f")} '
            f'{_fmt(r["real_time_factor"], "8.3g")} {_fmt(r["peak_rss_mib"], "8.0f")} '
            f'{pct("wheel_rail_vertical")} {pct("wheel_rail_lateral")} {pct("midspan")} '
            f'{_fmt(d["midspan"]["peak"], "10.2g")} {pct("pile_heads"):>10s} '
            f'{_fmt(r.get("cpu_us_per_brick_step"), "8.3f")}{status}')
    return '\n'.join(lines)


def write_json(report: dict[str, Any], path: str | Path) -> None:
    """Write the report as indented JSON."""
    Path(path).write_text(json.dumps(report, indent=2) + '\n', encoding='utf-8')


def bench_command(scenarios: Sequence[str], *, variants: str | None = None,
                  duration: float | None = None, json_path: Path | None = None,
                  repeat: int = 1, isolate: bool = True,
                  overrides: Sequence[str] = ()) -> int:
    """Run ``ttb-sim bench``: print the table (and write JSON); return the exit code."""
    names = [v.strip() for v in (variants or '').split(',') if v.strip()]
    report = bench(scenarios, names, duration, overrides=overrides, repeat=repeat,
                   isolate=isolate, progress=lambda line: print(f'bench: {line}',
                                                                file=sys.stderr))
    print(format_table(report))
    if json_path is not None:
        write_json(report, json_path)
    return 0
