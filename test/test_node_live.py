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
The node as a ROS user meets it: a process on a real ROS 2 graph (skipped without ROS 2).

The node runs as ``ros2 run ttb_sim simulator`` when the package is installed in
the sourced workspace, else as ``python -m ttb_sim.simulator_node``, in its own
process group on a private ROS domain; Ctrl-C is SIGINT to the group, as a
terminal sends it. A probe node in this process subscribes and calls services,
and ``ros2 bag info`` reads the bags. Every wait is bounded (a hang guard); no
assertion is about wall time (real-time factors are measured, not tested).
"""

from __future__ import annotations

import os
from pathlib import Path
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from typing import Any, Callable

import pytest

rclpy = pytest.importorskip(
    'rclpy', reason='rclpy is not importable: source a ROS 2 Jazzy installation to run the '
    'live node tests (the node logic is tested without ROS in test/node/)')
ROS2 = shutil.which('ros2')
pytestmark = pytest.mark.skipif(
    ROS2 is None, reason='the ros2 command is not on PATH: source a ROS 2 Jazzy installation '
    'to run the live node tests')

from diagnostic_msgs.msg import DiagnosticArray  # noqa: E402, I100
from geometry_msgs.msg import WrenchStamped  # noqa: E402
from rclpy.context import Context  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.qos import QoSProfile  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from std_srvs.srv import SetBool, Trigger  # noqa: E402
from polling import poll_until  # noqa: E402, I100 - the helper in test/

ROOT = Path(__file__).resolve().parents[1]
TIMEOUT = 90.0
DOMAIN = str(random.Random(os.getpid()).randrange(100, 200))


def node_command() -> list[str]:
    """Return how a user starts the node here."""
    env = ros_env()
    found = subprocess.run([ROS2, 'pkg', 'prefix', 'ttb_sim'], env=env, capture_output=True,
                           timeout=60)
    if found.returncode == 0:
        return [ROS2, 'run', 'ttb_sim', 'simulator']
    return [sys.executable, '-m', 'ttb_sim.simulator']


def ros_env() -> dict[str, str]:
    env = dict(os.environ)
    env['ROS_DOMAIN_ID'] = DOMAIN
    env['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    env['PYTHONPATH'] = os.pathsep.join([str(ROOT)] + [p for p in env.get(
        'PYTHONPATH', '').split(os.pathsep) if p])
    env['PYTHONUNBUFFERED'] = '1'
    env['PYTHONFAULTHANDLER'] = '1'
    return env


class NodeProcess:
    """The node in its own process group; its output goes to a file."""

    def __init__(self, tmp: Path, *params: str, command: list[str] | None = None) -> None:
        args = []
        for p in params:
            args += ['-p', p]
        self.log = tmp / f'node-{time.monotonic_ns()}.log'
        self._out = self.log.open('w')
        cmd = (command or node_command()) + (['--ros-args', *args] if args else [])
        self.proc = subprocess.Popen(cmd, cwd=tmp, env=ros_env(), stdout=self._out,
                                     stderr=subprocess.STDOUT, start_new_session=True)

    def ctrl_c(self) -> int:
        """Send SIGINT to the process group (a terminal's Ctrl-C); return the exit code."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
        return self.wait()

    def wait(self) -> int:
        try:
            code = self.proc.wait(timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            os.killpg(self.proc.pid, signal.SIGABRT)   # faulthandler: every thread's stack
            time.sleep(1.0)
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
            pytest.fail(f'the node did not end within {TIMEOUT} s:\n{self.output()}')
        self._out.close()
        return code

    def output(self) -> str:
        return self.log.read_text(errors='replace')


class Probe:
    """A probe node on the node's domain, spun in a background thread."""

    def __init__(self) -> None:
        os.environ['ROS_DOMAIN_ID'] = DOMAIN
        os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = rclpy.create_node('ttb_sim_live_probe', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._spin, daemon=True)
        self.thread.start()

    def _spin(self) -> None:
        try:
            self.executor.spin()
        except Exception:  # noqa: B902 - the context is shut down at the end of a test
            pass

    def collect(self, msg_type: Any, topic: str) -> list[Any]:
        """Subscribe and return the list the messages are appended to."""
        got: list[Any] = []

        def keep(msg: Any) -> None:
            with self.lock:
                got.append(msg)

        self.node.create_subscription(msg_type, topic, keep, QoSProfile(depth=100))
        return got

    def call(self, srv_type: Any, name: str, request: Any) -> Any:
        client = self.node.create_client(srv_type, name)
        assert client.wait_for_service(timeout_sec=TIMEOUT), name
        future = client.call_async(request)
        wait_for(future.done)
        return future.result()

    def close(self) -> None:
        self.executor.shutdown(timeout_sec=1.0)
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        self.thread.join(timeout=10.0)


def wait_for(condition: Callable[[], Any], timeout: float = TIMEOUT,
             proc: NodeProcess | None = None) -> Any:
    """Poll a condition; with ``proc``, stop when the node ends and show its output."""
    if proc is None:
        return poll_until(condition, timeout, interval=0.02)

    def ended() -> str:
        code = proc.proc.poll()
        return '' if code is None else f'the node ended early ({code}):\n{proc.output()}'

    return poll_until(condition, timeout, interval=0.02, abort=ended, detail=proc.output)


@pytest.fixture
def probe():
    p = Probe()
    yield p
    p.close()


def stamp(msg: Any) -> float:
    return msg.sec + 1e-9 * msg.nanosec


def assert_clean(output: str) -> None:
    assert 'Traceback' not in output, output
    assert 'RCLError' not in output and 'context is invalid' not in output, output


def test_default_node_streams_wheel_rail_forces_clock_and_keeps_the_paused_time(
        tmp_path: Path, probe: Probe) -> None:
    clock = probe.collect(Clock, '/clock')
    wheel = probe.collect(WrenchStamped, '/ttb_sim/wheel_rail/car01/axle1/left')
    node = NodeProcess(tmp_path)
    try:
        wait_for(lambda: len(wheel) >= 20 and len(clock) >= 20, proc=node)
        with probe.lock:
            forces = [m.wrench.force.z for m in wheel]
        assert all(f > 0 for f in forces)   # the rail pushes the wheel up
        # Half the static axle load per rail, 10 % either way for the dynamics.
        assert 0.9 * 78480.0 < sum(forces) / len(forces) < 1.1 * 78480.0
        answer = probe.call(SetBool, '/ttb_sim/pause', SetBool.Request(data=True))
        assert answer.success, answer.message
        time.sleep(0.5)   # let the last frames drain before watching the paused clock
        with probe.lock:
            n = len(clock)
        wait_for(lambda: len(clock) >= n + 5, proc=node)   # /clock goes on while paused
        with probe.lock:
            paused = {stamp(m.clock) for m in clock[n:]}
            times = [stamp(m.clock) for m in clock]
        assert len(paused) == 1
        assert all(b >= a for a, b in zip(times, times[1:]))   # never backwards
    finally:
        code = node.ctrl_c()
    assert code == 0, node.output()
    assert_clean(node.output())


def test_diagnostics_say_building_while_services_answer(tmp_path: Path, probe: Probe) -> None:
    diagnostics = probe.collect(DiagnosticArray, '/diagnostics')
    node = NodeProcess(tmp_path, 'scenario:=paper_ttbi')
    try:
        answer = probe.call(Trigger, '/ttb_sim/reset', Trigger.Request())
        building = not answer.success and 'being built' in answer.message
        if building:   # on a fast machine the model may be built already: then no claim
            wait_for(lambda: any('building model' in s.message for d in list(diagnostics)
                                 for s in d.status), proc=node)
    finally:
        code = node.ctrl_c()   # Ctrl-C during (or right after) the build
    assert code == 0, node.output()
    assert_clean(node.output())


@pytest.mark.parametrize('param, words', [
    ('train.speed_kmh:=-5.0', ['train.speed_kmh', '-5', '(0, 10000]']),
    ('publish_rate_hz:=-1.0', ['publish_rate_hz', '-1', '[0, 10000]']),
    ('loop:=yes_please', ['loop', 'yes_please', 'true or false']),
    ('scenario:=no_such_scenario', ['no_such_scenario']),
])
def test_bad_start_up_values_give_one_fatal_line_and_exit_2(tmp_path: Path, param: str,
                                                            words: list[str]) -> None:
    node = NodeProcess(tmp_path, param)
    code = node.wait()
    out = node.output()
    assert code == 2, out
    lines = [line for line in out.splitlines() if line.strip()]
    fatal = [line for line in lines if 'FATAL' in line]
    assert len(fatal) == 1 and all(w in fatal[0] for w in words), out
    assert_clean(out)


def test_existing_bag_directory_names_bag_path(tmp_path: Path) -> None:
    (tmp_path / 'taken').mkdir()
    node = NodeProcess(tmp_path, 'bag.enabled:=true', 'bag.path:=taken')
    assert node.wait() == 2
    assert 'choose another bag.path' in node.output()


@pytest.mark.parametrize('storage', ['sqlite3', 'mcap'])
def test_node_bags_open_in_ros2_bag_info(tmp_path: Path, probe: Probe, storage: str) -> None:
    if subprocess.run([ROS2, 'bag', '-h'], env=ros_env(), capture_output=True,
                      timeout=60).returncode != 0:
        pytest.skip('ros2 bag is not installed')
    clock = probe.collect(Clock, '/clock')
    node = NodeProcess(tmp_path, 'scenario:=moving_force_beam', 'bag.enabled:=true',
                       'bag.path:=bag', f'bag.storage:={storage}')
    try:
        wait_for(lambda: len(clock) >= 10, proc=node)
    finally:
        code = node.ctrl_c()
    assert code == 0, node.output()
    assert_clean(node.output())
    info = subprocess.run([ROS2, 'bag', 'info', str(tmp_path / 'bag')], env=ros_env(),
                          capture_output=True, text=True, timeout=60)
    assert info.returncode == 0, info.stdout + info.stderr
    assert f'Storage id:        {storage}' in info.stdout or storage in info.stdout
    count = int(info.stdout.split('Messages:')[1].split()[0])
    assert count > 0


def test_five_ctrl_c_in_a_row_exit_0_without_traceback(tmp_path: Path, probe: Probe) -> None:
    clock = probe.collect(Clock, '/clock')
    for k in range(5):
        node = NodeProcess(tmp_path)
        if k == 0:   # during (or right after) the build
            wait_for(lambda: 'building model' in node.output(), proc=node)
        else:
            n = len(clock)
            wait_for(lambda: len(clock) > n, proc=node)   # while streaming
            time.sleep(0.1 * k)
        code = node.ctrl_c()
        out = node.output()
        assert code == 0, out
        assert_clean(out)
