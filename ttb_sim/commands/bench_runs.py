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
in this process and returns its metrics (DOF counts, build, start, compile and
stepping times, CPU time per step, real-time factor, peak memory) and the traces
that are compared (:data:`QUANTITIES`); :func:`measure_isolated` runs it in a fresh Python
process (:func:`worker` is the child's entry point), so that the peak memory is
that run's alone; :func:`compare` gives the difference of a run's traces from the
``reference`` run's (and of the quantities derived from them, :data:`DERIVED`).

The stepping is timed once numba has compiled what it steps: numba compiles each
kernel on its first call (or loads it from its disk cache), which in a fresh
installation took 13 times a step's own time over a whole passage. The first
frames are a warm-up, until a frame interval passes without entering numba's
compiler (:func:`ttb_sim.fe.compiled.compile_clock`); the timed section starts
there, and the time spent in the compiler over the whole run (build, start,
warm-up) is reported on its own (``compile_time``), with the kernels still pending
when timing started (``pending_at_timing``: none, but for a kernel the variant makes
and never calls, e.g. the single-solve rail predictor under ``reference``) and the
compiler time inside the timed section (``compile_timed``, zero expected).
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

QUANTITIES = ('wheel_rail_vertical', 'wheel_rail_lateral', 'midspan', 'pile_heads',
              'bearings', 'body_vertical_acceleration')
"""Compared traces: wheel-rail Fz and Fy of every wheel (N), girder mid-span z (m), pile-head
z of every pile of the piled piers (m; none without), the bearing forces (every component of
both bearings of every support, N) and the car-body vertical acceleration (m/s^2, gravity
excluded; none for moving forces, whose bodies do not move)."""
DERIVED = {'wheel_rail_vertical_dynamic': 'wheel_rail_vertical'}
"""Compared quantities derived from a trace: the dynamic part of the wheel-rail Fz (each
wheel's force minus its own time mean over the frames compared), from its trace."""
COMPARED = (*QUANTITIES, *DERIVED)
"""Every quantity of a run's ``difference``."""

Traces = dict[str, np.ndarray]


def _dof_counts(sim: Any) -> dict[str, int]:
    """
    DOF counts per subsystem: track, bridge (girders, bearings, piers), vehicle.

    ``solved`` counts the track-bridge DOFs the time step solves (fewer than
    ``structure`` with the reduced track, or with the piled piers' interiors condensed,
    which the step advances mode by mode) plus the vehicle's.
    """
    st = sim.structure
    track = 0
    if st.track is not None:
        lines = (*st.track.rails, st.track.slab, st.track.base)
        full = np.unique(np.concatenate([line.dofs.ravel() for line in lines]))
        track = int(np.count_nonzero(st.full_to_free[full] < st.n_free))
    vehicle = sum(int(np.size(x)) for x in sim.coupling.monitored()[1:])
    # the reduced track's window, or the girder system left by condensed pier interiors
    solved = int(getattr(sim.coupling, 'solved_dofs', getattr(sim.coupling, 'n_free', st.n_free)))
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
    from ttb_sim.fe.compiled import compile_clock
    from ttb_sim.sim import make_runner

    values: list[tuple[str, Any]] = [('solver.variant', variant)]
    if duration is not None:
        values.append(('solver.duration', duration))
    loaded = load_scenario(scenario, overrides, values)
    with compile_clock() as clock:
        t0 = time.perf_counter()
        sim: Any = make_runner(loaded)
        t1 = time.perf_counter()
        run = _step(sim, t1, clock)
    metrics = _metrics(loaded, variant, sim, run, t0, t1)
    traces = {name: _stack(rows) for name, rows in run.rows.items()}
    return metrics, traces


@dataclass
class _Stepped:
    """How stepping one run went: its frames, clocks, end and the rows of every trace."""

    frames: int
    first: float
    """Wall clock (s) at the first frame (the end of the start)."""
    timed: float
    """Wall clock (s) at the frame the timed section starts from (the end of the warm-up)."""
    timed_frame: int
    """Index of that frame (the frames before it are the warm-up; -1: none was timed)."""
    end: float
    """Wall clock (s) after the last frame."""
    cpu: float
    """CPU seconds of the process over the timed section."""
    status: str
    message: str
    rows: dict[str, list[np.ndarray]]
    compile_time: float = 0.0
    """Wall seconds in numba's compiler over the run (build, start, stepping)."""
    compile_timed: float = 0.0
    """Of which inside the timed section."""
    pending: tuple[str, ...] = ()
    """Kernels made but not yet compiled when the timed section started."""


def _step(sim: Any, built: float, clock: Any) -> _Stepped:
    """
    Step a built run to its end (or its divergence), keeping the compared values.

    The timed section starts at the first frame whose interval from the frame
    before did not enter numba's compiler (``clock``, a
    :class:`~ttb_sim.fe.compiled.CompileClock`): the kernels the stepping calls
    are compiled (or loaded from the disk cache) by then.
    """
    from ttb_sim.fe.compiled import pending

    rows: dict[str, list[np.ndarray]] = {name: [] for name in QUANTITIES}
    status, message = 'ok', ''
    first = timed = built
    cpu0, timed_frame, entries, in_compiler = time.process_time(), -1, -1, 0.0
    waiting: tuple[str, ...] = ()
    frames = 0
    try:
        for frame in sim.frames():
            now = time.perf_counter()
            if frames == 0:
                first = now
            elif timed_frame < 0 and clock.entries == entries:
                timed, timed_frame, cpu0 = now, frames, time.process_time()
                in_compiler, waiting = clock.seconds, tuple(pending())
            entries = clock.entries
            frames += 1
            _keep(rows, frame)
    except DivergenceError as exc:
        status, message = 'diverged', str(exc)
    end = time.perf_counter()
    cpu = time.process_time() - cpu0 if timed_frame >= 0 else 0.0
    return _Stepped(frames, first, timed if timed_frame >= 0 else end, timed_frame, end, cpu,
                    status, message, rows, compile_time=clock.seconds,
                    compile_timed=clock.seconds - in_compiler if timed_frame >= 0 else 0.0,
                    pending=waiting)


def _keep(rows: dict[str, list[np.ndarray]], frame: Any) -> None:
    """Append a frame's values of every compared trace (:data:`QUANTITIES`)."""
    rows['wheel_rail_vertical'].append(frame.wheel_rail[..., 2].ravel())
    rows['wheel_rail_lateral'].append(frame.wheel_rail[..., 1].ravel())
    rows['midspan'].append(frame.midspan[:, 2].copy())
    rows['pile_heads'].append(frame.pile_displacement[:, 2].copy())
    rows['bearings'].append(frame.bearings.ravel())
    rows['body_vertical_acceleration'].append(frame.body_acceleration[:, 2].copy())


def _metrics(loaded: Any, variant: str, sim: Any, run: _Stepped, t0: float,
             t1: float) -> dict[str, Any]:
    """Return the report row of one run (plain data)."""
    from ttb_sim.sim import substructure_dof_counts

    steps = max(run.frames - 1, 0) * sim.output_every
    timed = max(run.frames - 1 - run.timed_frame, 0) * sim.output_every if (
        run.timed_frame >= 0) else 0
    stepping = run.end - run.timed
    cpu = run.cpu
    simulated = steps * sim.dt
    threads = getattr(sim, 'threads', None)
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
        'threads': threads.count if threads is not None else None,
        'threads_choice': threads.describe() if threads is not None else None,
        'steps': steps,
        'frames': run.frames,
        'simulated_time': simulated,
        'build_time': t1 - t0,
        'start_time': run.first - t1,
        'compile_time': run.compile_time,
        'warmup_steps': steps - timed,
        'warmup_time': run.timed - run.first,
        'timed_steps': timed,
        'compile_timed': run.compile_timed,
        'pending_at_timing': list(run.pending),
        'step_time': stepping,
        'ms_per_step': 1e3 * stepping / timed if timed else None,
        'cpu_ms_per_step': 1e3 * cpu / timed if timed else None,
        'us_per_brick_step': 1e6 * stepping / (timed * bricks) if timed and bricks else None,
        'cpu_us_per_brick_step': 1e6 * cpu / (timed * bricks) if timed and bricks else None,
        'real_time_factor': timed * sim.dt / stepping if stepping > 0 and timed else None,
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
    arrays: dict[str, Any] = {name: traces[name] for name in QUANTITIES}
    np.savez(job['traces'], **arrays)
    sys.stdout.write(json.dumps(metrics) + '\n')
    return 0


def compare(traces: Traces, reference: Traces) -> dict[str, dict[str, float | None]]:
    """
    Return the difference of each compared quantity from the reference run (:data:`COMPARED`).

    For each quantity: ``rms`` and ``peak`` of the difference (N, m or m/s^2, over
    every signal and frame the two runs share), and both relative to the RMS
    and to the peak of the reference (``rms_rel``, ``peak_rel``; None when the
    reference is zero). A derived quantity (:data:`DERIVED`) is its trace with each
    signal's own time mean (over the frames shared) taken out, in both runs, and then
    the same difference.
    """
    out = {name: _difference(traces.get(name), reference.get(name)) for name in QUANTITIES}
    for name, source in DERIVED.items():
        out[name] = _difference(traces.get(source), reference.get(source), dynamic=True)
    return out


def _difference(a: np.ndarray | None, b: np.ndarray | None,
                dynamic: bool = False) -> dict[str, float | None]:
    """Return the RMS and peak difference of trace ``a`` from ``b``, absolute and relative."""
    if a is None or b is None or a.size == 0 or b.size == 0 or a.shape[1] != b.shape[1]:
        return {'rms': None, 'peak': None, 'rms_rel': None, 'peak_rel': None}
    n = min(a.shape[0], b.shape[0])
    a, b = a[:n], b[:n]
    if dynamic:
        a, b = a - a.mean(axis=0), b - b.mean(axis=0)
    diff = a - b
    rms = float(np.sqrt(np.mean(diff**2)))
    peak = float(np.max(np.abs(diff)))
    ref_rms = float(np.sqrt(np.mean(b**2)))
    ref_peak = float(np.max(np.abs(b)))
    return {'rms': rms, 'peak': peak, 'rms_rel': rms / ref_rms if ref_rms > 0 else None,
            'peak_rel': peak / ref_peak if ref_peak > 0 else None}
