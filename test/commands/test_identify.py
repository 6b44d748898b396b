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


"""``ttb-sim identify``: the posterior from a bag alone, its files, refusals, its workers."""

import json
import os
from pathlib import Path
import signal
import subprocess
import sys

import numpy as np
import pytest
from ttb_sim.cli import main
from ttb_sim.commands.identify import PoolRunner
from ttb_sim.twin import FeatureSpec, ForwardModel

pytest.importorskip('emcee', reason="pip install 'ttb_sim[twin]'")

ROOT = Path(__file__).resolve().parents[2]
HANG_BOUND = 300.0
"""Seconds after which identify is taken as hung (a bound, not a speed check)."""

SET = ['--set', 'sensor_layouts=[span:1]', '--set', 'output.rate_hz=1000', '--set',
       'solver.dt=0.0005']
LOSS = 'damage.girders=[{span: 1, start: 14, length: 4, loss: 0.3}]'
ARGS = ['--param', 'damage.girders[0].loss=uniform:0,0.6', '--sensors',
        'span01_strain_mid,span01_acc_mid', '--design', '8', '--steps', '600']


@pytest.fixture(scope='module')
def observed(tmp_path_factory) -> Path:
    bag = tmp_path_factory.mktemp('identify') / 'observed'
    assert main(['run', 'moving_force_beam', '--out', str(bag), *SET, '--set', LOSS]) == 0
    return bag


def test_a_hidden_loss_from_the_bag_alone(observed, tmp_path, capsys):
    (observed / 'summary.json').unlink()   # a bag recorded elsewhere has none
    out = tmp_path / 'id'
    assert main(['identify', str(observed), *ARGS, '--out', str(out)]) == 0
    posterior = json.loads((out / 'posterior.json').read_text())
    loss = posterior['parameters']['damage.girders[0].loss']
    assert loss['q05'] <= 0.3 <= loss['q95'] and abs(loss['median'] - 0.3) < 0.05
    assert loss['identified']
    for name in ('chains.npz', 'corner.png', 'trace.png', 'fit.png', 'index.html',
                 'model_scenario.yaml'):
        assert (out / name).is_file()
    assert 'damage.girders[0].loss: median' in capsys.readouterr().out


@pytest.mark.parametrize('args, words', [
    (['--param', 'damage.girders[0].loss=beta:0,1'], 'give KEY=FAMILY:A,B'),
    (['--param', 'damage.girders[0].loss=uniform:0,x'], "'x' is not a number"),
    (['--param', 'bridge.spam=uniform:0,1'], "unknown key 'bridge.spam'"),
    (['--param', 'damage.girders[0].loss=uniform:0,2'], 'damage.girders[0].loss'),
    ([*ARGS, '--sensors', 'nope'], "no sensor 'nope'"),
    ([*ARGS, '--steps', '5'], '--steps 5'),
    ([], 'at least one --param'),
    ([*ARGS, '--workers', '0'], '--workers 0 must be from 1 to'),
    ([*ARGS, '--refine', '-1'], '--refine -1 must be an integer from 0'),
])
def test_bad_input_exits_2_in_one_line_and_writes_nothing(observed, tmp_path, capsys, args,
                                                          words):
    out = tmp_path / 'id'
    assert main(['identify', str(observed), *args, '--out', str(out)]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_a_bag_without_its_scenario_needs_one(tmp_path, capsys):
    assert main(['identify', str(tmp_path / 'missing'), *ARGS]) == 2
    assert 'missing' in capsys.readouterr().err


def test_the_design_is_the_same_bits_on_one_or_two_workers():
    model = ForwardModel('moving_force_beam', ['damage.girders[0].loss'],
                         overrides=[*SET[1::2], 'solver.duration=0.3',
                                    LOSS.replace('0.3}', '0.0}')],
                         sensors=['span01_acc_mid'], noise=False,
                         features=FeatureSpec(psd_fmin_hz=4.0, psd_fmax_hz=90.0,
                                              psd_points=12, psd_segment_s=0.25))
    thetas = [[0.1], [2.0], [0.3]]   # the second refused: recorded, the others go on
    here = model.evaluate_many(thetas)
    assert [r['status'] for r in here] == ['ok', 'failed', 'ok']
    assert 'damage.girders[0].loss = 2.0' in here[1]['error']
    for workers in (1, 2):
        seen = []
        there = model.evaluate_many(thetas, PoolRunner(workers),
                                    lambda run, r: seen.append(run.index))
        assert sorted(seen) == [0, 1, 2]
        assert [r['status'] for r in there] == ['ok', 'failed', 'ok']
        for a, b in zip(here, there):
            assert a['status'] != 'ok' or np.array_equal(a['vector'], b['vector'])


@pytest.mark.parametrize('sig, code, at', [
    (signal.SIGTERM, 143, 'design of'),         # setting up (the bag read, the model built)
    (signal.SIGINT, 130, 'design run 1/'),      # the design running on two workers
])
def test_a_signal_stops_the_workers_and_writes_nothing(observed, tmp_path, sig, code, at):
    out = tmp_path / 'id'
    env = {**os.environ, 'PYTHONPATH': os.pathsep.join(
        [str(ROOT), os.environ.get('PYTHONPATH', '')])}
    proc = subprocess.Popen([sys.executable, '-m', 'ttb_sim.cli', 'identify', str(observed),
                             *ARGS, '--design', '12', '--workers', '2', '--out', str(out)],
                            stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                            env=env)
    assert proc.stderr is not None
    seen = []
    for line in proc.stderr:
        seen.append(line)
        if at in line:
            break
    proc.send_signal(sig)
    err = ''.join(seen) + proc.communicate(timeout=HANG_BOUND)[1]
    assert proc.returncode == code, err
    assert err.strip().splitlines()[-1] == \
        f'ttb-sim: stopped by {signal.Signals(sig).name}; nothing written', err
    assert 'Traceback' not in err
    assert list(tmp_path.iterdir()) == []   # no folder, no staging folder left behind


def test_a_second_design_over_the_first_posterior(observed, tmp_path):
    out = tmp_path / 'id'
    assert main(['identify', str(observed), *ARGS, '--refine', '6', '--out', str(out)]) == 0
    posterior = json.loads((out / 'posterior.json').read_text())
    assert posterior['diagnostics']['design_runs'] == 8 + 6
    loss = posterior['parameters']['damage.girders[0].loss']
    assert loss['q05'] <= 0.3 <= loss['q95'] and abs(loss['median'] - 0.3) < 0.05
    refined = np.load(out / 'chains.npz')['design_theta'][8:, 0]
    assert np.all(np.abs(refined - 0.3) < 0.15)   # the prior is U(0, 0.6): drawn near 0.3
