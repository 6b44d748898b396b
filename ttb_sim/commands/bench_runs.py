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
One measured run of ``ttb-sim bench``: a variant stepping a workload, and its difference.

:func:`measure` builds and steps one passage (or one pile-soil substructure run)
in this process and returns its metrics (DOF counts, build, start and stepping
times, CPU time per step, real-time factor, peak memory) and the traces that are
compared (:data:`QUANTITIES`); :func:`measure_isolated` runs it in a fresh Python
process (:func:`worker` is the child's entry point), so that the peak memory is
that run's alone; :func:`compare` gives the difference of a run's traces from the
``reference`` run's.
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import os
from pathlib import Path
import subprocess
import sys
import tempfile
import time
from typing import Any, Sequence

import numpy as np

from ttb_sim.errors import DivergenceError, ScenarioError, SimulationError

QUANTITIES = ('wheel_rail_vertical', 'wheel_rail_lateral', 'midspan', 'pile_heads')
"""Compared traces: wheel-rail Fz and Fy of every wheel (N), girder mid-span z (m), pile-head
z of every pile of the piled piers (m; none without)."""

Traces = dict[str, np.ndarray]


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
        Metrics as plain data (see :mod:`ttb_sim.commands.bench`) and the compared
        traces, each of shape (n_frames, n_signals).

    Raises
    ------
    ScenarioError
        For a bad scenario, key or value, or a variant refused for the model's size.

    """
    from ttb_sim.config import load_scenario
    from ttb_sim.sim import make_runner

    values: list[tuple[str, Any]] = [('solver.variant', variant)]
    if duration is not None:
        values.append(('solver.duration', duration))
    loaded = load_scenario(scenario, overrides, values)
    t0 = time.perf_counter()
    sim: Any = make_runner(loaded)
    t1 = time.perf_counter()
    run = _step(sim, t1)
    metrics = _metrics(loaded, variant, sim, run, t0, t1)
    traces = {name: _stack(rows) for name, rows in run.rows.items()}
    return metrics, traces


@dataclass
class _Stepped:
    """How stepping one run went: its frames, clocks, end and the rows of every trace."""

    frames: int
    first: float
    """Wall clock (s) at the first frame (the end of the start)."""
    end: float
    """Wall clock (s) after the last frame."""
    cpu: float
    """CPU seconds of the process from the first frame to the end."""
    status: str
    message: str
    rows: dict[str, list[np.ndarray]]


def _step(sim: Any, built: float) -> _Stepped:
    """Step a built run to its end (or its divergence), keeping the compared values."""
    rows: dict[str, list[np.ndarray]] = {name: [] for name in QUANTITIES}
    status, message = 'ok', ''
    t2 = built
    c2 = time.process_time()
    frames = 0
    try:
        for frame in sim.frames():
            if frames == 0:
                t2 = time.perf_counter()
                c2 = time.process_time()
            frames += 1
            rows['wheel_rail_vertical'].append(frame.wheel_rail[..., 2].ravel())
            rows['wheel_rail_lateral'].append(frame.wheel_rail[..., 1].ravel())
            rows['midspan'].append(frame.midspan[:, 2].copy())
            rows['pile_heads'].append(frame.pile_displacement[:, 2].copy())
    except DivergenceError as exc:
        status, message = 'diverged', str(exc)
    t3 = time.perf_counter()
    cpu = time.process_time() - c2
    return _Stepped(frames, t2, t3, cpu, status, message, rows)


def _metrics(loaded: Any, variant: str, sim: Any, run: _Stepped, t0: float,
             t1: float) -> dict[str, Any]:
    """Return the report row of one run (plain data)."""
    from ttb_sim.sim import substructure_dof_counts

    steps = max(run.frames - 1, 0) * sim.output_every
    stepping = run.end - run.first
    cpu = run.cpu
    simulated = steps * sim.dt
    substructure = loaded.substructure_only
    bricks = len(sim.model.mesh.cells) if substructure else None
    return {
        'scenario': loaded.name,
        'variant': variant,
        'model': 'pile_soil' if substructure else 'train_bridge',
        'load': sim.load.type if substructure else None,
        'scheme': sim.scheme if substructure else None,
        'factorization': sim.factorization if substructure else sim.integrator.method,
        'status': run.status,
        'message': run.message,
        'dofs': substructure_dof_counts(sim) if substructure else _dof_counts(sim),
        'bricks': bricks,
        'dt': sim.dt,
        'steps': steps,
        'frames': run.frames,
        'simulated_time': simulated,
        'build_time': t1 - t0,
        'start_time': run.first - t1,
        'step_time': stepping,
        'ms_per_step': 1e3 * stepping / steps if steps else None,
        'cpu_ms_per_step': 1e3 * cpu / steps if steps else None,
        'us_per_brick_step': 1e6 * stepping / (steps * bricks) if steps and bricks else None,
        'cpu_us_per_brick_step': 1e6 * cpu / (steps * bricks) if steps and bricks else None,
        'real_time_factor': simulated / stepping if stepping > 0 and steps else None,
        'peak_rss_mib': _peak_rss_mib(),
    }


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
        code = 'import sys; from ttb_sim.commands.bench_runs import worker; sys.exit(worker())'
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
