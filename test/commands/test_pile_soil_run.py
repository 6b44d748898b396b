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
Pile-soil scenarios through ``ttb-sim run``: keys, refusals, frames and topics in the bag.

A coarse single pile (h = 0.8 m in a 12 x 12 m block, about 5 000 DOFs) keeps
every run to a few seconds. Checked: the contract keys (``soil.layers`` set
whole with defaults for c, phi and damping_ratio); each bad input the issue
lists refused with exit 2, one line naming the key, and nothing written; a
static load gives one frame at t = 0 whose head displacement equals the model's
static solution; a harmonic load gives frames at ``output.rate_hz`` whose head
response oscillates at the load frequency and, with a bonded interface (a linear
model), scales with the load amplitude to round-off; the bag holds the pile and
soil topics with the contract types, read back by rosbags and by the independent
mcap reader.
"""

import json
from pathlib import Path

import numpy as np
import pytest
from ttb_sim.cli import main
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io.reader import read_bag, TopicArrays
from ttb_sim.validation.cases.pile_soil import head_stiffness

COARSE = ['soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
          'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6',
          'output.soil_points=[[2.0, 0.0, 0.0]]']


def _sets(*extra: str) -> list[str]:
    out: list[str] = []
    for item in (*COARSE, *extra):
        out += ['--set', item]
    return out


def test_layers_set_whole_take_the_defaults_of_c_phi_and_damping() -> None:
    s = load_scenario('single_pile', ['soil.layers=[{thickness: 22, E: 5.0e7, nu: 0.3, '
                                      'rho: 1900}]'])
    (layer,) = s.soil.layers
    assert (layer.thickness, layer.E, layer.nu, layer.rho) == (22.0, 5.0e7, 0.3, 1900.0)
    assert (layer.c, layer.phi, layer.damping_ratio) == (10e3, 30.0, 0.05)
    assert s.substructure_only and s.soil.depth == 22.0


def test_the_builtins_are_the_contract_cases() -> None:
    harmonic = load_scenario('pile_harmonic')
    assert (harmonic.piles.rows, harmonic.piles.cols, harmonic.piles.spacing) == (3, 5, 3.0)
    assert (harmonic.load.type, harmonic.load.amplitude, harmonic.load.frequency,
            harmonic.load.pile, harmonic.load.direction) == ('harmonic', 10e3, 20.0, 5, 'z')
    assert not harmonic.cap.enabled
    centres = harmonic.piles.centres()
    between = tuple(0.5 * (a + b) for a, b in zip(centres[3], centres[4]))
    assert harmonic.output.soil_points[-1][:2] == pytest.approx(between)
    single = load_scenario('single_pile')
    assert single.piles.count == 1 and not single.cap.enabled


@pytest.mark.parametrize('sets, key', [
    (['load.type=harmonic', 'load.frequency=20'], 'soil.mesh.h'),
    (['soil.block.lx=3'], 'soil.block.lx'),
    (['piles.rows=2', 'piles.spacing=0.5'], 'piles.spacing = 0.5'),
    (['piles.length=30'], 'piles.length = 30'),
    (['soil.layers=[{thickness: 0, E: 5.0e6, nu: 0.3, rho: 1900}]'],
     'soil.layers[0].thickness = 0'),
    (['soil.layers=[{thickness: 10, E: 5.0e6, nu: 0.5, rho: 1900}]'], 'soil.layers[0].nu = 0.5'),
    (['piles.nu=0.5'], 'piles.nu = 0.5'),
    (['load.pile=2'], 'load.pile = 2'),
    (['soil.mesh.h=0.02', 'soil.mesh.h_max=0.02'], 'soil.mesh.h = 0.02'),
    (['output.soil_points=[[50, 0, 0]]'], 'output.soil_points[0]'),
    (['soil.boundary=rigid'], 'soil.boundary'),
    (['load.direction=w'], 'load.direction'),
])
def test_bad_substructures_are_refused_before_anything_runs(
        sets: list[str], key: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / 'bag'
    assert main(['run', 'single_pile', '--out', str(out), *_sets(*sets)]) == 2
    err = capsys.readouterr().err
    assert err.startswith('ttb-sim: error: ') and err.count('\n') == 1, err
    assert key in err, err
    assert not out.exists()


def test_a_static_load_gives_one_frame_with_the_static_solution(tmp_path: Path) -> None:
    out = tmp_path / 'static'
    assert main(['run', 'single_pile', '--out', str(out), *_sets('load.amplitude=2000')]) == 0
    bag = read_bag(out)
    disp = bag['/ttb_sim/piles/pier01/pile01/displacement']
    assert len(disp) == 1 and disp.stamp_ns[0] == 0
    scenario = load_scenario('single_pile', COARSE + ['load.amplitude=2000'])
    stiffness = head_stiffness(scenario.substructure(), 2000.0)
    assert disp.component('vector', 'z')[0] == pytest.approx(2000.0 / stiffness, rel=1e-6)
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['solver']['pile_soil']['free_dofs'] == summary['solver']['free_dofs']
    assert 'train' not in summary['scenario'] and 'load' in summary['scenario']
    assert '/ttb_sim/train/odometry' not in summary['bag']['topics']


def _harmonic(tmp_path: Path, name: str, amplitude: float) -> dict[str, TopicArrays]:
    out = tmp_path / name
    assert main(['run', 'single_pile', '--out', str(out), '--duration', '1.0',
                 *_sets('load.type=harmonic', 'load.frequency=4', f'load.amplitude={amplitude}',
                        'interface.model=bonded', 'output.rate_hz=200')]) == 0
    return read_bag(out)


def test_a_harmonic_load_oscillates_at_its_frequency_and_scales_linearly(
        tmp_path: Path) -> None:
    one = _harmonic(tmp_path, 'one', 1000.0)
    two = _harmonic(tmp_path, 'two', 2000.0)
    head = one['/ttb_sim/piles/pier01/pile01/displacement']
    t = head.stamp
    assert len(t) == 201 and t[1] - t[0] == pytest.approx(5e-3, rel=1e-9)
    z = head.component('vector', 'z')
    assert z[0] == 0.0
    late = t >= 0.5
    spectrum = np.abs(np.fft.rfft(z[late] - z[late].mean(), 8 * late.sum()))
    freqs = np.fft.rfftfreq(8 * late.sum(), t[1] - t[0])
    assert freqs[np.argmax(spectrum)] == pytest.approx(4.0, abs=0.3)
    z2 = two['/ttb_sim/piles/pier01/pile01/displacement'].component('vector', 'z')
    np.testing.assert_allclose(z2, 2.0 * z, rtol=1e-9, atol=1e-15 * np.abs(z).max())
    imu = one['/ttb_sim/piles/pier01/pile01/imu']
    assert np.all(np.isfinite(imu['linear_acceleration']))
    # the cloud's velocity is the rate of its displacement: the central difference of uz
    # at 5 ms frames of a 4 Hz response is within (w dt)^2 / 6 = 0.3 % of it
    points = one['/ttb_sim/soil/points']['points'].astype(float)
    uz, vz = points[late, -1, 5], points[late, -1, 11]
    rate = (uz[2:] - uz[:-2]) / (2 * (t[1] - t[0]))
    assert np.sqrt(np.mean((rate - vz[1:-1]) ** 2)) < 0.01 * np.sqrt(np.mean(vz ** 2))


def test_soil_points_are_in_the_cloud_with_their_positions(tmp_path: Path) -> None:
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    out = tmp_path / 'cloud'
    assert main(['run', 'single_pile', '--out', str(out), *_sets()]) == 0
    with open(next(out.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        clouds = [msg for _, channel, _, msg in reader.iter_decoded_messages()
                  if channel.topic == '/ttb_sim/soil/points']
    (cloud,) = clouds
    names = [f.name for f in cloud.fields]
    assert names == ['x', 'y', 'z', 'ux', 'uy', 'uz', 'ax', 'ay', 'az', 'vx', 'vy', 'vz']
    points = np.frombuffer(bytes(cloud.data), dtype='<f4').reshape(cloud.width, 12)
    assert tuple(points[-1, :3]) == (2.0, 0.0, 0.0)  # the user point, last
    assert np.all(np.isfinite(points)) and cloud.width > 1  # observation line too


def test_the_scenario_layer_refuses_a_load_on_no_pile() -> None:
    with pytest.raises(ScenarioError, match=r'load\.pile = 16; allowed: 1 \.\. 15'):
        load_scenario('pile_harmonic', ['load.pile=16'])


def test_a_displacement_over_the_limit_stops_the_run_with_a_readable_bag(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / 'diverged'
    args = _sets('load.type=harmonic', 'load.frequency=4', 'solver.divergence_limit=1e-7')
    assert main(['run', 'single_pile', '--out', str(out), '--duration', '1', *args]) == 1
    assert 'solver.divergence_limit' in capsys.readouterr().err
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['status'] == 'diverged' and 0 < summary['frames'] < 201
    bag = read_bag(out)
    head = bag['/ttb_sim/piles/pier01/pile01/displacement'].component('vector', 'z')
    assert len(head) == summary['frames'] and np.abs(head).max() <= 1e-7
