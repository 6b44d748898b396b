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
Prove that the core of ttb_sim never imports rclpy or a ROS message package.

Every module is imported in a fresh interpreter in which an import hook refuses
rclpy, the rosidl runtime and the ROS message/service packages (even where ROS 2
is installed), and records who asked for them. All must import except
:mod:`ttb_sim.simulator_node`, which serves as the control: the hook stops it.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
import subprocess
import sys
import warnings

import ttb_sim

BLOCKED = ('rclpy', 'rosidl_runtime_py', 'rosidl_parser', 'rpyutils', 'builtin_interfaces',
           'std_msgs', 'std_srvs', 'geometry_msgs', 'sensor_msgs', 'nav_msgs',
           'diagnostic_msgs', 'visualization_msgs', 'rosgraph_msgs', 'rcl_interfaces',
           'launch', 'launch_ros')

ROS_ONLY = {'ttb_sim.simulator_node'}

_PROBE = r"""
import importlib, importlib.abc, json, pkgutil, sys, traceback

BLOCKED = set(json.loads(sys.argv[1]))
ROS_ONLY = set(json.loads(sys.argv[2]))
attempts = []


class RosBlocked(ImportError):
    pass


class Blocker(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split('.')[0] in BLOCKED:
            attempts.append(name)
            raise RosBlocked(f'{name} is blocked: the ttb_sim core must not import ROS')
        return None


for name in list(sys.modules):
    if name.split('.')[0] in BLOCKED:
        del sys.modules[name]
sys.meta_path.insert(0, Blocker())

import ttb_sim
results = {}
for info in pkgutil.walk_packages(ttb_sim.__path__, 'ttb_sim.'):
    before = len(attempts)
    try:
        importlib.import_module(info.name)
        status = 'ok'
    except RosBlocked as exc:
        status = 'ros: ' + str(exc)
    except ImportError as exc:
        status = 'other: ' + repr(exc)
    except Exception:
        status = 'error: ' + traceback.format_exc(limit=3)
    results[info.name] = {'status': status, 'ros_attempts': attempts[before:]}
print(json.dumps(results))
"""


def _probe() -> dict[str, dict]:
    root = str(Path(ttb_sim.__file__).resolve().parent.parent)
    env = dict(os.environ)
    env['PYTHONPATH'] = os.pathsep.join(p for p in (root, env.get('PYTHONPATH')) if p)
    proc = subprocess.run(
        [sys.executable, '-c', _PROBE, json.dumps(BLOCKED), json.dumps(sorted(ROS_ONLY))],
        capture_output=True, text=True, timeout=300, cwd=root, env=env)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


def test_core_modules_import_with_ros_blocked() -> None:
    """Every module but simulator_node imports, and none even tries to import ROS."""
    results = _probe()
    for name in ROS_ONLY:   # control: the hook does stop the rclpy shell
        assert results[name]['status'].startswith('ros'), (name, results[name])
        del results[name]
    for name in ('ttb_sim.node', 'ttb_sim.io.topics', 'ttb_sim.io.bag',
                 'ttb_sim.sim.simulation', 'ttb_sim.config', 'ttb_sim.cli'):
        assert results[name]['status'] == 'ok', (name, results[name])
    ros = {name: r for name, r in results.items()
           if r['ros_attempts'] or r['status'].startswith('ros')}
    assert not ros, f'modules that import ROS: {ros}'
    errors = {name: r['status'] for name, r in results.items()
              if r['status'].startswith('error')}
    assert not errors, f'modules that fail to import: {errors}'
    missing = {name: r['status'] for name, r in results.items()
               if r['status'].startswith('other')}
    if missing:  # an optional, non-ROS dependency is absent: not this test's concern
        warnings.warn(f'modules not importable here (non-ROS reasons): {missing}')
