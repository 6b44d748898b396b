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

"""`ttb-sim bench`: report structure and the zero difference of the reference from itself.

Never asserts on times: only on the structure and on the numbers that do not depend on
the machine.
"""

import json
from pathlib import Path

import pytest
from ttb_sim.cli import main
from ttb_sim.commands import bench as bn

TINY = ['moving_force_beam']
"""One span, one moving force: builds and steps in milliseconds."""


def _check_run(run: dict) -> None:
    for key in ('scenario', 'variant', 'factorization', 'status', 'dofs', 'dt', 'steps',
                'frames', 'simulated_time', 'build_time', 'start_time', 'step_time',
                'ms_per_step', 'cpu_ms_per_step', 'real_time_factor', 'peak_rss_mib',
                'difference'):
        assert key in run, key
    assert set(run['dofs']) == {'structure', 'track', 'bridge', 'vehicle', 'substructures',
                                'substructures_full', 'total', 'solved'}
    assert run['dofs']['solved'] <= run['dofs']['total']
    assert set(run['difference']) == set(bn.QUANTITIES)
    for quantity in run['difference'].values():
        assert set(quantity) == {'rms', 'peak', 'rms_rel', 'peak_rel'}


def test_in_process_report_and_reference_difference_is_zero():
    report = bn.bench(TINY, ['cholmod'], 0.01, isolate=False)
    assert set(report) == {'machine', 'runs'}
    runs = report['runs']
    assert [r['variant'] for r in runs] == ['reference', 'cholmod']
    for run in runs:
        _check_run(run)
        assert run['status'] == 'ok'
        assert run['steps'] == 20 and run['dt'] == pytest.approx(5e-4)
    ref = runs[0]['difference']['midspan']
    assert ref['rms'] == 0.0 and ref['peak'] == 0.0
    assert runs[1]['difference']['midspan']['rms_rel'] < 1e-9
    # moving forces have no wheel-rail contact: nothing to compare
    assert runs[0]['difference']['wheel_rail_vertical']['rms'] is None
    json.dumps(report)  # plain data


def test_isolated_runs_report_their_own_peak_memory():
    report = bn.bench(TINY, ['reference'], 0.005)
    (run,) = report['runs']
    _check_run(run)
    assert run['peak_rss_mib'] > 0
    assert run['difference']['midspan']['peak'] == 0.0


def test_wheel_rail_forces_are_compared_for_multibody_cars():
    """One car on the approach track, 5 steps: cholmod agrees with reference to 1e-9."""
    report = bn.bench(['track_approach'], ['cholmod'], 5e-4, isolate=False,
                      overrides=['train.start_position=-10'])
    ref, fast = report['runs']
    assert ref['status'] == fast['status'] == 'ok'
    assert ref['dofs']['vehicle'] == 42 and ref['dofs']['track'] > 0
    assert ref['difference']['wheel_rail_vertical']['rms'] == 0.0
    assert fast['difference']['wheel_rail_vertical']['rms_rel'] < 1e-9


def test_cli_table_and_json(tmp_path: Path, capsys):
    out = tmp_path / 'bench.json'
    code = main(['bench', *TINY, '--duration', '0.005', '--variants', 'reference',
                 '--in-process', '--json', str(out)])
    assert code == 0
    table = capsys.readouterr().out
    assert 'moving_force_beam' in table and 'reference' in table and 'ms/step' in table
    report = json.loads(out.read_text())
    assert report['runs'][0]['difference']['midspan']['rms'] == 0.0


def test_cli_unknown_variant_exit_2(capsys):
    assert main(['bench', *TINY, '--variants', 'reference,turbo']) == 2
    err = capsys.readouterr().err
    assert "solver.variant = 'turbo'" in err and "'reference'" in err and "'cholmod'" in err


def test_run_unknown_variant_exit_2(tmp_path: Path, capsys):
    out = tmp_path / 'o'
    assert main(['run', *TINY, '--out', str(out), '--set', 'solver.variant=turbo']) == 2
    err = capsys.readouterr().err
    assert "solver.variant = 'turbo'" in err and "'reference'" in err
    assert not out.exists()
