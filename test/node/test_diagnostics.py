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

"""Tests of what the node reports on /diagnostics (ttb_sim.node.diagnostics)."""

import pytest
from ttb_sim.io.cdr import typestore
from ttb_sim.node.diagnostics import (diagnostic_array, DiagnosticsReport, ERROR, OK,
                                      passage_level, SlidingWindow, StepMeter, StepWindow,
                                      WARN)


def test_the_meter_gives_the_window_since_the_last_reading():
    meter = StepMeter(10.0)
    for _ in range(4):
        meter.frame(5, 0.01)
    meter.stepping(0.02, 0.015)
    first = meter.window(12.0)
    assert (first.wall, first.steps) == (2.0, 20)
    assert first.simulated == pytest.approx(0.04)
    assert first.real_time_factor == pytest.approx(0.02)
    assert first.step_ms == pytest.approx(1.0)
    assert first.cpu == pytest.approx(0.015)
    empty = meter.window(12.0)
    assert (empty.wall, empty.steps, empty.real_time_factor, empty.step_ms) == (0.0, 0, 0.0, 0.0)


def test_the_level_of_a_passage():
    slow = StepWindow(wall=1.0, simulated=0.5, steps=10, stepping=0.9, cpu=0.9)
    assert passage_level('running', '', '', 3, 1.0, slow) == (
        WARN, 'slower than requested: real-time factor 0.50 over the last 1.0 s < 1 (50 % short)')
    nearly = StepWindow(wall=5.0, simulated=4.8, steps=10, stepping=0.9, cpu=0.9)
    assert passage_level('running', '', '', 3, 1.0, nearly) == (OK, 'running, passage 3')
    short = StepWindow(wall=5.0, simulated=4.7, steps=10, stepping=0.9, cpu=0.9)
    assert passage_level('running', '', '', 3, 1.0, short)[1].endswith('(6 % short)')
    assert passage_level('running', '', '', 3, 0.0, slow) == (OK, 'running, passage 3')
    assert passage_level('paused', '', '', 3, 1.0, slow) == (OK, 'paused, passage 3')
    assert passage_level('diverged', 'NaN at step 7', '', 3, 1.0, slow) == (
        ERROR, 'diverged: NaN at step 7')
    assert passage_level('failed', 'cannot start', '', 3, 1.0, slow) == (ERROR, 'cannot start')
    assert passage_level('running', '', 'bag write failed', 3, 0.0, slow) == (
        ERROR, 'bag write failed')


def test_the_diagnostic_array_carries_the_report():
    store = typestore()
    report = DiagnosticsReport(WARN, 'slow', (('state', 'running'), ('passage', '2')))

    def types(name):
        return store.types[name]
    stamp = types('builtin_interfaces/msg/Time')(sec=3, nanosec=4)
    array = diagnostic_array(types, report, 'ttb_sim: simulation', 'ttb_sim', stamp)
    status = array.status[0]
    assert array.header.stamp == stamp and array.header.frame_id == ''
    assert status.level == bytes([WARN]) and status.message == 'slow'
    assert (status.name, status.hardware_id) == ('ttb_sim: simulation', 'ttb_sim')
    assert [(kv.key, kv.value) for kv in status.values] == list(report.values)


def test_the_sliding_window_covers_the_last_five_seconds():
    sliding = SlidingWindow(5.0)
    for k in range(8):   # 1 s windows: 1 s simulated each, then 0.5 s from the 6th on
        rate = 1.0 if k < 5 else 0.5
        over = sliding.add(StepWindow(wall=1.0, simulated=rate, steps=10, stepping=0.5,
                                      cpu=0.5))
    assert over.wall == 5.0
    assert over.real_time_factor == pytest.approx((2 * 1.0 + 3 * 0.5) / 5)
    sliding.clear()
    assert sliding.add(StepWindow(1.0, 0.9, 1, 0.1, 0.1)).real_time_factor == pytest.approx(0.9)
