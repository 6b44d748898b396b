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

"""Tests of the forwarding of library log records to the node's ROS logger."""

from __future__ import annotations

import logging

from ttb_sim.node.logs import ForwardingHandler, install, level_name


class Sink:
    """Collects (level, message) like the node's ROS logger; ``ok`` False: shut down."""

    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []
        self.ok = True

    def __call__(self, level: str, message: str) -> bool:
        if self.ok:
            self.lines.append((level, message))
        return self.ok


class FakeClock:
    """A clock the test moves by hand."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def _installed(sink: Sink, clock: FakeClock | None = None):
    handler = ForwardingHandler(sink, clock=clock or FakeClock())
    return handler, install(handler)


def test_levels_map_to_the_ros_logger_methods():
    assert [level_name(n) for n in (10, 20, 30, 40, 50)] == [
        'debug', 'info', 'warning', 'error', 'fatal']


def test_a_warning_repeated_at_every_passage_is_forwarded_once():
    sink = Sink()
    handler, uninstall = _installed(sink)
    try:
        log = logging.getLogger('ttb_sim.fe.factorization')
        for _ in range(21):   # 21 loop restarts
            log.warning('%s (package %s) is not installed; factorising with %s instead',
                        'qdldl', 'qdldl', 'superlu_sym')
        logging.getLogger('ttb_sim.sim.simulation').warning('solver.dt = %.3g s exceeds', 0.01)
        logging.getLogger('ttb_sim.sim.simulation').warning('solver.dt = %.3g s exceeds', 0.02)
    finally:
        uninstall()
    assert sink.lines == [
        ('warning', 'qdldl (package qdldl) is not installed; factorising with superlu_sym '
                    'instead'),
        ('warning', 'solver.dt = 0.01 s exceeds'), ('warning', 'solver.dt = 0.02 s exceeds')]
    assert handler.dropped == 20


def test_progress_lines_are_throttled_and_repeats_dropped():
    sink, clock = Sink(), FakeClock()
    _, uninstall = _installed(sink, clock)
    log = logging.getLogger('ttb_sim.model.foundation.reduction')
    try:
        for second in range(0, 31, 2):   # a line every 2 s of a 30 s build
            clock.now = float(second)
            log.info('building model: %d s so far', second)
        log.info('model: %d free DOFs', 10)
        clock.now = 100.0
        log.info('model: %d free DOFs', 10)   # the same text at the next passage
    finally:
        uninstall()
    assert [m for _, m in sink.lines] == [
        'building model: 0 s so far', 'building model: 10 s so far',
        'building model: 20 s so far', 'building model: 30 s so far', 'model: 10 free DOFs']


def test_records_reach_the_sink_only_and_uninstall_restores_the_logger(capsys):
    logger = logging.getLogger('ttb_sim')
    before = (logger.level, logger.propagate, list(logger.handlers))
    sink = Sink()
    _, uninstall = _installed(sink)
    logging.getLogger('ttb_sim.sim').warning('forwarded')
    sink.ok = False   # rclpy has shut down: a warning still shows, on stderr
    logging.getLogger('ttb_sim.sim').warning('after shutdown')
    uninstall()
    assert sink.lines == [('warning', 'forwarded')]
    assert 'after shutdown' in capsys.readouterr().err
    assert (logger.level, logger.propagate, list(logger.handlers)) == before


def test_the_progress_watcher_keeps_the_last_build_progress_for_the_diagnostics():
    """A reduction's per-shift record reaches /diagnostics' build report with its percent."""
    from ttb_sim.model.foundation.reduction import BuildProgress
    from ttb_sim.node.logs import install, ProgressWatcher
    from ttb_sim.node.shell import node_diagnostics
    from ttb_sim.node.stepper import StepperStatus
    watcher = ProgressWatcher()
    undo = install(watcher)
    try:
        progress = BuildProgress(5, 600.0)
        progress(2)
    finally:
        undo()
    assert watcher.latest is not None
    fraction, left, line = watcher.latest
    assert fraction == 0.4 and left is not None and '2 of 5 shifts done (40 %)' in line
    report = node_diagnostics('paper_ttbcpsi', StepperStatus('building', 12.0), None,
                              progress=watcher.latest)
    values = dict(report.values)
    assert values['substructure reduction done (%)'] == '40'
    assert '40 %' in report.message
