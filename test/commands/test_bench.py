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

import numpy as np
import pytest
from ttb_sim.cli import main
from ttb_sim.commands import bench as bn

TINY = ['moving_force_beam']
"""One span, one moving force: builds and steps in milliseconds."""


def _check_run(run: dict) -> None:
    for key in ('scenario', 'variant', 'factorization', 'status', 'dofs', 'dt', 'steps',
                'frames', 'simulated_time', 'build_time', 'start_time', 'step_time',
                'ms_per_step', 'cpu_ms_per_step', 'real_time_factor', 'peak_rss_mib',
                'compile_time', 'compile_timed', 'warmup_steps', 'timed_steps',
                'pending_at_timing', 'threads', 'threads_requested', 'difference'):
        assert key in run, key
    assert set(run['dofs']) == {'structure', 'track', 'bridge', 'vehicle', 'substructures',
                                'substructures_full', 'total', 'solved'}
    assert run['dofs']['solved'] <= run['dofs']['total']
    assert set(run['difference']) == set(bn.COMPARED)
    assert run['warmup_steps'] + run['timed_steps'] == run['steps']
    assert run['warmup_steps'] > 0
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
    # the dynamic part of Fz over two frames is small: its round-off is relatively larger
    for name, within in (('wheel_rail_vertical', 1e-9), ('wheel_rail_vertical_dynamic', 1e-5),
                         ('bearings', 1e-9), ('body_vertical_acceleration', 1e-9)):
        assert ref['difference'][name]['rms'] == 0.0, name
        assert fast['difference'][name]['rms_rel'] < within, name


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


PILE = ['soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
        'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6', 'load.frequency=4',
        'output.rate_hz=200', 'output.soil_points=[[2.0, 0.0, 0.0]]']
"""The built-in single_pile workload (harmonic) on a coarse mesh: 6 120 DOFs, 1 573 bricks."""
SUBSTRUCTURE_DOFS = {'soil', 'piles', 'cap', 'interface', 'boundary', 'total', 'solved'}


def _pile_model():
    from ttb_sim.config import load_scenario
    from ttb_sim.model.foundation.substructure import build

    scenario = load_scenario('single_pile', PILE)
    return scenario, build(scenario.substructure('pier01'))


def test_substructure_workload_rows_dof_counts_and_difference():
    report = bn.bench(['single_pile'], ['qdldl'], 0.5, isolate=False, overrides=PILE)
    ref, fast = report['runs']
    scenario, model = _pile_model()
    assert [ref['variant'], fast['variant']] == ['reference', 'qdldl']
    assert [ref['scheme'], fast['scheme']] == ['implicit', 'mixed']
    for run in (ref, fast):
        assert run['status'] == 'ok' and run['model'] == 'pile_soil'
        assert run['load'] == 'harmonic'  # the workload's own override
        assert set(run['dofs']) == SUBSTRUCTURE_DOFS
        assert run['dt'] == pytest.approx(5e-3) and run['steps'] == 100
        # counts from the mesh, independently of the model's matrices
        nodes = model.mesh.nodes
        assert run['dofs']['total'] == 3 * len(nodes)
        half = 0.5 * scenario.soil.block.lx
        outer = ((np.abs(np.abs(nodes[:, 0]) - half) < 1e-9)
                 | (np.abs(np.abs(nodes[:, 1]) - half) < 1e-9)
                 | (np.abs(nodes[:, 2] + scenario.soil.depth) < 1e-9))
        assert run['dofs']['boundary'] == 3 * int(outer.sum())
        pile_cells = int(model.summary['pile_cells'])  # one brick across the 0.8 m pile
        assert run['dofs']['piles'] == 3 * 4 * (pile_cells + 1)
        assert run['dofs']['cap'] == 0 and run['dofs']['interface'] > run['dofs']['piles']
        assert run['bricks'] == len(model.mesh.cells)
        assert run['cpu_us_per_brick_step'] == pytest.approx(
            1e3 * run['cpu_ms_per_step'] / run['bricks'], rel=1e-9)
        for name in ('wheel_rail_vertical', 'wheel_rail_lateral', 'midspan'):
            assert run['difference'][name]['rms'] is None
    assert ref['dofs']['solved'] == ref['dofs']['total']
    assert 0 < fast['dofs']['solved'] < fast['dofs']['total']
    assert ref['difference']['pile_heads']['rms'] == 0.0
    # implicit against mixed soil at 4 Hz, dt = 5 ms over two load periods: a
    # time-discretisation difference, at most zeta omega dt + (omega dt)^2 / 4 = 1 %
    # (test/sim/test_substructure_variants.py)
    assert 0 < fast['difference']['pile_heads']['rms_rel'] < 0.01
    table = bn.format_table(report)
    assert 'µs/brick' in table and table.count('single_pile') == 4   # times, differences
    json.dumps(report)


def test_a_refused_reference_leaves_the_other_variants_running(monkeypatch):
    from ttb_sim.sim.substructure import standalone as substructure_run

    monkeypatch.setattr(substructure_run, 'IMPLICIT_MAX_DOFS', 1000)
    report = bn.bench(['single_pile'], ['qdldl'], 0.01, isolate=False, overrides=PILE)
    ref, fast = report['runs']
    assert ref['status'] == 'refused' and ref['variant'] == 'reference'
    assert ref['message'].startswith("solver.variant = 'reference': ")
    assert fast['status'] == 'ok' and fast['difference']['pile_heads']['rms'] is None
    table = bn.format_table(report)
    assert 'refused: solver.variant' in table
    json.dumps(report)


def test_isolated_substructure_runs_return_the_pile_heads():
    report = bn.bench(['single_pile'], ['cholmod'], 0.01, overrides=PILE)
    ref, fast = report['runs']
    assert ref['difference']['pile_heads']['rms'] == 0.0
    assert fast['difference']['pile_heads']['rms_rel'] is not None
    assert fast['peak_rss_mib'] > 0 and fast['factorization'] == 'cholmod'


def test_cli_bad_scenario_exit_2_before_any_run(capsys):
    assert main(['bench', 'single_pile', 'no_such_scenario', '--in-process']) == 2
    err = capsys.readouterr().err
    assert 'no_such_scenario' in err and 'bench: single_pile' not in err
    assert err.strip().count('\n') == 0


def test_the_timed_section_starts_after_numba_compiled_the_kernels(tmp_path: Path, monkeypatch):
    """
    With numba's disk cache empty, compiling is reported apart and not timed as stepping.

    Each run is its own process with the cache pointed at an empty folder: its kernels
    compile on first use. The timed section must start with nothing pending and
    without entering the compiler again; the compile time is in its own field. No
    assertion on how long anything took.
    """
    from ttb_sim.fe.compiled import available

    if not available():
        pytest.skip('numba is not installed: nothing compiles')
    monkeypatch.setenv('NUMBA_CACHE_DIR', str(tmp_path / 'numba-cache'))
    report = bn.bench(['track_approach'], ['qdldl'], 0.004,
                      overrides=['train.start_position=-10'])
    ref, fast = report['runs']
    for run in (ref, fast):
        _check_run(run)
        assert run['status'] == 'ok'
        assert run['compile_timed'] == 0.0, run['variant']   # no compiler entry while timed
        assert run['timed_steps'] > 0 and run['ms_per_step'] is not None
    # every kernel made was compiled before the timing; the reference, which solves the
    # track in full, does not make the single-solve rail predictor at all
    assert fast['pending_at_timing'] == []
    assert ref['pending_at_timing'] == []
    assert fast['compile_time'] > 0.0   # the compiled contact step, compiled on first use
    assert any(p.name.endswith('.nbi') for p in (tmp_path / 'numba-cache').rglob('*'))
    table = bn.format_table(report)
    assert 'compile s' in table.splitlines()[0]


def test_threads_rows_one_per_variant_and_count():
    report = bn.bench(TINY, ['cholmod'], 0.005, isolate=False, threads=[1, 2])
    runs = report['runs']
    assert [(r['variant'], r['threads_requested'], r['threads']) for r in runs] == [
        ('reference', 1, 1), ('cholmod', 1, 1), ('reference', 2, 2), ('cholmod', 2, 2)]
    for run in runs:
        _check_run(run)
        assert run['threads_choice'].endswith('(solver.threads)')
    assert runs[2]['difference']['midspan']['rms'] == 0.0   # each count's own reference
    table = bn.format_table(report)
    rows = [line.split() for line in table.splitlines() if line.startswith('moving_force')]
    assert [row[2] for row in rows] == ['1', '1', '2', '2'] * 2   # both tables
    json.dumps(report)


def test_default_threads_is_the_auto_choice_once():
    (run,) = bn.bench(TINY, ['reference'], 0.002, isolate=False)['runs']
    assert run['threads_requested'] is None and 'auto' in run['threads_choice']
    assert bn.format_table({'runs': [run]}).splitlines()[2].split()[2].endswith('*')


@pytest.mark.parametrize('value, shown', [('1,x', "'1,x'"), (',', "','"), ('99', '99'),
                                          ('-1', '-1')])
def test_cli_bad_threads_exit_2(capsys, value, shown):
    assert main(['bench', *TINY, '--threads', value, '--in-process']) == 2
    err = capsys.readouterr().err
    assert err.startswith('ttb-sim: error: --threads') and shown in err
    assert 'bench: ' not in err and err.count('\n') == 1


def test_difference_of_the_dynamic_part_ignores_a_constant_offset():
    """Fz dyn: each signal less its own time mean, then the one RMS difference."""
    t = np.linspace(0.0, 1.0, 50)[:, None]
    ref = {'wheel_rail_vertical': np.hstack([1e5 + 1e3 * np.sin(9 * t), 8e4 + 0 * t])}
    shifted = {'wheel_rail_vertical': ref['wheel_rail_vertical'] + [500.0, -200.0]}
    d = bn.compare(shifted, ref)
    assert set(d) == set(bn.COMPARED)
    assert d['wheel_rail_vertical']['rms'] > 300.0
    assert d['wheel_rail_vertical_dynamic']['rms'] < 1e-9
    scaled = {'wheel_rail_vertical': np.hstack([1e5 + 1.1e3 * np.sin(9 * t), 8e4 + 0 * t])}
    dyn = bn.compare(scaled, ref)['wheel_rail_vertical_dynamic']
    assert dyn['rms_rel'] == pytest.approx(0.1, rel=1e-9)   # the constant wheel: no dynamics
    assert d['bearings']['rms'] is None   # no trace: nothing to compare
