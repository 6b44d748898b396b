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
Tests of the stepping thread with the node's real threading model, without ROS.

The :class:`Stepper` runs on its own thread as in the node; the test thread plays
the executor (parameter changes, pause, stop). The bag must be opened, written and
closed on the stepping thread, for MCAP and for SQLite 3 (whose objects refuse any
other thread), and hold every frame the controller recorded, read back by rosbags.
Waits are bounded (hang guards), never timing assertions.
"""

from __future__ import annotations

import functools
from pathlib import Path
import threading
from typing import Any

import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.config import load_scenario, Scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.topics import topic_table
from ttb_sim.node import DEFAULT_SCENARIO, initial_values, parameter_table, Stepper, Tick
from ttb_sim.sim import Frame, Layout
from polling import poll_until  # noqa: I100 - the helper in test/

TIMEOUT = 60.0


wait_for = functools.partial(poll_until, timeout=TIMEOUT)


class ThreadRecorder:
    """A frame sink that notes the thread of every call, around a real BagRecorder."""

    def __init__(self, inner: BagRecorder | None = None) -> None:
        self.inner = inner
        self.threads: dict[str, set[int]] = {'open': {threading.get_ident()}, 'write': set(),
                                             'close': set()}
        self.frames = 0
        self.closed = False

    def write(self, frame: Frame) -> None:
        self.threads['write'].add(threading.get_ident())
        if self.inner is not None:
            self.inner.write(frame)
        self.frames += 1

    def close(self) -> None:
        self.threads['close'].add(threading.get_ident())
        if self.inner is not None:
            self.inner.close()
        self.closed = True


def values_for(scenario: Scenario, **given: Any) -> dict[str, Any]:
    base: dict[str, Any] = {'real_time_factor': 0.0, 'loop': False}
    base.update(given)
    return initial_values(parameter_table(scenario), base)


class Ticks:
    """Collects ticks as the node's publisher would be handed them."""

    def __init__(self) -> None:
        self.frames: list[Frame] = []
        self.events: list[str] = []
        self.lock = threading.Lock()

    def __call__(self, tick: Tick) -> None:
        with self.lock:
            self.frames.extend(tick.frames)
            self.events.extend(tick.events)


@pytest.mark.parametrize('storage', ['sqlite3', 'mcap'])
def test_bag_lives_on_the_stepping_thread_and_holds_every_frame(beam: Scenario,
                                                                tmp_path: Path,
                                                                storage: str) -> None:
    path = tmp_path / f'bag-{storage}'
    recorders: list[ThreadRecorder] = []

    def open_recorder(layout: Layout) -> ThreadRecorder:
        inner = BagRecorder(path, topic_table(layout), storage).__enter__()
        recorders.append(ThreadRecorder(inner))
        return recorders[-1]

    ticks = Ticks()
    stepper = Stepper(beam, values_for(beam), on_tick=ticks, open_recorder=open_recorder)
    stepper.start()
    stepper.publishing_ready()
    wait_for(lambda: stepper.controller is not None and stepper.controller.state == 'idle')
    assert stepper.stop()
    rec = recorders[0]
    assert rec.closed and rec.frames > 10
    stepping = rec.threads['write']
    assert len(stepping) == 1 and stepping != {threading.get_ident()}
    assert rec.threads['open'] == stepping and rec.threads['close'] == stepping
    with AnyReader([path]) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
    assert set(counts.values()) == {rec.frames}
    assert 'idle' in ticks.events


def test_changes_during_the_build_apply_to_the_built_model(beam: Scenario) -> None:
    release = threading.Event()
    opened = threading.Event()

    def open_recorder(layout: Layout) -> ThreadRecorder:
        opened.set()
        assert release.wait(TIMEOUT)
        return ThreadRecorder()

    ticks = Ticks()
    stepper = Stepper(beam, values_for(beam, loop=True, publish_rate_hz=0.0), on_tick=ticks,
                      open_recorder=open_recorder)
    stepper.start()
    try:
        assert opened.wait(TIMEOUT)
        status = stepper.status()
        assert status.state == 'building' and stepper.controller is None
        stepper.apply('train.speed_kmh', 250)   # an integer, as `ros2 param set` sends it
        release.set()
        wait_for(lambda: stepper.status().state == 'waiting')
        assert not ticks.frames                   # nothing stepped before publishers exist
        stepper.publishing_ready()
        wait_for(lambda: len(ticks.frames) > 3)
        assert stepper.status().state == 'running'
        with ticks.lock:
            assert ticks.frames[-1].speed == pytest.approx(250 / 3.6)
        assert stepper.controller is not None
        assert stepper.controller.values['train.speed_kmh'] == 250.0
    finally:
        release.set()
        assert stepper.stop()
    assert stepper.status().state == 'stopped'


def test_a_failed_build_is_reported_once_and_ends_the_thread(beam: Scenario) -> None:
    bad = load_scenario('moving_force_beam', [], [('solver.dt', 1e-6),
                                                  ('solver.duration', 1e4)])
    failures: list[str] = []
    stepper = Stepper(bad, values_for(bad), on_tick=Ticks(),
                      on_failed=lambda message, code: failures.append((message, code)))
    stepper.start()
    wait_for(lambda: not stepper.alive)
    status = stepper.status()
    assert status.state == 'failed' and failures == [(status.error, 2)]
    assert 'solver.dt' in status.error and "'moving_force_beam'" in status.error


def test_a_recorder_that_cannot_open_fails_without_stepping(beam: Scenario,
                                                            tmp_path: Path) -> None:
    def open_recorder(layout: Layout) -> ThreadRecorder:
        raise ScenarioError('cannot create bag: disk full')

    ticks = Ticks()
    failures: list[str] = []
    stepper = Stepper(beam, values_for(beam), on_tick=ticks, open_recorder=open_recorder,
                      on_failed=lambda message, code: failures.append(message))
    stepper.start()
    stepper.publishing_ready()
    wait_for(lambda: not stepper.alive)
    assert failures == ['cannot create bag: disk full'] and not ticks.frames


def test_stop_while_paused_closes_on_the_stepping_thread(beam: Scenario) -> None:
    recorders: list[ThreadRecorder] = []

    def open_recorder(layout: Layout) -> ThreadRecorder:
        recorders.append(ThreadRecorder())
        return recorders[-1]

    stepper = Stepper(beam, values_for(beam, real_time_factor=1.0, loop=True),
                      on_tick=Ticks(), open_recorder=open_recorder)
    stepper.start()
    stepper.publishing_ready()
    wait_for(lambda: recorders and recorders[0].frames > 0)
    assert stepper.controller is not None
    assert 'paused' in stepper.controller.set_paused(True)
    assert stepper.stop()
    rec = recorders[0]
    assert rec.closed and rec.threads['close'] == rec.threads['write']


def test_the_default_scenario_streams_wheel_rail_forces_and_loops() -> None:
    scenario = load_scenario(DEFAULT_SCENARIO)
    table = parameter_table(scenario)
    assert table['loop'].default is True
    assert scenario.train.vehicle != 'moving_force' and scenario.bridge.n_spans > 1
    stepper = Stepper(scenario, values_for(scenario), on_tick=Ticks())
    stepper.start()
    try:
        wait_for(lambda: stepper.status().state in ('waiting', 'failed'))
        assert stepper.controller is not None
        names = [t.full_name() for t in topic_table(stepper.controller.layout)]
    finally:
        assert stepper.stop()
    assert any('/wheel_rail/' in n for n in names)
    assert any('/bridge/span02/midspan' in n for n in names)
    assert any('/bearings/' in n for n in names)
    assert any(n.endswith('/body/imu') for n in names)
