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

It validates everything before it creates anything, then records the passage with
:func:`ttb_sim.io.passage.run_to_bag`, which leaves a closed, readable bag and a
summary whatever way the run ends (success, divergence, interruption).
"""

from __future__ import annotations

import logging
from pathlib import Path
import signal
import sys
import time
from typing import Any, Sequence, TYPE_CHECKING

from ttb_sim.commands.signals import signal_name, SignalHandlers, StopFlag
from ttb_sim.config import load_scenario
from ttb_sim.io.passage import run_to_bag, RunResult  # noqa: F401 - the library of the verb

if TYPE_CHECKING:
    from ttb_sim.config import Scenario
    from ttb_sim.sim import Runner

# The model, the stepping core and the bag writer are imported where first needed (about a
# second): a scenario path that does not exist is refused before them.

log = logging.getLogger(__name__)

EXIT_OK, EXIT_FAILURE = 0, 1


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
