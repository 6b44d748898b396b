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
The stepping thread: builds the model, opens, writes and closes the bag, steps passages.

:class:`Stepper` runs everything heavy of the live node on one thread of its
own, so that the executor stays free for parameters, services and diagnostics:

1. it builds the :class:`~ttb_sim.node.passage.PassageController` (the model),
   while :meth:`Stepper.status` reports ``building`` with the elapsed time;
2. it opens the recorder (a :class:`~ttb_sim.node.runs.FrameSink` made by
   ``open_recorder``) on this thread, waits until the caller says it is ready
   to publish (:meth:`Stepper.publishing_ready`), then steps, paced by the
   real-time factor, handing each :class:`~ttb_sim.node.passage.Tick` to
   ``on_tick``;
3. when stopped, it closes the controller and with it the recorder, again on
   this thread (SQLite objects may only be used on the thread that made them).

Parameter changes that arrive while the model is built are kept and applied to
the controller as soon as it exists.
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import threading
import time
from typing import Any, Callable, Mapping

from ttb_sim.config import Scenario
from ttb_sim.errors import TtbSimError
from ttb_sim.node.parameters import normalize_value, parameter_table
from ttb_sim.node.passage import PassageController, Tick
from ttb_sim.node.runs import FrameSink
from ttb_sim.sim import Layout

log = logging.getLogger(__name__)

MAX_SLEEP = 0.05
"""Longest wall-clock wait between two stepping ticks (s): bounds the reaction to a stop."""


@dataclass(frozen=True)
class StepperStatus:
    """
    What the stepping thread is doing, as plain data.

    Attributes
    ----------
    state : str
        'building', 'waiting' (built, publishers not yet ready), 'running'
        (stepping; the controller has its own passage state), 'failed' or
        'stopped'.
    elapsed : float
        Wall-clock seconds since the thread started (building) or the build time.
    error : str
        Why it failed ('' otherwise).

    """

    state: str
    elapsed: float
    error: str = ''


class Stepper:
    """
    Build the model and step it on a thread of its own.

    Parameters
    ----------
    scenario : Scenario
        The loaded scenario.
    values : mapping
        Every node parameter's value at start-up (validated).
    on_tick : callable
        Receives every tick (frames to publish, events); called on the thread.
    open_recorder : callable, optional
        ``open_recorder(layout)`` returns an open frame sink; called on the thread
        after the build (the bag then gets every frame from t = 0).
    on_built : callable, optional
        Called on the thread once the controller exists (e.g. to create the
        publishers of its topic table on the executor).
    on_failed : callable, optional
        Called on the thread as ``on_failed(message, code)`` when building or opening
        fails (code 2: the scenario or the bag destination; 1: anything else).
    budget : float
        Wall-clock seconds of one stepping tick.
    clock : callable
        Monotonic wall clock in seconds (pacing; injectable for tests).

    """

    def __init__(self, scenario: Scenario, values: Mapping[str, Any], *,
                 on_tick: Callable[[Tick], None],
                 open_recorder: Callable[[Layout], FrameSink] | None = None,
                 on_built: Callable[[PassageController], None] | None = None,
                 on_failed: Callable[[str, int], None] | None = None,
                 budget: float = 0.02,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.scenario = scenario
        self.table = parameter_table(scenario)
        self.values = dict(values)
        self.controller: PassageController | None = None
        self._on_tick = on_tick
        self._open_recorder = open_recorder
        self._on_built = on_built
        self._on_failed = on_failed
        self._budget = budget
        self._clock = clock
        self._lock = threading.Lock()
        self._pending: list[tuple[str, Any]] = []
        self._stop = threading.Event()
        self._wake = threading.Event()
        self._ready = threading.Event()
        self._state = 'building'
        self._error = ''
        self._started = clock()
        self._build_time = 0.0
        self._thread = threading.Thread(target=self._run, name='ttb_sim-stepper', daemon=True)

    # -- control ------------------------------------------------------------------------

    def start(self) -> None:
        """Start building and stepping."""
        self._started = self._clock()
        self._thread.start()

    def publishing_ready(self) -> None:
        """Tell the thread that the publishers exist: stepping may start."""
        self._ready.set()
        self._wake.set()

    def stop(self, timeout: float = 5.0) -> bool:
        """
        Stop stepping, close the bag on the stepping thread and wait for it.

        Returns
        -------
        bool
            True when the thread has ended (False: still building after ``timeout``;
            it is a daemon thread and stops at the next tick, and no bag is open yet).

        """
        self._stop.set()
        self._wake.set()
        if self._thread.is_alive() and self._thread is not threading.current_thread():
            self._thread.join(timeout)
        return not self._thread.is_alive()

    def wake(self) -> None:
        """Cut the current wait short (after a speed, pace or pause change)."""
        self._wake.set()

    def apply(self, name: str, value: Any) -> None:
        """Apply a validated parameter value now, or as soon as the model is built."""
        with self._lock:
            if self.controller is not None:
                self.controller.apply(name, value)
            else:
                param = self.table.get(name)
                self.values[name] = normalize_value(param, value) if param else value
                self._pending.append((name, value))
        self.wake()

    def status(self) -> StepperStatus:
        """Return what the thread is doing."""
        with self._lock:
            if self._state == 'building':
                return StepperStatus('building', self._clock() - self._started)
            return StepperStatus(self._state, self._build_time, self._error)

    @property
    def alive(self) -> bool:
        """Tell whether the thread is running."""
        return self._thread.is_alive()

    # -- the thread ---------------------------------------------------------------------

    def _fail(self, message: str, code: int) -> None:
        with self._lock:
            self._state, self._error = 'failed', message
        if self._on_failed is not None:   # it reports the failure (the node: one FATAL line)
            self._on_failed(message, code)
        else:
            log.error(message)

    def _run(self) -> None:
        controller = self._build()
        if controller is None:
            return
        try:
            self._wait_ready()
            with self._lock:
                if self._state == 'waiting':
                    self._state = 'running'
            while not self._stop.is_set():
                tick = controller.advance(budget=self._budget)
                self._on_tick(tick)
                wait = min(tick.sleep, MAX_SLEEP)
                if wait > 0 and not self._stop.is_set():
                    self._wake.wait(wait)
                    self._wake.clear()
        except Exception as exc:  # noqa: B902 - a failure ends stepping, never the node
            self._fail(f'stepping stopped: {type(exc).__name__}: {exc}', 1)
        finally:
            controller.close()   # closes the recorder on the thread that opened it
            with self._lock:
                if self._state != 'failed':
                    self._state = 'stopped'

    def _build(self) -> PassageController | None:
        """Build the controller and open the recorder; None on failure or stop."""
        log.debug('building model: %s', self.scenario.name)
        try:
            with self._lock:
                values = dict(self.values)
            controller = PassageController(self.scenario, values, clock=self._clock)
        except TtbSimError as exc:
            self._fail(f'cannot build scenario {self.scenario.name!r}: {exc}', 2)
            return None
        except Exception as exc:  # noqa: B902 - reported as a failed build, not a traceback
            self._fail(f'building scenario {self.scenario.name!r} failed: '
                       f'{type(exc).__name__}: {exc}', 1)
            return None
        if self._stop.is_set():
            controller.close()
            return None
        if self._open_recorder is not None:
            try:
                controller.recorder = self._open_recorder(controller.layout)
            except TtbSimError as exc:
                controller.close()
                self._fail(str(exc), 2)
                return None
        with self._lock:
            for name, value in self._pending:
                controller.apply(name, value)
            self._pending.clear()
            self.controller = controller
            self._build_time = self._clock() - self._started
            self._state = 'waiting'
        log.debug('model built in %.2f s', self._build_time)
        if self._on_built is not None:
            self._on_built(controller)
        return controller

    def _wait_ready(self) -> None:
        while not self._stop.is_set() and not self._ready.is_set():
            self._wake.wait(MAX_SLEEP)
            self._wake.clear()
