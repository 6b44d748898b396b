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


"""``ttb-sim dataset``: cases drawn from priors, one Parquet table, resumable, failures kept."""

import json
from pathlib import Path

from mcap_ros2.reader import read_ros2_messages
import numpy as np
import pytest
from ttb_sim.cli import main

pq = pytest.importorskip('pyarrow.parquet', reason="pip install 'ttb_sim[twin]'")

SPEC = """
scenario: moving_force_beam
n: 4
sampler: sobol
seed: 3
set: ['sensor_layouts=[span:1]']
duration: 0.4
features: {psd_fmin_hz: 1.0, psd_fmax_hz: 100.0, psd_points: 16, psd_segment_s: 0.2}
priors:
  train.speed_kmh: {uniform: [150, 300]}
  bridge.damping_ratio: {choice: [0.01, 0.02]}
"""


def write(tmp_path: Path, text: str, name: str = 'spec.yaml') -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def table(out: Path) -> dict[str, list]:
    return pq.read_table(out / 'dataset.parquet').to_pydict()


@pytest.fixture(scope='module')
def made(tmp_path_factory):
    tmp = tmp_path_factory.mktemp('dataset')
    out = tmp / 'ds'
    assert main(['dataset', str(write(tmp, SPEC)), '--out', str(out), '--workers', '2']) == 0
    return tmp, out


def test_one_row_per_case_a_column_per_prior_key_and_labels(made):
    _, out = made
    rows = table(out)
    assert rows['case'] == [f'case{i:05d}' for i in range(4)]
    assert rows['status'] == ['ok'] * 4
    speeds = rows['train.speed_kmh']
    assert all(150 <= v <= 300 for v in speeds) and len(set(speeds)) == 4
    assert set(rows['bridge.damping_ratio']) == {0.01, 0.02}
    assert rows['labels.train.speed_kmh'] == speeds   # the label is the drawn value
    assert rows['labels.scenario'] == ['moving_force_beam'] * 4
    grid = json.loads(pq.read_schema(out / 'dataset.parquet').metadata[b'ttb_sim'])[
        'psd_frequencies_hz']
    assert grid == json.loads((out / 'dataset.json').read_text())['psd_frequencies_hz']
    assert len(grid) == 16 and all(len(p) == 16 for p in rows['psd.span01_acc_mid.z'])
    assert all(v > 0 for v in rows['truth.girder_displacement_peak_m'])
    # the faster train gives the larger mid-span acceleration here: the rows are not copies
    assert len(set(rows['features.span01_acc_mid.z.rms'])) == 4


def test_features_agree_with_an_independent_reader_of_the_case_bag(made):
    _, out = made
    rows = table(out)
    bag = next((out / 'case00001' / 'bag').glob('*.mcap'))
    z = np.array([m.ros_msg.linear_acceleration.z for m in read_ros2_messages(
        str(bag), topics=['/ttb_sim/sensors/span01_acc_mid'])])
    assert rows['features.span01_acc_mid.z.peak'][1] == pytest.approx(np.max(np.abs(z)))
    assert rows['features.span01_acc_mid.z.rms'][1] == pytest.approx(np.std(z), rel=0.05)
    summary = json.loads((out / 'case00001' / 'summary.json').read_text())
    assert summary['labels']['train']['speed_kmh'] == rows['train.speed_kmh'][1]


def test_a_rerun_skips_finished_cases_and_redoes_a_half_written_one(made, capsys):
    tmp, out = made
    before = table(out)
    (out / 'case00002' / 'case.json').unlink()   # as if killed before it finished
    capsys.readouterr()
    assert main(['dataset', str(tmp / 'spec.yaml'), '--out', str(out), '--workers', '1']) == 0
    err = capsys.readouterr().err
    assert '3 of 4 cases already finished' in err and '[1/1] case00002 ok' in err
    after = table(out)
    for column in ('train.speed_kmh', 'features.span01_acc_mid.z.rms', 'psd.span01_acc_mid.z'):
        assert after[column] == before[column]   # the same case, bit for bit


def test_another_spec_for_the_same_folder_is_refused(made, capsys):
    tmp, out = made
    other = write(tmp, SPEC.replace('seed: 3', 'seed: 4'), 'other.yaml')
    assert main(['dataset', str(other), '--out', str(out)]) == 2
    assert 'seed' in capsys.readouterr().err


def test_a_failing_case_is_recorded_and_the_others_go_on(tmp_path, capsys):
    spec = SPEC.replace('n: 4', 'n: 2').replace(
        'bridge.damping_ratio: {choice: [0.01, 0.02]}',
        'solver.divergence_limit: {choice: [1.0e-9, 10.0]}') + 'keep_bags: false\n'
    out = tmp_path / 'ds'
    assert main(['dataset', str(write(tmp_path, spec)), '--out', str(out)]) == 1
    rows = table(out)
    status = dict(zip(rows['solver.divergence_limit'], rows['status']))
    assert status == {1.0e-9: 'diverged', 10.0: 'ok'}
    assert 'failed cases' in capsys.readouterr().err
    ok = rows['case'][rows['status'].index('ok')]
    assert not (out / ok / 'bag').exists() and (out / ok / 'summary.json').is_file()


@pytest.mark.parametrize('change, words', [
    (('n: 4', 'n: 0'), 'n = 0 is out of range'),
    (('sampler: sobol', 'sampler: halton'), "sampler = 'halton'"),
    (('{uniform: [150, 300]}', '{normal: [300, 500]}'), 'priors.train.speed_kmh'),
    (('train.speed_kmh:', 'train.speed:'), "unknown key 'train.speed'"),
    (('priors:', 'prior:'), "unknown key 'prior'"),
    (('duration: 0.4', 'duration: -1'), 'duration = -1'),
])
def test_a_bad_spec_exits_2_before_anything_runs(tmp_path, capsys, change, words):
    out = tmp_path / 'ds'
    spec = write(tmp_path, SPEC.replace(*change))
    assert main(['dataset', str(spec), '--out', str(out)]) == 2
    err = capsys.readouterr().err
    assert words in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
