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


"""``ttb-sim identify``: the posterior from a bag alone, its files, and refusals in one line."""

import json
from pathlib import Path

import pytest
from ttb_sim.cli import main

pytest.importorskip('emcee', reason="pip install 'ttb_sim[twin]'")

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
