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
The pier-top accelerometer and the pile strain gauge, through ``ttb-sim run`` and the bag.

The accelerometer reads the pier top's acceleration of the integrated state: noiseless, it
is the second difference of the pier-top displacement topic of the same run once both are
low-passed well inside the anti-alias filter's passband. The strain gauge reads the pile's
axial strain (tension positive): under a head force F it is F / (E A) at the head, less the
load the soil takes over the gauge's element, and it falls with depth.
"""

import json

import numpy as np
import pytest
from scipy import signal
from ttb_sim.cli import main
from ttb_sim.config import load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.io import read_bag
from ttb_sim.sim.substructure.standalone import SubstructureRun
from ttb_sim.sim.substructure.statics import static_solve

FRAME_RATE = 1000.0
LOW_PASS_HZ = 20.0
"""Both signals low-passed here: a quarter of the 80 Hz passband of a 200 Hz sensor, where the
second difference of frames 1 ms apart is within (2 pi 20 Hz 1 ms)^2 / 12 = 0.13 % of the
acceleration (and Newmark's own averaging of a over a step adds as little)."""
ACCELERATION_TOLERANCE = 0.02
"""Of the low-passed peak: the second difference's error in the band (0.4 % measured) with
margin for the filters' edges."""
PILE = ['soil.block.lx=12', 'soil.block.ly=12', 'soil.mesh.h=0.8', 'soil.mesh.growth=1.5',
        'soil.mesh.h_max=2.5', 'piles.side=0.8', 'piles.length=6', 'load.amplitude=-1000']
"""A 0.8 m square pile 6 m long in [P] Table 5 soil (coarse: 0.8 m bricks at the pile) under
1 kN downward on its head."""
HEAD_STRAIN = -1000.0 / (1e11 * 0.8**2)
"""F / (E A) (compression, negative)."""
STRAIN_TOLERANCE = 0.10
"""Relative: the first element (0.8 m) averages N / (E A) over its length; the soil takes
about 6 % of the head force over it in this soft top layer (measured from the strain of the
layers below: 0.94, 0.86, 0.69, 0.48, 0.30 of F / (E A) down the pile)."""


def second_difference(u: np.ndarray, rate: float) -> np.ndarray:
    """Return the central second difference of rows u (ends repeated)."""
    a = np.empty_like(u)
    a[1:-1] = (u[2:] - 2.0 * u[1:-1] + u[:-2]) * rate**2
    a[0], a[-1] = a[1], a[-2]
    return a


def test_pier_top_accelerometer_is_the_second_derivative_of_the_pier_top(tmp_path):
    out = tmp_path / 'bag'
    sensor = '{name: pa, type: accelerometer, at: pier05/top, axes: [x, y, z], rate_hz: 200}'
    assert main(['run', 'ten_span_train', '--out', str(out), '--duration', '1.0', '--set',
                 f'output.rate_hz={FRAME_RATE:g}', '--set', f'sensors=[{sensor}]']) == 0
    bag = read_bag(out)
    sensed = bag['/ttb_sim/sensors/pa'].fields['linear_acceleration']
    top = bag['/ttb_sim/piers/pier05/top'].fields['vector']
    info = next(s for s in json.loads((out / 'summary.json').read_text())['sensors']
                if s['name'] == 'pa')
    aa, q = info['anti_alias'], info['decimation']
    cheb = signal.cheby2(aa['order'], aa['attenuation_db'], aa['stopband_hz'], output='sos',
                         fs=FRAME_RATE)
    a = second_difference(top, FRAME_RATE)
    zi = signal.sosfilt_zi(cheb)[:, :, None] * a[0][None, None, :]
    expected = signal.sosfilt(cheb, a, axis=0, zi=zi)[0][::q][:len(sensed)]
    low = signal.butter(4, LOW_PASS_HZ, output='sos', fs=FRAME_RATE / q)
    trim = int(0.1 * FRAME_RATE / q)
    err = signal.sosfiltfilt(low, sensed - expected, axis=0)[trim:-trim, 2]
    peak = np.abs(signal.sosfiltfilt(low, sensed, axis=0)[:, 2]).max()
    assert peak > 0.05                                   # the train shakes the pier
    assert np.abs(err).max() <= ACCELERATION_TOLERANCE * peak
    assert np.all(sensed[:, :2] == 0.0)                  # a pier on springs moves vertically


def test_pile_strain_at_the_head_is_f_over_ea_and_falls_with_depth():
    depths = (0.0, 1.0, 3.0, 5.0, 6.0)
    sensors = ', '.join(f'{{name: g{i}, type: strain, at: "pier01/pile01/depth={d:g}"}}'
                        for i, d in enumerate(depths))
    run = SubstructureRun(load_scenario('single_pile', PILE + [
        'load.type=harmonic', 'load.frequency=2', f'sensors=[{sensors}]']))
    assert run.layout.pile_gauges == len(depths)
    static = SubstructureRun(load_scenario('single_pile', PILE))   # the same model, static
    u = static_solve(static.model, static.force, direct=True,
                     factorization=static.factorization).u
    strain = run.gauges @ u
    assert strain[0] == pytest.approx(HEAD_STRAIN, rel=STRAIN_TOLERANCE)
    assert np.all(np.diff(strain) > 0.0) and strain[-1] < 0.0   # the tip still bears


def test_pile_strain_gauge_in_a_bag(tmp_path):
    out = tmp_path / 'bag'
    gauges = ('[{name: head, type: strain, at: pier01/pile01, rate_hz: 500}, '
              '{name: deep, type: strain, at: "pier01/pile01/depth=3", rate_hz: 500}]')
    args = ['run', 'single_pile', '--out', str(out), '--set', 'load.type=harmonic', '--set',
            'load.frequency=2', '--set', 'solver.duration=0.5', '--set', f'sensors={gauges}']
    for item in PILE:
        args += ['--set', item]
    assert main(args) == 0
    bag = read_bag(out)
    head = bag['/ttb_sim/sensors/head'].fields['vector']
    deep = bag['/ttb_sim/sensors/deep'].fields['vector']
    # 2 Hz is quasi-static for the pile (axial modes above 100 Hz): the peak at t = 0.125 s
    assert np.abs(head[:, 0]).max() == pytest.approx(abs(HEAD_STRAIN), rel=STRAIN_TOLERANCE)
    assert head[:, 0].min() < 0.0 and np.abs(deep[:, 0]).max() < np.abs(head[:, 0]).max()
    assert np.all(head[:, 1:] == 0.0)


@pytest.mark.parametrize('name, sets, sensor, message', [
    ('ten_span_train', ['output.rate_hz=1000'], '{name: g, type: strain, at: pier05/pile01}',
     r'pier 5 has no piles; piled piers: \[\]'),
    ('live_coupled', ['output.rate_hz=1000'], '{name: g, type: strain, at: pier07/pile99}',
     r'pile 99 does not exist; the group has 15 \(1 to 15'),
    ('live_coupled', ['output.rate_hz=1000'], '{name: g, type: strain, at: pier03/pile01}',
     r'pier 3 has no piles; piled piers: \[7, 8\]'),
    ('single_pile', ['load.type=harmonic'],
     '{name: g, type: strain, at: "pier01/pile01/depth=13"}',
     r'depth 13 m is below the pile tip; allowed 0 to 12 m \(piles.length\)'),
    ('single_pile', ['load.type=harmonic'],
     '{name: g, type: strain, at: "pier01/pile01/depth=-1"}',
     r'depth .-1. is above the pile head'),
    ('single_pile', ['load.type=harmonic'],
     '{name: g, type: accelerometer, at: "pier01/pile01/depth=2"}',
     r'only a strain gauge may be at a depth'),
    ('single_pile', [], '{name: g, type: strain, at: pier01/pile01}',
     r"a static load \(load.type = 'static'\) gives one frame"),
    ('ten_span_train', ['output.rate_hz=1000'], '{name: a, type: inclinometer, at: pier05/top}',
     r'an? inclinometer cannot be at .pier05/top.'),
])
def test_pile_and_pier_sensors_are_refused_where_they_do_not_apply(name, sets, sensor,
                                                                   message):
    with pytest.raises(ScenarioError, match=message):
        load_scenario(name, sets + [f'sensors=[{sensor}]'])


def test_a_pier_top_accelerometer_without_piers_exits_2(tmp_path, capsys):
    out = tmp_path / 'bag'
    assert main(['run', 'moving_force_beam', '--out', str(out), '--set', 'output.rate_hz=1000',
                 '--set', 'sensors=[{name: a, type: accelerometer, at: pier02/top}]']) == 2
    assert 'pier 2 reports no top; piers with a top: []' in capsys.readouterr().err
    assert not out.exists()


def test_pier_top_accelerometers_in_the_pier_layout():
    s = load_scenario('live_coupled', ['sensor_layouts=[pier:7]', 'output.rate_hz=1000'])
    top = next(c for c in s.all_sensors if c.name == 'pier07_top_acc')
    assert top.at == 'pier07/top' and top.type == 'accelerometer' and top.measured_axes == 'xyz'


def test_pile_strain_gauges_on_a_reduced_piled_pier(tmp_path):
    """live_coupled: the gauges read interior pile DOFs recovered through the reduction basis."""
    out = tmp_path / 'bag'
    gauges = ('[{name: head, type: strain, at: pier07/pile08, rate_hz: 500}, '
              '{name: deep, type: strain, at: "pier07/pile08/depth=5", rate_hz: 500}]')
    assert main(['run', 'live_coupled', '--out', str(out), '--duration', '0.3', '--set',
                 'output.rate_hz=1000', '--set', f'sensors={gauges}']) == 0
    bag = read_bag(out)
    head = bag['/ttb_sim/sensors/head'].fields['vector'][:, 0]
    deep = bag['/ttb_sim/sensors/deep'].fields['vector'][:, 0]
    assert np.all(np.isfinite(head)) and 1e-9 < np.abs(head).max() < 1e-5
    assert np.sqrt(np.mean(deep**2)) < np.sqrt(np.mean(head**2))
