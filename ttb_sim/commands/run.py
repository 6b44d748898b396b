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
The ``run`` verb: a scenario simulated to a rosbag2 directory plus ``summary.json``.

This is the library behind ``ttb-sim run``: it validates everything before it
creates anything, writes frames as they come, and leaves a closed, readable bag
and a summary whatever way the run ends (success, divergence, interruption).
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import logging
from pathlib import Path
import signal
import sys
import time
from typing import Any, Callable, Sequence, TYPE_CHECKING

from ttb_sim import __version__
from ttb_sim.commands.signals import signal_name, SignalHandlers, StopFlag
from ttb_sim.config import load_scenario
from ttb_sim.errors import SimulationError

if TYPE_CHECKING:
    from ttb_sim.config import Scenario
    from ttb_sim.io.topics import PeakTracker, Topic
    from ttb_sim.sim import CostEstimate, Runner

# The model, the stepping core and the bag writer are imported where first needed (about a
# second): a scenario path that does not exist is refused before them.

log = logging.getLogger(__name__)

EXIT_OK, EXIT_FAILURE = 0, 1


@dataclass
class RunResult:
    """What a run produced."""

    path: Path
    status: str
    """'ok', 'diverged' or 'interrupted'."""
    summary: dict[str, Any]


def run_to_bag(scenario: Scenario, out: str | Path, storage: str = 'mcap',
               progress: Callable[[int], None] | None = None,
               simulation: Runner | None = None,
               should_stop: Callable[[], bool] | None = None,
               setup_time: float = 0.0, estimate: CostEstimate | None = None) -> RunResult:
    """
    Simulate a scenario and record it.

    Parameters
    ----------
    scenario : Scenario
        Validated scenario.
    out : Path
        Bag directory to create (must not exist).
    storage : str
        'mcap' or 'sqlite3'.
    progress : callable, optional
        Called with the number of frames written since the last call.
    simulation : Runner, optional
        An already built model of ``scenario`` (:func:`~ttb_sim.sim.make_runner`).
    should_stop : callable, optional
        Polled between frames; when it returns True the run stops cleanly with
        status 'interrupted' (signal handlers set such a flag, so that no
        exception ever interrupts a message half-written).
    setup_time : float
        Seconds already spent on set-up (loading, building) by the caller; the
        time to build ``simulation`` here, when it is not given, is added.
    estimate : CostEstimate, optional
        The cost estimate told to the user (made here when not given); it is
        written to ``summary.json``.

    Returns
    -------
    RunResult
        Status 'ok', 'diverged' or 'interrupted'.

    Raises
    ------
    ScenarioError
        Before anything is written, for a bad storage or an existing ``out``.
    KeyboardInterrupt
        Re-raised after the bag and summary have been closed and written.

    """
    from ttb_sim.config.labels import LABELS_KEY
    from ttb_sim.io.bag import BagRecorder, check_destination, make_parents
    from ttb_sim.io.sensor_stream import SensorStream
    from ttb_sim.io.topics import NAMESPACE, PeakTracker, topic_table
    from ttb_sim.sim import make_runner

    check_destination(out, storage)  # before summary.json could land in someone's folder
    out = Path(out)
    built = time.perf_counter()
    sim = simulation or make_runner(scenario)
    setup_time += time.perf_counter() - built
    topics = topic_table(sim.layout)
    sensing = SensorStream(scenario, sim.layout, sim.dt, sim.output_every)  # before the bag
    estimate = estimate or sim.plan(len(topics))
    peaks = PeakTracker(topics)
    make_parents(out)
    done = _Progress()
    start = time.perf_counter()
    try:
        with BagRecorder(out, topics, storage, extra=sensing.extra) as bag:
            bag.set_custom_data(LABELS_KEY, json.dumps(sensing.labels, sort_keys=True))
            sensing.write_labels(bag, 0)
            try:
                for frame in sim.frames():
                    bag.write(frame)
                    sensing.write(bag, sensing.push(frame))
                    peaks.update(frame)
                    done.frames += 1
                    done.last_time = frame.time
                    if progress is not None:
                        progress(1)
                    if should_stop is not None and should_stop():
                        done.status, done.message = 'interrupted', 'stopped by a signal'
                        break
            finally:   # the samples of the frames written, whatever ended the run
                sensing.write(bag, sensing.flush())
    except SimulationError as exc:  # divergence, interface iterations that fail
        done.status, done.message = 'diverged', str(exc)
    except KeyboardInterrupt:
        done.status, done.message = 'interrupted', 'interrupted by a signal'
        raise
    finally:
        summary = _summary(scenario, sim, out, storage, topics, estimate, peaks, done,
                           setup_time, time.perf_counter() - start)
        summary['bag']['topics'] += [f'{NAMESPACE}/{name}' for name, _ in sensing.extra]
        summary['sensors'] = sensing.describe()
        summary['labels'] = sensing.labels
        if out.is_dir():
            (out / 'summary.json').write_text(json.dumps(summary, indent=2) + '\n',
                                              encoding='utf-8')
    return RunResult(path=out, status=done.status, summary=summary)


@dataclass
class _Progress:
    """How far a run got: its status and message, the frames written, the last frame's time."""

    status: str = 'ok'
    message: str = ''
    frames: int = 0
    last_time: float = 0.0


def _summary(scenario: Scenario, sim: Runner, out: Path, storage: str, topics: Sequence[Topic],
             estimate: CostEstimate, peaks: PeakTracker, done: _Progress, setup_time: float,
             stepping: float) -> dict[str, Any]:
    """Return the contents of ``summary.json``."""
    wall = setup_time + stepping
    return {
        'ttb_sim_version': __version__,
        'status': done.status,
        'message': done.message,
        'scenario': scenario.echo(),
        'bag': {'path': str(out), 'storage': storage,
                'topics': [t.full_name() for t in topics]},
        'solver': {'dt': sim.dt, 'steps_planned': sim.n_steps,
                   'duration_planned': sim.duration, 'free_dofs': sim.n_free,
                   'output_every_steps': sim.output_every, **sim.describe()},
        'frames': done.frames,
        'simulated_time': done.last_time,
        'estimate': estimate.as_dict(),
        'setup_time': setup_time,
        'stepping_time': stepping,
        'wall_time': wall,
        'real_time_factor': done.last_time / wall if wall > 0 else None,
        'peaks': peaks.summary(),
        'soil_points': list(sim.layout.soil_point_names),
    }


def run(scenario: str | Path, *, out: str | Path | None = None, storage: str = 'mcap',
        overrides: Sequence[str] = (), speed_kmh: float | None = None,
        duration: float | None = None, force: bool = False) -> int:
    """
    Run ``ttb-sim run``: load, build, simulate to a bag; return the exit code.

    Parameters
    ----------
    scenario
        YAML path or built-in name.
    out
        Bag directory to create (default: a new folder under ``./runs/``).
    storage
        'mcap' or 'sqlite3'.
    overrides
        ``KEY=VALUE`` strings (YAML scalars).
    speed_kmh, duration
        Shortcuts for ``train.speed_kmh`` and ``solver.duration``.
    force
        Run even above the step budget (:data:`~ttb_sim.sim.STEP_BUDGET`).

    Raises
    ------
    ScenarioError
        Before anything is written, for a bad scenario or destination, or a
        plan over the step budget without ``force``.

    """
    start = time.perf_counter()
    stop = StopFlag()
    handlers = SignalHandlers()
    handlers.install(stop)
    bar = None
    try:
        loaded, out, simulation = _set_up(scenario, out, storage, overrides, speed_kmh,
                                          duration, force)
        from ttb_sim.io.topics import topic_table
        estimate = simulation.plan(len(topic_table(simulation.layout)))
        print(f'ttb-sim: plan: {estimate.describe()}', file=sys.stderr)
        stop.setup = False  # from here on a signal closes the bag cleanly
        if sys.stderr.isatty():
            from tqdm import tqdm
            bar = tqdm(total=simulation.n_frames, unit='frame', desc=loaded.name,
                       file=sys.stderr, leave=False)
        result = run_to_bag(loaded, out, storage,
                            progress=bar.update if bar is not None else None,
                            simulation=simulation, should_stop=stop.__bool__,
                            setup_time=time.perf_counter() - start, estimate=estimate)
    finally:
        handlers.restore()
        if bar is not None:
            bar.close()
    s = result.summary
    if result.status == 'interrupted':
        print(f'ttb-sim: stopped by {signal_name(stop.signal)}; bag closed at {out} with '
              f'{s["frames"]} frames', file=sys.stderr)
        return 128 + (stop.signal or signal.SIGINT)
    if result.status == 'diverged':
        print(f'ttb-sim: failed: {s["message"]}; bag closed at {out} with {s["frames"]} '
              'frames', file=sys.stderr)
        return EXIT_FAILURE
    print(f'{out}: {s["frames"]} frames, {s["simulated_time"]:.3f} s simulated in '
          f'{s["wall_time"]:.2f} s (set-up {s["setup_time"]:.2f} s; real-time factor '
          f'{s["real_time_factor"]:.3g})')
    return EXIT_OK


def _set_up(scenario: str | Path, out: str | Path | None, storage: str, overrides: Sequence[str],
            speed_kmh: float | None, duration: float | None, force: bool
            ) -> tuple[Scenario, Path, Runner]:
    """Load the scenario, check the destination, then build the model (in that order)."""
    values: list[tuple[str, Any]] = []
    if speed_kmh is not None:
        values.append(('train.speed_kmh', speed_kmh))
    if duration is not None:
        values.append(('solver.duration', duration))
    loaded = load_scenario(scenario, overrides, values)  # before the model's modules import
    from ttb_sim.io.bag import check_destination, default_bag_path
    from ttb_sim.sim import make_runner, STEP_BUDGET

    target = out if out is not None else default_bag_path(loaded.name)
    check_destination(target, storage)  # before the model is built: a bad --out fails at once
    log.info('set-up: building the model of %s', loaded.name)
    return loaded, Path(target), make_runner(loaded, max_steps=None if force else STEP_BUDGET)
