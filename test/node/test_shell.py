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

"""Tests of the ROS-free half of the rclpy shell (ttb_sim.node.shell)."""

import threading

import pytest
from ttb_sim.errors import ScenarioError
from ttb_sim.io.topics import topic_table
from ttb_sim.node.diagnostics import DiagnosticsReport, ERROR, OK, WARN
from ttb_sim.node.parameters import initial_values, parameter_table
from ttb_sim.node.passage import PassageController, Tick
from ttb_sim.node.publishing import PublishStats
from ttb_sim.node.shell import (bag_destination, building_message, ClockGuard,
                                declare_parameters, live_topics, node_diagnostics, open_bag,
                                pause_answer, qos_class, shutdown_line, tick_messages)
from ttb_sim.node.stepper import StepperStatus
from ttb_sim.sim import Simulation


def test_start_up_declares_the_scenario_first_then_its_parameters():
    declared = []

    def declare(name, default, param):
        declared.append(name)
        return {'scenario': 'moving_force_beam', 'train.speed_kmh': 300}.get(name, default)
    start = declare_parameters(declare)
    assert declared[0] == 'scenario' and declared.count('scenario') == 1
    assert set(declared) == set(start.table)
    assert start.scenario.name == 'moving_force_beam'
    assert start.values['train.speed_kmh'] == 300.0
    assert 'train.speed_kmh' in start.integers_for_doubles()


def test_a_scenario_that_does_not_load_is_a_scenario_error():
    with pytest.raises(ScenarioError):
        declare_parameters(lambda name, default, param: 'no_such_scenario')


def test_qos_classes_say_what_they_are():
    assert qos_class('data', 'reliable') == 'reliable'
    assert qos_class('data', 'best_effort') == 'best_effort'
    assert qos_class('clock', 'best_effort') == 'clock'
    assert qos_class('latched', 'best_effort') == 'latched'
    with pytest.raises(ValueError, match='unknown topic QoS class'):
        qos_class('fast', 'reliable')


def test_the_shutdown_line_says_what_ran(beam, tmp_path):
    assert 'before the model was built' in shutdown_line(None, 0, None)
    c = PassageController(beam, initial_values(parameter_table(beam),
                                               {'real_time_factor': 0.0, 'loop': False}))
    c.advance(budget=5.0, max_frames=20)
    line = shutdown_line(c, 7, tmp_path / 'bag')
    assert line.startswith('shutting down: 1 passage(s), ')
    assert 's simulated' in line and 'real-time factor' in line
    assert '7 frames published' in line and str(tmp_path / 'bag') in line
    assert 'recorded' not in shutdown_line(c, 7, None)


def test_the_bag_destination(beam, tmp_path):
    table = parameter_table(beam)
    off = initial_values(table, {'bag.enabled': False})
    assert bag_destination(off, beam.name) is None
    on = initial_values(table, {'bag.enabled': True, 'bag.path': str(tmp_path / 'bag')})
    assert bag_destination(on, beam.name) == tmp_path / 'bag'
    (tmp_path / 'bag').mkdir()
    with pytest.raises(ScenarioError, match='bag.path'):
        bag_destination(on, beam.name)


def test_open_bag_records_under_the_namespace(beam, tmp_path):
    sim = Simulation(beam)
    recorder = open_bag(tmp_path / 'a' / 'bag', 'mcap', sim.layout, '/robot/ttb_sim')
    recorder.write(next(iter(sim.frames())))
    recorder.close()
    assert (tmp_path / 'a' / 'bag' / 'metadata.yaml').is_file()
    text = (tmp_path / 'a' / 'bag' / 'metadata.yaml').read_text()
    assert '/robot/ttb_sim/bridge/span01/midspan' in text


def test_live_topics_leave_out_the_clock_and_name_private_topics(beam):
    topics = topic_table(Simulation(beam).layout)
    live = live_topics(topics)
    assert len(live) == len([t for t in topics if t.qos != 'clock'])
    for topic, name in live:
        assert topic.qos != 'clock'
        assert name == topic.name if topic.name.startswith('/') else name == f'~/{topic.name}'


def test_the_clock_never_goes_backwards_across_threads():
    guard = ClockGuard()
    sent = []
    guard.send(2_500_000_000, lambda s, n: sent.append((s, n)))
    guard.send(1_000_000_000, lambda s, n: sent.append((s, n)))
    guard.send(2_500_000_000, lambda s, n: sent.append((s, n)))
    assert sent == [(2, 500_000_000), (2, 500_000_000)]
    out: list[int] = []

    def send_all(start):
        for t in range(start, 2000, 2):
            guard.send(3_000_000_000 + t, lambda s, n: out.append(s * 10**9 + n))
    threads = [threading.Thread(target=send_all, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out == sorted(out)


def test_answers_and_log_lines(beam):
    building = StepperStatus('building', 1.25)
    assert building_message(building) == ('the model is still being built (1.2 s so far); '
                                          'try again')
    failed = StepperStatus('failed', 2.0, 'bad file')
    assert building_message(failed) == 'the model could not be built: bad file'
    c = PassageController(beam, initial_values(parameter_table(beam), {}))
    assert pause_answer(c, True) == (True, 'paused at t = 0.000 s')
    assert tick_messages(Tick(events=['ended', 'idle']), c) == [
        ('info', 'the train has left: idle (set loop:=true or call ~/reset for another '
         'passage)')]
    c.divergence = 'boom'
    assert tick_messages(Tick(events=['diverged']), c) == [
        ('error', 'boom; stepping stopped, bag closed; call ~/reset to restart')]
    assert tick_messages(Tick(events=['diverged']), None) == []


def test_node_diagnostics_while_building_and_after():
    building = node_diagnostics('beam', StepperStatus('building', 3.04), None)
    assert (building.level, building.message) == (OK, 'building model: 3.0 s')
    assert building.as_dict() == {'state': 'building', 'scenario': 'beam',
                                  'build time so far (s)': '3.0'}
    failed = node_diagnostics('beam', StepperStatus('failed', 3.0, 'no memory'), None)
    assert (failed.level, failed.message) == (ERROR, 'cannot build the model: no memory')
    passage = DiagnosticsReport(WARN, 'slow', (('state', 'running'),))
    stats = PublishStats(offered=8, published=7, dropped=1, busy=0.00175)
    report = node_diagnostics('beam', StepperStatus('running', 0.5), passage, stats)
    assert (report.level, report.message) == (WARN, 'slow')
    assert list(report.as_dict()) == ['state', 'model build time (s)', 'published frames',
                                      'dropped frames (publishing could not keep up)',
                                      'publish CPU time per frame (ms)']
    assert report.as_dict()['publish CPU time per frame (ms)'] == '0.250'
    stopped = node_diagnostics('beam', StepperStatus('running', 0.5), passage,
                               PublishStats(0, 0, 0, 0.0), 'publishing stopped: OSError: gone')
    assert (stopped.level, stopped.message) == (ERROR, 'publishing stopped: OSError: gone')
