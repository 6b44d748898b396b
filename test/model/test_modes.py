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
Natural modes (``ttb-sim modes``) against closed forms.

A fixed-fixed chain of equal masses and springs (exact frequencies and, with
Rayleigh damping, exact modal damping ratios), both solver paths; a simply
supported span on rigid supports against the Euler-Bernoulli first bending
frequency; the command's table, JSON and refusals.
"""

import json
import math

import numpy as np
import pytest
import scipy.sparse as sp

from ttb_sim.cli import main
from ttb_sim.commands.modes import modes_report
from ttb_sim.config import load_scenario
from ttb_sim.model.bridge import span_frequency
from ttb_sim.model.modes import DENSE_LIMIT, natural_modes


def _chain(n, k=4.0e6, m=2.0):
    main_diagonal = np.full(n, 2 * k)
    stiffness = sp.diags([main_diagonal, np.full(n - 1, -k), np.full(n - 1, -k)], [0, 1, -1])
    mass = sp.identity(n) * m
    j = np.arange(1, n + 1)
    exact = 2 * np.sqrt(k / m) * np.sin(j * math.pi / (2 * (n + 1))) / (2 * math.pi)
    return mass.tocsr(), stiffness.tocsr(), exact


@pytest.mark.parametrize('n', [DENSE_LIMIT // 2, 3 * DENSE_LIMIT])
def test_chain_frequencies_and_rayleigh_damping_are_exact(n):
    mass, stiffness, exact = _chain(n)
    a0, a1 = 0.3, 2e-5
    around = float(exact[n // 3])
    found = natural_modes(mass, stiffness, a0 * mass + a1 * stiffness, around, 7)
    expected = exact[np.sort(np.argsort(np.abs(exact**2 - around**2))[:7])]
    assert np.allclose(found.frequencies, expected, rtol=1e-9)
    omega = 2 * math.pi * found.frequencies
    assert np.allclose(found.damping_ratios, a0 / (2 * omega) + a1 * omega / 2, rtol=1e-8)
    assert np.allclose(found.shapes.T @ (mass @ found.shapes), np.eye(7), atol=1e-9)


def test_simply_supported_span_first_bending_frequency():
    """One span on rigid supports: f1 = (pi / 2 L^2) sqrt(EI / m) within 0.1 %."""
    overrides = ['bridge.n_spans=1', 'bearings.model=rigid', 'foundation.model=rigid']
    b = load_scenario('ten_span_train', overrides).bridge
    f1 = span_frequency(b.span_length, b.bending_stiffness, b.mass_per_length)
    report = modes_report('ten_span_train', around=f1, count=1, overrides=overrides)
    assert report['modes'][0]['frequency_hz'] == pytest.approx(f1, rel=1e-3)
    assert report['modes'][0]['girders_uz'] == [pytest.approx(1.0)] or \
        report['modes'][0]['girders_uz'] == [pytest.approx(-1.0)]


def test_modes_command_table_and_json(tmp_path, capsys):
    out = tmp_path / 'modes.json'
    assert main(['modes', 'ten_span_train', '--count', '4', '--around', '5',
                 '--json', str(out)]) == 0
    table = capsys.readouterr().out
    report = json.loads(out.read_text())
    frequencies = [m['frequency_hz'] for m in report['modes']]
    assert len(frequencies) == 4 and frequencies == sorted(frequencies)
    assert all(len(m['girders_uz']) == 10 for m in report['modes'])
    assert all(max(abs(g) for g in m['girders_uz']) == pytest.approx(1.0)
               for m in report['modes'])
    assert f'{frequencies[0]:8.3f}' in table


@pytest.mark.parametrize('args, match', [
    (['--count', '0'], '--count = 0: allowed values are 1 to 200'),
    (['--around', '-1'], '--around = -1.0: allowed values are 0 to 10000 Hz'),
    (['--set', 'bridge.n_spans=0'], 'bridge.n_spans'),
])
def test_modes_command_refuses_bad_input(tmp_path, capsys, args, match):
    out = tmp_path / 'modes.json'
    assert main(['modes', 'ten_span_train', '--json', str(out), *args]) == 2
    assert match in capsys.readouterr().err
    assert not out.exists()


def test_modes_command_refuses_a_substructure_only_scenario(capsys):
    assert main(['modes', 'single_pile']) == 2
    assert "load.type = 'static'" in capsys.readouterr().err


def test_modes_command_refuses_a_json_path_in_a_missing_folder(tmp_path, capsys):
    assert main(['modes', 'ten_span_train', '--json', str(tmp_path / 'no' / 'm.json')]) == 2
    assert '--json' in capsys.readouterr().err


def test_piled_pier_takes_part_in_the_bridge_modes():
    """Four spans, pier 3 on a coarse pile group: its top moves with the girders it carries."""
    from ttb_sim.validation.cases.coupled import FAST
    coarse = [*FAST, 'soil.mesh.h=3.0', 'soil.mesh.h_max=6.0', 'soil.mesh.h_shaft=3.0']
    piled = modes_report('paper_ttbcpsi', around=3.0, count=6, overrides=coarse)
    springs = modes_report('paper_ttbcpsi', around=3.0, count=6,
                           overrides=[*coarse, 'foundation.model=springs',
                                      'foundation.piled_piers=[]'])
    assert all(list(m['piled_pier_tops_uz']) == ['3'] for m in piled['modes'])
    assert max(abs(m['piled_pier_tops_uz']['3']) for m in piled['modes']) > 0.05
    assert all(m['piled_pier_tops_uz'] == {} for m in springs['modes'])
    # the substructure's coordinates are DOFs of the monolithic structure
    assert piled['free_dofs'] > springs['free_dofs']
