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

"""`ttb-sim frf`: its arguments, its refusals, and its numbers through the whole pipeline."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ttb_sim.cli import main
from ttb_sim.commands.frf import parse_frequencies
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.foundation.frequency_response import substructure_response

#: A small single pile: an 8 m block at h = 0.6 m (about 7 000 DOFs, a second per solve).
SMALL = ['--set', 'soil.block.lx=8', '--set', 'soil.block.ly=8', '--set', 'soil.mesh.h=0.6',
         '--set', 'soil.mesh.h_max=1.5', '--set', 'load.type=harmonic']


@pytest.mark.parametrize('text, values', [
    ('5', [5.0]), ('1,2.5,10', [1.0, 2.5, 10.0]), ('1:3:1', [1.0, 2.0, 3.0]),
    ('0:1:0.5', [0.0, 0.5, 1.0]),
])
def test_frequencies_parse(text: str, values: list[float]) -> None:
    assert parse_frequencies(text) == pytest.approx(values)


@pytest.mark.parametrize('text, match', [
    ('abc', "'abc' is not a number"), ('1,,2', 'is not a number'), ('-1', 'outside'),
    ('nan', 'outside'), ('1:0:1', 'STOP >= START'), ('1:2:0', 'STEP > 0'),
    ('0:1000:1', '1001 frequencies'), ('a:b:c', 'START:STOP:STEP'),
])
def test_bad_frequencies_are_named(text: str, match: str) -> None:
    with pytest.raises(ScenarioError, match=match):
        parse_frequencies(text)


@pytest.mark.parametrize('args, match', [
    (['frf', 'moving_force_beam'], 'neither a pile-soil substructure run'),
    (['frf', 'single_pile', '--freqs', 'x'], "'x' is not a number"),
    (['frf', 'single_pile', '--pml', '-1'], '--pml = -1'),
    (['frf', 'single_pile', '--pml', '2', '--freqs', '0,1'], 'above 0 Hz'),
    (['frf', 'single_pile', '--solver', 'mumps'], 'auto, pardiso, superlu'),
    (['frf', 'single_pile', '--json', '/nonexistent/x.json'], 'existing folder'),
    (['frf', 'single_pile', '--set', 'soil.mesh.h=-1'], 'soil.mesh.h'),
])
def test_refusals_exit_2_with_one_line(args: list[str], match: str,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith('ttb-sim: error:') and match in err[0], err


def test_the_table_json_and_figure_hold_the_solver_numbers(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out, png = tmp_path / 'frf.json', tmp_path / 'frf.png'
    assert main(['frf', 'single_pile', '--freqs', '2,6', '--refine', '--solver', 'superlu',
                 '--json', str(out), '--plot', str(png), *SMALL]) == 0
    table = capsys.readouterr().out
    assert 'halved' in table and 'change' in table
    report = json.loads(out.read_text())
    assert [c['label'] for c in report['cases']] == ['scenario', 'halved']
    assert report['cases'][1]['dofs'] > 4 * report['cases'][0]['dofs']   # 2^3 in the near field
    head = np.array(report['cases'][0]['head']) @ np.array([1.0, 1j])
    # the same numbers as the library call on the same scenario (the JSON carries them whole)
    loaded = load_scenario('single_pile', [a for a in SMALL if a != '--set'])
    direct = substructure_response(loaded.substructure('pier01'), loaded.load, [2.0, 6.0],
                                   method='superlu')
    np.testing.assert_allclose(head, direct.heads[:, 0, 2], rtol=1e-12)
    halved = np.array(report['cases'][1]['head']) @ np.array([1.0, 1j])
    moved = np.abs(halved / head - 1)
    for f, m in zip((2.0, 6.0), moved):
        assert f'{100 * m:7.2f}%' in table
    assert png.stat().st_size > 10_000


#: live_coupled's piled pier on a coarse 24 m block (about 6 000 DOFs, a second in all).
COARSE_PIER = ['--set', 'soil.block.lx=24', '--set', 'soil.block.ly=18', '--set',
               'soil.mesh.h=3', '--set', 'soil.mesh.h_max=6']


@pytest.mark.parametrize('args, match', [
    (['frf', 'live_coupled', '--at', 'pier'], "--at = 'pier': allowed values are load, master"),
    (['frf', 'single_pile', '--at', 'master'], 'no pile cap'),
    (['frf', 'single_pile', '--no-reduced'], '--no-reduced: allowed only with --at master'),
])
def test_master_refusals_exit_2_with_one_line(args: list[str], match: str,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0], err


def test_at_master_sets_the_reduced_substructure_beside_the_unreduced_mesh(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The reduced block keeps the statics (1e-9) and the JSON holds what the table shows."""
    out, png = tmp_path / 'master.json', tmp_path / 'master.png'
    assert main(['frf', 'live_coupled', '--at', 'master', '--freqs', '0,2', '--json',
                 str(out), '--plot', str(png), *COARSE_PIER]) == 0
    table = capsys.readouterr().out
    assert 'reduced max' in table and "cap's master" in table
    report = json.loads(out.read_text())
    assert [c['label'] for c in report['cases']] == ['scenario', 'reduced']
    errors = report['cases'][1]['errors']
    assert max(v[0] for k, v in errors.items() if k.startswith('Z_')) <= 1e-9   # 0 Hz
    z = np.array(report['cases'][0]['impedance']) @ np.array([1.0, 1j])
    assert z.shape == (2, 6, 6) and np.abs(z[0].imag).max() == 0.0   # no damping at rest
    assert f'{abs(z[1, 2, 2]):12.4e}' in table
    assert png.stat().st_size > 10_000


def test_at_master_without_the_reduced_substructure(tmp_path: Path) -> None:
    """--no-reduced: the meshes alone (no reduction is built), the halved one the reference."""
    out = tmp_path / 'master.json'
    assert main(['frf', 'live_coupled', '--at', 'master', '--freqs', '0,2', '--refine',
                 '--no-reduced', '--json', str(out), *COARSE_PIER]) == 0
    report = json.loads(out.read_text())
    assert [c['label'] for c in report['cases']] == ['scenario', 'halved']
    assert report['reference'] == 'halved'
