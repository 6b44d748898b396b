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
The plan told before a run: cost estimate, step budget, dt accuracy warning, validate progress.

The estimate is a model (ttb_sim/sim/cost.py); these tests check what it
counts and where it is told, never how fast anything runs.
"""

import json
import logging
from pathlib import Path

import pytest
from ttb_sim.cli import main
from ttb_sim.commands.validate import validate
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.sim import estimate_cost, Simulation, STEP_BUDGET


def test_the_plan_is_told_and_written(tmp_path: Path, capsys) -> None:
    out = tmp_path / 'bag'
    assert main(['run', 'moving_force_beam', '--duration', '0.01', '--out', str(out)]) == 0
    err = capsys.readouterr().err
    assert 'ttb-sim: plan: 20 steps of 0.0005 s' in err and '95 free DOFs' in err
    assert 'estimated' in err
    estimate = json.loads((out / 'summary.json').read_text())['estimate']
    assert estimate['steps'] == 20 and estimate['free_dofs'] == 95
    assert estimate['frames'] == 21 and estimate['messages'] == 21 * 7
    assert estimate['wall_time'] > 0.0


def test_the_estimate_grows_with_steps_dofs_cars_and_variant() -> None:
    kw = {'steps': 1000, 'dt': 1e-4, 'free_dofs': 1000, 'cars': 0, 'frames': 10,
          'messages_per_frame': 5, 'variant': 'qdldl'}
    base = estimate_cost(**kw).wall_time
    assert estimate_cost(**{**kw, 'steps': 2000}).wall_time > base
    assert estimate_cost(**{**kw, 'free_dofs': 50_000}).wall_time > base
    assert estimate_cost(**{**kw, 'cars': 8}).wall_time > base
    assert estimate_cost(**{**kw, 'variant': 'reference'}).wall_time > base
    # the reduced track is cheaper only where there is a track under multibody cars
    cars = {**kw, 'cars': 8}
    assert (estimate_cost(**{**cars, 'variant': 'reduced'}).wall_time
            < estimate_cost(**cars).wall_time)
    assert estimate_cost(**{**kw, 'variant': 'reduced'}).wall_time == base
    # the compiled loop of moving forces and quarter cars is cheaper than qdldl's steps
    assert estimate_cost(**{**kw, 'variant': 'realtime'}).wall_time < base
    large = {**kw, 'steps': 10**6, 'free_dofs': 50_000}
    assert 'estimated 10.3 min' in estimate_cost(**large).describe()


@pytest.mark.parametrize('sets, words', [
    (['solver.dt=1e-9'], r'solver.duration = 0 \(automatic: 0.755437 s\) at solver.dt = 1e-09 '
                         r's plans 7.55e\+08 time steps, over the budget of 2e\+07'),
    (['bridge.bending_stiffness=1'], r'at dt = 0.002 s \(automatic\) plans 6.12e\+07'),
    (['solver.duration=1e5', 'solver.dt=1e-5'], r'solver.duration = 100000 s'),
])
def test_a_plan_over_the_budget_is_refused_before_building(sets, words) -> None:
    with pytest.raises(ScenarioError, match=words + '.*or pass --force'):
        Simulation(load_scenario('moving_force_beam', sets))


def test_the_cli_refuses_over_budget_with_exit_2_and_writes_nothing(tmp_path, capsys) -> None:
    out = tmp_path / 'bag'
    assert main(['run', 'moving_force_beam', '--set', 'solver.dt=1e-9', '--out',
                 str(out)]) == 2
    assert 'pass --force' in capsys.readouterr().err
    assert not out.exists()


def test_force_lifts_the_budget_but_not_the_hard_limit() -> None:
    scenario = load_scenario('moving_force_beam', ['solver.dt=1e-9'])
    sim = Simulation(scenario, max_steps=None)  # --force: built, not run here
    assert sim.n_steps > STEP_BUDGET
    with pytest.raises(ScenarioError, match=r'plans inf time steps, over the budget of 1e\+12'):
        Simulation(load_scenario('moving_force_beam', ['solver.dt=5e-324']), max_steps=None)


def test_a_coarse_dt_is_warned_about(caplog) -> None:
    with caplog.at_level(logging.WARNING, logger='ttb_sim.sim.simulation'):
        Simulation(load_scenario('moving_force_beam', ['solver.dt=0.01',
                                                       'solver.duration=0.05']))
    assert 'solver.dt = 0.01 s exceeds the accuracy rule T1/200 = 0.000897 s' in caplog.text
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger='ttb_sim.sim.simulation'):
        Simulation(load_scenario('moving_force_beam', ['solver.dt=0.0005',
                                                       'solver.duration=0.05']))
    assert 'accuracy rule' not in caplog.text


def test_validate_tells_progress_per_case(capsys) -> None:
    assert validate(['V4', 'V5']) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith('[1/2] V4 ') and err[0].endswith('...')
    assert err[1].startswith('[1/2] V4 pass in ')
    assert err[2].startswith('[2/2] V5 ') and err[3].startswith('[2/2] V5 pass in ')
