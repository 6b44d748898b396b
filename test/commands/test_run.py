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
The ``run`` verb (`run_to_bag`, `run`) on a tiny scenario: summary, refusals, divergence.

The scenario is ``moving_force_beam`` cut to 0.1 s: the force (156.96 kN at 200 km/h)
enters the 32 m span at t = 0, so the head is at x = v t and the mid-span deflects
downward, less than the static central value F L^3 / (48 EI) = 0.231 mm.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from ttb_sim.commands.run import EXIT_FAILURE, run, run_to_bag
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io.reader import bag_topics, read_bag

DURATION = 0.1
SPEED = 200.0 / 3.6
MIDSPAN = '/ttb_sim/bridge/span01/midspan'
ODOMETRY = '/ttb_sim/train/odometry'


def _scenario(*overrides: str):
    return load_scenario('moving_force_beam', [f'solver.duration={DURATION}', *overrides])


@pytest.fixture(scope='module')
def tiny_run(tmp_path_factory):
    out = tmp_path_factory.mktemp('run') / 'bag'
    return run_to_bag(_scenario(), out)


def test_summary_fields(tiny_run):
    """summary.json echoes the result: status, counts, times, topics and peaks."""
    summary = json.loads((tiny_run.path / 'summary.json').read_text(encoding='utf-8'))
    assert summary == json.loads(json.dumps(tiny_run.summary))
    assert tiny_run.status == summary['status'] == 'ok'
    assert summary['message'] == ''
    assert summary['scenario']['name'] == 'moving_force_beam'
    assert summary['scenario']['solver']['duration'] == DURATION
    assert summary['bag'] == {'path': str(tiny_run.path), 'storage': 'mcap',
                              'topics': list(bag_topics(tiny_run.path))}
    solver = summary['solver']
    assert solver['duration_planned'] == DURATION
    assert solver['steps_planned'] * solver['dt'] == pytest.approx(DURATION, rel=1e-9)
    assert summary['frames'] == solver['steps_planned'] // solver['output_every_steps'] + 1
    assert summary['simulated_time'] == pytest.approx(DURATION, rel=1e-9)
    assert summary['wall_time'] > 0.0
    assert summary['real_time_factor'] == pytest.approx(DURATION / summary['wall_time'])
    assert {'ttb_sim_version', 'peaks'} <= summary.keys()


def test_bag_agrees_with_summary_and_kinematics(tiny_run):
    """
    The bag holds every frame; the head moves at v (x = v t, 1e-9 m) and the peaks agree.

    Mid-span: sagging only, and within the static central deflection
    F L^3 / (48 EI) = 0.231 mm (the force is still near the support, a < 5.6 m).
    """
    summary = tiny_run.summary
    arrays = read_bag(tiny_run.path, [MIDSPAN, ODOMETRY])
    midspan, odometry = arrays[MIDSPAN], arrays[ODOMETRY]
    assert len(midspan) == len(odometry) == summary['frames']
    t = odometry.stamp
    assert odometry.component('position', 'x') == pytest.approx(SPEED * t, abs=1e-9)
    z = midspan.component('vector', 'z')
    peaks = summary['peaks'][MIDSPAN]['z']
    assert peaks['min'] == z.min()
    assert peaks['max'] == z.max()
    static = 156960.0 * 32.0**3 / (48.0 * 4.646e11)
    assert -static < z.min() < 0.0
    assert summary['peaks'][ODOMETRY]['pose.pose.position.x']['max'] == pytest.approx(
        SPEED * DURATION, rel=1e-9)


def test_existing_directory_refused_before_writing(tmp_path: Path):
    out = tmp_path / 'taken'
    out.mkdir()
    with pytest.raises(ScenarioError, match='exists; refusing to overwrite'):
        run_to_bag(_scenario(), out)
    assert list(out.iterdir()) == []


def test_unknown_storage_refused_before_writing(tmp_path: Path):
    out = tmp_path / 'new'
    with pytest.raises(ScenarioError, match="storage 'zip'"):
        run_to_bag(_scenario(), out, storage='zip')
    assert not out.exists()


def test_forced_divergence_leaves_a_readable_bag(tmp_path: Path):
    """
    solver.divergence_limit = 1e-5 m stops the run as the force loads the span.

    The status is 'diverged', the message names the limit, and the bag (closed) holds
    every frame written before the failure, the last one below the limit.
    """
    result = run_to_bag(_scenario('solver.divergence_limit=1e-5'), tmp_path / 'bag')
    summary = result.summary
    assert result.status == 'diverged'
    assert 'solver.divergence_limit = 1e-05 m' in summary['message']
    assert json.loads((result.path / 'summary.json').read_text())['status'] == 'diverged'
    assert 1 < summary['frames'] < summary['solver']['steps_planned'] + 1
    midspan = read_bag(result.path, [MIDSPAN])[MIDSPAN]
    assert len(midspan) == summary['frames']
    assert midspan.stamp[-1] == pytest.approx(summary['simulated_time'], abs=1e-9)
    assert np.max(np.abs(midspan['vector'])) <= 1e-5


def test_run_exit_code_on_divergence(tmp_path: Path, capsys):
    out = tmp_path / 'bag'
    code = run('moving_force_beam', out=out, duration=DURATION,
               overrides=['solver.divergence_limit=1e-5'])
    assert code == EXIT_FAILURE == 1
    assert 'failed: solution diverged' in capsys.readouterr().err
    assert (out / 'metadata.yaml').is_file()


def test_a_missing_scenario_file_is_refused_before_the_model_imports():
    """`ttb-sim run /nonexistent.yaml` refuses before the model, scipy's solvers, the core."""
    import subprocess
    import sys

    import ttb_sim

    code = ('import sys\n'
            'from ttb_sim.cli import main\n'
            'code = main(["run", "/nonexistent/scenario.yaml"])\n'
            'heavy = [m for m in ("ttb_sim.model", "ttb_sim.config.records", "ttb_sim.sim",\n'
            '                     "ttb_sim.io.bag", "scipy.sparse.linalg") if m in sys.modules]\n'
            'print(code, heavy)\n')
    root = str(Path(ttb_sim.__file__).resolve().parents[1])
    proc = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True,
                          env={'PYTHONPATH': root, 'PATH': '/usr/bin:/bin'}, check=False)
    assert proc.stdout.strip() == '2 []', proc.stderr
    assert "scenario file '/nonexistent/scenario.yaml' does not exist" in proc.stderr


@pytest.mark.parametrize('argv', [
    ['--set', 'solver.duration=abc', '--duration', '0.01'],
    ['--duration', '0.01', '--set', 'solver.duration=abc'],
    ['--set', 'solver.duration=abc', '--set', 'solver.duration=0.01'],
])
def test_a_bad_set_value_is_refused_whatever_overrides_it(tmp_path: Path, capsys, argv):
    """A later option of the same key (--duration, another --set) does not hide a bad value."""
    from ttb_sim.cli import main

    out = tmp_path / 'bag'
    assert main(['run', 'moving_force_beam', '--out', str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert err == ("ttb-sim: error: solver.duration = 'abc': expected a number, allowed "
                   '[0, 100000] s\n')
    assert not out.exists()


def test_a_bad_shortcut_value_is_refused_though_a_set_follows(tmp_path: Path, capsys):
    from ttb_sim.cli import main

    assert main(['run', 'moving_force_beam', '--out', str(tmp_path / 'b'), '--speed-kmh', '-3',
                 '--set', 'train.speed_kmh=200']) == 2
    assert 'train.speed_kmh = -3.0 is out of range: allowed (0, 10000] km/h' in \
        capsys.readouterr().err
    with pytest.raises(ScenarioError, match="solver.variant = 'turbo': allowed values"):
        load_scenario('moving_force_beam', ['solver.variant=turbo'],
                      [('solver.variant', 'qdldl')])
