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
A passage recorded: a scenario simulated to a rosbag2 directory plus ``summary.json``.

:func:`run_to_bag` is the library behind ``ttb-sim run``, ``sweep``, ``dataset`` and the
forward model of :mod:`ttb_sim.twin`: it writes frames as they come, the virtual
sensors' samples and the labels beside them, and leaves a closed, readable bag and a
summary whatever way the run ends (success, divergence, interruption).
"""

from __future__ import annotations

from dataclasses import dataclass
import json
import logging
from pathlib import Path
import time
from typing import Any, Callable, Sequence, TYPE_CHECKING

from ttb_sim import __version__
from ttb_sim.errors import SimulationError

if TYPE_CHECKING:
    from ttb_sim.config import Scenario
    from ttb_sim.io.sensor_stream import MetadataSink
    from ttb_sim.io.topics import PeakTracker, Topic
    from ttb_sim.sim import CostEstimate, Runner

__all__ = ['recorded_scenario', 'RunResult', 'run_to_bag', 'SCENARIO_KEY', 'store_scenario']

SCENARIO_KEY = 'ttb_sim.scenario'
"""The key of the run's scenario (JSON, as ``summary.json`` echoes it) in a bag's
``custom_data``: enough to build the same model again from the bag alone."""

log = logging.getLogger(__name__)


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
            store_scenario(bag, scenario)
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


def store_scenario(sink: MetadataSink, scenario: Scenario) -> None:
    """
    Store ``scenario`` in a bag's ``custom_data`` (:data:`SCENARIO_KEY`), as JSON.

    What :func:`recorded_scenario` reads back.  ``ttb-sim run`` stores it once; the
    node again whenever the scenario of its passage changes (the last value wins).
    """
    sink.set_custom_data(SCENARIO_KEY, json.dumps(scenario.echo(), sort_keys=True))


def recorded_scenario(bag: str | Path) -> dict[str, Any] | None:
    """
    Return the scenario a bag of ours was recorded from (plain data), or None.

    None for a bag without it (recorded by ``ros2 bag record``, or by an older
    ttb_sim), or whose ``metadata.yaml`` cannot be read.
    """
    import yaml
    path = Path(bag)
    metadata = path / 'metadata.yaml' if path.is_dir() else path.parent / 'metadata.yaml'
    try:
        info = yaml.safe_load(metadata.read_text(encoding='utf-8'))
        text = info['rosbag2_bagfile_information']['custom_data'][SCENARIO_KEY]
        data = json.loads(text)
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError):
        return None
    return data if isinstance(data, dict) else None
