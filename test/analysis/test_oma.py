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
Operational modal analysis (issue #31 item 4): identification, pairing, analyze, V27.

The synthetic records are free decays written here in closed form (two modes of known
frequency, damping and shape); the pipeline tests run ``ttb-sim run``, ``ttb-sim analyze``
and ``ttb-sim modes`` as a user does and compare the ``modes`` section of
``metrics.json`` with the table of ``ttb-sim modes``.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ttb_sim.analysis.oma import (IdentificationError, identify_modes, mac, ModelMode,
                                  pair_modes, unit_shapes)
from ttb_sim.cli import main
from ttb_sim.commands.analyze import analyze
from ttb_sim.errors import ScenarioError
from ttb_sim.validation.cases.modal import (DAMPING_TOLERANCE, FREQUENCY_TOLERANCE,
                                            v27_identification, V27_OVERRIDES, v27_rows)
from ttb_sim.validation.cases.registry import run_cases

RATE = 200.0
MODES = ((5.0, 0.02, np.array([0.7, 1.0, 0.7])), (21.0, 0.015, np.array([-1.0, 0.0, 1.0])))
"""(frequency Hz, damping ratio, shape at three channels) of the synthetic decay."""


def free_decay(seconds: float = 5.0, noise: float = 1e-3, seed: int = 1) -> np.ndarray:
    """Return a two-mode free decay at three channels plus white noise, (3, samples)."""
    t = np.arange(int(seconds * RATE)) / RATE
    y = np.zeros((3, t.size))
    for (f, zeta, shape), amplitude in zip(MODES, (1.0, 0.4)):
        w = 2 * math.pi * f
        wd = w * math.sqrt(1 - zeta**2)
        y += amplitude * shape[:, None] * (np.exp(-zeta * w * t) * np.sin(wd * t))[None, :]
    return y + noise * np.random.default_rng(seed).standard_normal(y.shape)


def test_two_modes_of_a_free_decay_are_found_with_their_damping_and_shapes():
    ident = identify_modes(free_decay(), RATE)
    assert len(ident.modes) == 2
    for mode, (f, zeta, shape) in zip(ident.modes, MODES):
        assert mode.frequency_hz == pytest.approx(f, rel=2e-3)
        assert mode.damping_ratio == pytest.approx(zeta, rel=0.05)
        assert mac(mode.shape, shape) > 0.99
        assert mode.poles >= 0.25 * len(ident.orders)
    assert any(p.stable for p in ident.poles) and any(not p.stable for p in ident.poles)


def test_too_few_channels_or_samples_say_so():
    with pytest.raises(IdentificationError, match='at least 2 channels'):
        identify_modes(free_decay()[:1], RATE)
    with pytest.raises(IdentificationError, match=r'too few for model orders up to 40: at '
                       r'least \d+ samples'):
        identify_modes(free_decay(seconds=0.5), RATE)
    bad = free_decay()
    bad[1, 10] = math.nan
    with pytest.raises(IdentificationError, match='non-finite'):
        identify_modes(bad, RATE)


def test_pairing_by_mac_then_frequency_and_unseen_model_modes():
    ident = identify_modes(free_decay(), RATE)
    model = unit_shapes([
        ModelMode(5.05, 0.02, 3e-3 * MODES[0][2]),
        ModelMode(14.0, 0.02, np.array([1e-16, -2e-16, 1e-16])),   # not seen by the channels
        ModelMode(20.0, 0.02, 3e-3 * MODES[1][2]),
        ModelMode(22.0, 0.02, 3e-3 * MODES[0][2])])   # near in frequency, wrong shape
    assert not np.any(model[1].shape)
    pairs = pair_modes(ident.modes, model)
    assert [p.model for p in pairs] == [0, 2]
    assert pairs[0].frequency_difference == pytest.approx(ident.modes[0].frequency_hz / 5.05 - 1)
    assert pairs[1].mac > 0.99
    aliased = pair_modes(ident.modes[:1], [ModelMode(10.0, 0.02, MODES[0][2])])
    assert aliased[0].model is None   # the same shape at twice the frequency: not a pair
    shapeless = pair_modes(ident.modes, [ModelMode(21.5, 0.0), ModelMode(9.0, 0.01)])
    assert [p.model for p in shapeless] == [None, 0]
    assert shapeless[1].damping_difference is None and shapeless[1].mac is None


def test_v27_passes_and_a_wrong_model_frequency_is_a_miss():
    rows = run_cases(['V27'])
    assert all(r.passed for r in rows), [r for r in rows if not r.passed]
    judged = [r for r in rows if r.error_kind == 'relative']
    assert len(judged) == 4   # frequency and damping of the two bending modes
    for r in judged:
        tolerance = FREQUENCY_TOLERANCE if r.quantity.startswith('f,') else DAMPING_TOLERANCE
        assert r.tolerance == tolerance and r.error < tolerance
    wrong = v27_rows(v27_identification(), model_scale=1.02)
    assert [r.passed for r in wrong if r.quantity.startswith('f,')] == [False, False]
    assert all(r.passed for r in wrong if r.quantity.startswith(('zeta', 'MAC')))


@pytest.fixture(scope='module')
def analysed(tmp_path_factory):
    """Run the V27 passage with ttb-sim run, analyse it and list ttb-sim modes."""
    folder = tmp_path_factory.mktemp('oma')
    sets = [a for o in V27_OVERRIDES for a in ('--set', o)]
    assert main(['run', 'moving_force_beam', '--out', str(folder / 'bag'), *sets]) == 0
    assert main(['analyze', str(folder / 'bag')]) == 0
    assert main(['modes', 'moving_force_beam', '--around', '0', '--count', '8',
                 '--json', str(folder / 'modes.json'), *sets]) == 0
    metrics = json.loads((folder / 'bag' / 'analysis' / 'metrics.json').read_text())
    return folder, metrics, json.loads((folder / 'modes.json').read_text())


def test_analyze_sets_the_identified_modes_beside_ttb_sim_modes(analysed):
    folder, metrics, table = analysed
    section = metrics['modes']
    assert section['status'] == 'identified' and section['window']['kind'] == 'free'
    assert section['window']['start_s'] == pytest.approx(32.0 / (200 / 3.6) + 0.1, abs=0.01)
    assert len(section['channels']) == 4
    listed = [m['frequency_hz'] for m in table['modes']]
    paired = [m for m in section['identified'] if m['model_mode'] is not None]
    assert len(paired) >= 2
    for m in paired:
        model_f = m['model_frequency_hz']
        k = int(np.argmin(np.abs(np.array(listed) - model_f)))
        assert model_f == pytest.approx(listed[k], rel=1e-9)   # the same model as ttb-sim modes
        assert m['model_damping_ratio'] == pytest.approx(table['modes'][k]['damping_ratio'])
        assert abs(m['frequency_hz'] / model_f - 1) < FREQUENCY_TOLERANCE
        assert abs(m['damping_ratio'] / m['model_damping_ratio'] - 1) < DAMPING_TOLERANCE
        assert m['frequency_difference_percent'] == pytest.approx(
            100 * (m['frequency_hz'] / model_f - 1))
        assert m['mac'] > 0.9
    assert {round(m['model_frequency_hz'], 2) for m in paired} >= {5.57, 22.29}
    page = (folder / 'bag' / 'analysis' / 'index.html').read_text()
    assert 'src="modes.png"' in page and 'Modes: identified from the sensors' in page
    assert (folder / 'bag' / 'analysis' / 'modes.png').stat().st_size > 10_000
    assert 'modes.png' in metrics['figures']


def test_whole_window_and_the_skips_need_no_traceback(analysed, tmp_path, capsys):
    folder, _, _ = analysed
    out = tmp_path / 'whole'
    assert main(['analyze', str(folder / 'bag'), '--out', str(out), '--modes-window',
                 'whole']) == 0
    whole = json.loads((out / 'metrics.json').read_text())['modes']
    assert whole['status'] == 'identified' and whole['window']['start_s'] < 0.01
    assert main(['run', 'moving_force_beam', '--out', str(tmp_path / 'plain')]) == 0
    capsys.readouterr()
    assert main(['analyze', str(tmp_path / 'plain')]) == 0
    err = capsys.readouterr().err
    plain = json.loads((tmp_path / 'plain' / 'analysis' / 'metrics.json').read_text())['modes']
    assert plain['status'] == 'skipped' and '0 accelerometer channel(s)' in plain['reason']
    assert 'ttb-sim: modes skipped: the bag has 0 accelerometer channel(s)' in err
    assert 'Traceback' not in err
    short = [a for o in V27_OVERRIDES[:1] + V27_OVERRIDES[2:] for a in ('--set', o)]
    assert main(['run', 'moving_force_beam', '--out', str(tmp_path / 'short'), *short,
                 '--set', 'solver.free_vibration_periods=2']) == 0
    capsys.readouterr()
    assert main(['analyze', str(tmp_path / 'short')]) == 0
    reason = json.loads((tmp_path / 'short' / 'analysis' / 'metrics.json').read_text()
                        )['modes']['reason']
    assert reason.startswith('free window t = ') and 'samples' in reason
    assert 'Traceback' not in capsys.readouterr().err
    with pytest.raises(SystemExit) as refused:
        main(['analyze', str(folder / 'bag'), '--out', str(tmp_path / 'x'), '--modes-window',
              'ambient'])
    assert refused.value.code == 2
    with pytest.raises(ScenarioError, match="--modes-window 'ambient': allowed values are free"):
        analyze(folder / 'bag', out=tmp_path / 'x', modes_window='ambient')
