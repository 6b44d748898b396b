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

"""Tests of the passage controller: passages, speed changes, pacing, recording, diagnostics."""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.config import load_scenario, Scenario
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.topics import SOIL_FIELDS, topic_table
from ttb_sim.node.diagnostics import ERROR, OK
from ttb_sim.node.parameters import initial_values, parameter_table
from ttb_sim.node.passage import PassageController
from ttb_sim.sim import Frame


class FakeClock:
    """A wall clock the test moves by hand."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


class ListRecorder:
    """Collects frames like a BagRecorder."""

    def __init__(self) -> None:
        self.frames: list[Frame] = []
        self.closed = False

    def write(self, frame: Frame) -> None:
        assert not self.closed
        self.frames.append(frame)

    def close(self) -> None:
        self.closed = True


def controller(scenario: Scenario, recorder=None, clock=None, **values) -> PassageController:
    table = parameter_table(scenario)
    given = {'real_time_factor': 0.0, 'loop': False}   # the node loops by default
    given.update(values)
    kwargs = {'recorder': recorder}
    if clock is not None:
        kwargs['clock'] = clock
    return PassageController(scenario, initial_values(table, given), **kwargs)


def run_until_idle(c: PassageController) -> list[Frame]:
    published = []
    for _ in range(1000):
        if c.state != 'running':
            break
        published.extend(c.advance(budget=5.0).frames)
    return published


# -- passage controller ---------------------------------------------------------------------

def test_speed_change_applies_at_the_next_frame(beam):
    c = controller(beam, publish_rate_hz=0.0)
    frames = c.advance(budget=5.0, max_frames=10).frames
    assert frames[-1].speed == pytest.approx(200 / 3.6)
    c.apply('train.speed_kmh', 350)   # an integer, as `ros2 param set` sends it
    head = frames[-1].head_position
    nxt = c.advance(budget=5.0, max_frames=1).frames[0]
    assert nxt.speed == pytest.approx(97.2, abs=0.05)
    assert nxt.speed == pytest.approx(350 / 3.6)
    assert nxt.head_position - head == pytest.approx(350 / 3.6 * c.frame_period)
    assert c.values['train.speed_kmh'] == 350.0
    # the next passage is built at the new speed too
    assert c.passage_scenario().train.speed_kmh == 350.0


def test_reset_restarts_the_passage_with_continuous_time(beam):
    c = controller(beam)
    c.advance(budget=5.0, max_frames=20)   # mid-passage
    before = c.last_frame
    message = c.reset()
    assert 'passage 2' in message
    first = c.advance(budget=5.0, max_frames=1).frames[0]
    assert first.head_position == pytest.approx(beam.train.start_position)
    assert first.time == pytest.approx(before.time + c.frame_period)
    assert first.step == 0


@pytest.mark.parametrize('rate', [0.01, 3.0])
def test_the_next_passage_continues_from_the_simulated_end(beam, rate):
    # A publishing period longer than the passage (0.01 Hz), or one that does not divide
    # it (3 Hz): the node's time must follow the simulated time, not the publishing grid.
    c = controller(beam, loop=True, publish_rate_hz=rate)
    planned = c.sim.n_steps * c.sim.dt
    published = []
    for _ in range(100):
        tick = c.advance(budget=5.0, max_frames=100)
        published += tick.frames
        if c.passage == 2:
            break
    assert c.time_offset == pytest.approx(planned + c.sim.dt, rel=1e-12)
    published += c.advance(budget=5.0, max_frames=1).frames
    starts = [f.time for f in published if f.step == 0]
    assert starts[0] == 0.0 and starts[1] == pytest.approx(planned + c.sim.dt, rel=1e-12)


def test_pause_stops_stepping_and_resume_continues(beam):
    c = controller(beam)
    c.advance(budget=5.0, max_frames=5)
    t = c.last_frame.time
    assert 'paused' in c.set_paused(True)
    tick = c.advance(budget=5.0)
    assert tick.stepped == 0 and c.last_frame.time == t and c.state == 'paused'
    c.set_paused(False)
    assert c.advance(budget=5.0, max_frames=3).stepped == 3
    assert c.last_frame.time == pytest.approx(t + 3 * c.frame_period)


def test_without_loop_the_node_idles_after_the_passage(beam):
    c = controller(beam, loop=False)
    run_until_idle(c)
    assert c.state == 'idle' and c.passage == 1
    assert c.last_frame.head_position >= c.sim.exit_position
    assert c.advance().stepped == 0
    assert 'nothing to pause' in c.set_paused(True)
    c.apply('loop', True)   # switching loop on wakes an idle node
    assert c.state == 'running' and c.passage == 2


def test_with_loop_passages_repeat(beam):
    c = controller(beam, loop=True)
    events, times = [], []
    for _ in range(200):
        tick = c.advance(budget=5.0, max_frames=500)
        events += tick.events
        times += [f.time for f in tick.frames]
        if c.passage >= 3:
            break
    assert c.passage >= 3 and c.state == 'running'
    assert events.count('restarted') >= 2 and 'idle' not in events
    assert all(b > a for a, b in zip(times, times[1:]))   # /clock never goes back


def test_speed_up_ends_the_passage_early(beam):
    slow = controller(beam)
    run_until_idle(slow)
    fast = controller(beam)
    fast.apply('train.speed_kmh', 400)
    run_until_idle(fast)
    assert fast.state == 'idle'
    assert fast.last_frame.time < slow.last_frame.time


def test_every_frame_recorded_publishing_decimated(beam):
    rec = ListRecorder()
    c = controller(beam, recorder=rec, publish_rate_hz=50.0)
    published = run_until_idle(c)
    n_frames = c.sim.n_frames
    assert len(rec.frames) == n_frames
    assert c.recorded == n_frames
    times = [f.time for f in published]
    assert times[0] == 0.0
    assert len(published) == pytest.approx(c.last_frame.time * 50 + 1, abs=1)
    gaps = [b - a for a, b in zip(times, times[1:])]
    assert min(gaps) == pytest.approx(0.02, abs=1e-9)
    assert max(gaps) == pytest.approx(0.02, abs=1e-9)


def test_publish_rate_zero_publishes_every_frame(beam):
    c = controller(beam, publish_rate_hz=0.0)
    assert len(run_until_idle(c)) == c.sim.n_frames


def test_recorded_bag_has_the_topic_table_and_every_frame(beam, tmp_path: Path):
    c = controller(beam)
    topics = topic_table(c.layout)
    bag = BagRecorder(tmp_path / 'bag', topics).__enter__()
    c.recorder = bag
    run_until_idle(c)
    c.close()
    with AnyReader([tmp_path / 'bag']) as reader:
        names = {x.topic: x.msgtype for x in reader.connections}
        counts = {x.topic: x.msgcount for x in reader.connections}
    assert names == {t.full_name(): t.msgtype for t in topics}
    assert set(counts.values()) == {c.sim.n_frames}


def test_irregularity_changes_apply_from_the_next_passage(beam):
    c = controller(beam)
    c.advance(budget=5.0, max_frames=3)
    c.apply('irregularity.seed', 7)
    c.apply('irregularity.scale', 0)
    assert c.sim.scenario.irregularity.seed == 1   # current passage unchanged
    assert c.passage_scenario().irregularity.seed == 7
    c.reset()
    assert c.sim.scenario.irregularity.seed == 7
    assert c.sim.scenario.irregularity.scale == 0.0
    diag = c.diagnostics().as_dict()
    assert 'seed=7' in diag['irregularity (from next passage)']


def test_divergence_stops_stepping_closes_the_bag_and_reports(tmp_path: Path):
    scenario = load_scenario('moving_force_beam', ['solver.divergence_limit=1e-9'])
    rec = ListRecorder()
    c = controller(scenario, recorder=rec, loop=True)
    tick = c.advance(budget=5.0)
    assert 'diverged' in tick.events
    assert c.state == 'diverged' and rec.closed and c.recorder is None
    assert len(rec.frames) >= 1   # frames before the failure were recorded
    assert c.advance().stepped == 0
    report = c.diagnostics()
    assert report.level == ERROR
    assert 'diverged' in report.message and 'divergence_limit' in report.message
    assert report.as_dict()['state'] == 'diverged'
    assert 'nothing to pause' in c.set_paused(True)
    # a reset restarts stepping (unrecorded: the bag stays closed)
    c.values['bag.enabled'] = True
    assert 'not recorded' in c.reset()
    assert c.state == 'running'


def test_a_passage_that_cannot_start_is_reported(beam, tmp_path: Path):
    c = controller(beam)
    c.advance(budget=5.0, max_frames=3)
    bad = tmp_path / 'profile.csv'
    bad.write_text('not, a, profile\n')
    c.apply('irregularity.file', str(bad))
    c.apply('irregularity.spectrum', 'no_such')   # bypassing validation on purpose
    c.reset()   # must not raise inside a service callback
    assert c.state == 'failed'
    report = c.diagnostics()
    assert report.level == ERROR and 'cannot start passage 2' in report.message
    assert c.advance().stepped == 0


def test_close_is_idempotent_and_stops_stepping(beam):
    rec = ListRecorder()
    c = controller(beam, recorder=rec)
    c.advance(budget=5.0, max_frames=3)
    c.close()
    c.close()
    assert rec.closed and c.state == 'stopped'
    assert c.advance().stepped == 0


# -- pacing and diagnostics -----------------------------------------------------------------

def test_real_time_factor_paces_simulation_time(beam):
    clock = FakeClock()
    c = controller(beam, clock=clock, real_time_factor=1.0, publish_rate_hz=0.0)
    assert c.advance(budget=5.0).stepped == 1                        # the t = 0 frame only
    clock.now += 0.1
    c.advance(budget=5.0)
    assert c.last_frame.time == pytest.approx(0.1, abs=c.frame_period)
    tick = c.advance(budget=5.0)                                     # nothing due yet
    assert tick.stepped == 0 and 0 < tick.sleep <= c.frame_period + 1e-9
    c.apply('real_time_factor', 2)                         # re-anchors at the current time
    clock.now += 0.1
    c.advance(budget=5.0)
    assert c.last_frame.time == pytest.approx(0.3, abs=c.frame_period)


def test_diagnostics_report_rate_step_time_and_frame_values(beam):
    clock = FakeClock()
    c = controller(beam, clock=clock, real_time_factor=0.5)
    c.diagnostics()   # open a window
    c.advance(budget=5.0)
    for _ in range(10):
        clock.now += 0.1
        c.advance(budget=5.0)
    clock.now += 0.0001
    report = c.diagnostics()
    d = report.as_dict()
    assert report.level == OK
    assert float(d['real-time factor']) == pytest.approx(0.5, rel=0.05)
    assert float(d['step time (ms)']) > 0
    assert d['contact iterations'] == '0'
    assert d['divergence'] == 'none'
    assert d['state'] == 'running'
    assert float(d['speed (km/h)']) == pytest.approx(200.0)
    assert 'span01 midspan z (m)' in d
    assert float(d['solver dt (s)']) == pytest.approx(c.sim.dt)


def test_diagnostics_warn_when_slower_than_requested(beam):
    clock = FakeClock()
    c = controller(beam, clock=clock, real_time_factor=1.0)
    c.diagnostics()
    c.advance()
    clock.now += 0.2
    c.advance(max_frames=2)     # a slow machine: far fewer frames than due
    clock.now += 0.8
    report = c.diagnostics()
    assert report.level == 1 and 'slower than requested' in report.message


def test_markers_refresh_is_throttled(beam):
    clock = FakeClock()
    c = controller(beam, clock=clock, real_time_factor=1.0, publish_rate_hz=0.0)
    assert c.advance().markers
    clock.now += 0.05
    assert not c.advance().markers
    clock.now += 0.06
    assert c.advance().markers


def test_a_substructure_scenario_streams_its_piles_and_soil_points(tmp_path: Path):
    """scenario:=single_pile (coarse, harmonic): frames carry piles and ground; speed is inert."""
    scenario = load_scenario('single_pile', [
        'soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
        'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6', 'load.type=harmonic',
        'load.frequency=4', 'output.rate_hz=100', 'solver.duration=0.2'])
    recorder = ListRecorder()
    c = controller(scenario, recorder=recorder, loop=False, publish_rate_hz=0.0)
    assert [t.name for t in topic_table(c.layout)] == [
        '/clock', 'piles/pier01/pile01/displacement', 'piles/pier01/pile01/imu', 'soil/points']
    c.apply('train.speed_kmh', 350)   # accepted, no effect on the substructure
    published = run_until_idle(c)
    assert c.state == 'idle' and len(recorder.frames) == 21 == len(published)
    assert recorder.frames[-1].time == pytest.approx(0.2)
    assert abs(recorder.frames[-1].pile_displacement[0, 2]) > 0
    assert recorder.frames[-1].soil_points.shape[1] == len(SOIL_FIELDS)


def test_the_pace_runs_on_across_loop_restarts(beam):
    """At real_time_factor 1 the simulated time follows the wall clock over many passages."""
    clock = FakeClock()
    c = controller(beam, clock=clock, loop=True, real_time_factor=1.0)
    start = clock.now
    c.advance(budget=5.0)
    while c.passage < 4:
        clock.now += 0.05
        c.advance(budget=5.0)
    elapsed = clock.now - start
    # Within one frame of the wall clock: a re-anchor at every restart lost 0.05 s per passage.
    assert c.node_time == pytest.approx(elapsed, abs=c.frame_period + 1e-9)


def test_a_slow_passage_build_is_caught_up_not_lost(beam, monkeypatch):
    """A loop restart whose build takes longer than MAX_LAG (a loaded machine) loses no time."""
    import ttb_sim.node.passage as passage
    clock = FakeClock()
    c = controller(beam, clock=clock, loop=True, real_time_factor=1.0)
    build = passage.make_runner

    def slow_build(scenario):
        clock.now += passage.MAX_LAG + 0.1   # the build's wall time, on the test's clock
        return build(scenario)
    monkeypatch.setattr(passage, 'make_runner', slow_build)
    start = clock.now
    per_tick = round(0.1 / c.frame_period)   # stepping at twice real time: a catch-up of
    c.advance(budget=5.0)                     # a build spans several ticks
    while c.passage < 5:
        clock.now += 0.05
        c.advance(budget=5.0, max_frames=per_tick)
    for _ in range(int(2 * (passage.MAX_LAG + 0.1) / 0.05)):   # catch the last build up
        clock.now += 0.05
        c.advance(budget=5.0, max_frames=per_tick)
    # A re-anchor in the middle of each catch-up lost about 0.5 s a passage.
    assert c.node_time == pytest.approx(clock.now - start, abs=0.1)
