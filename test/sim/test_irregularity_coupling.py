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
Track irregularity under quarter cars.

Reference: a quarter car running over a sinusoidal profile z = A sin(2 pi x / L)
reaches the steady state of base excitation at omega = 2 pi V / L, with sprung
acceleration amplitude omega^2 A sqrt((k^2 + (c omega)^2) / ((k - m omega^2)^2 +
(c omega)^2)) (closed form); tolerance 1 %.
"""

import math
from pathlib import Path

import numpy as np
import pytest
from ttb_sim.config import key_spec, load_scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity import available_spectra
from ttb_sim.sim.simulation import Simulation


def test_schema_lists_the_library_spectra():
    _, _, spec = key_spec('irregularity.spectrum')
    assert set(spec.choices) == {'none', *available_spectra()}


def test_sinusoidal_profile_transmissibility(tmp_path: Path):
    amp, wavelength, speed = 2e-3, 10.0, 10.0
    m, fn, zeta = 1000.0, 1.5, 0.2
    k = m * (2 * math.pi * fn) ** 2
    c = 2 * zeta * math.sqrt(k * m)
    x = np.arange(-400.0, 0.0 + 1e-9, 0.05)
    z = amp * np.sin(2 * math.pi * x / wavelength)
    csv = tmp_path / 'sine.csv'
    rows = '\n'.join(f'{a:.17g},{b:.17g},{b:.17g},0.0,0.0' for a, b in zip(x, z))
    csv.write_text('x,z_left,z_right,y_left,y_right\n' + rows + '\n')
    s = load_scenario('sprung_mass_beam', [
        f'irregularity.file={csv}', 'train.start_position=-300', f'train.sprung_mass={m}',
        f'train.suspension_stiffness={k}', f'train.suspension_damping={c}',
        f'train.speed_kmh={speed * 3.6}', 'solver.duration=20', 'solver.dt=0.002'])
    frames = list(Simulation(s).frames())
    t = np.array([f.time for f in frames])
    acc = np.array([f.body_acceleration[0, 2] for f in frames])
    w = 2 * math.pi * speed / wavelength
    damping = (c * w) ** 2
    expected = w**2 * amp * math.sqrt((k**2 + damping) / ((k - m * w**2) ** 2 + damping))
    steady = acc[t > 12.0]
    assert np.abs(steady).max() == pytest.approx(expected, rel=0.01)
    # Off the bridge the girder is untouched.
    assert np.all([f.midspan[0, 2] == 0.0 for f in frames])


def test_scale_zero_is_the_smooth_track():
    base = ['solver.duration=0.3']
    smooth = list(Simulation(load_scenario('sprung_mass_beam', base)).frames())
    zero = list(Simulation(load_scenario('sprung_mass_beam', base + [
        'irregularity.spectrum=paper', 'irregularity.scale=0'])).frames())
    assert all(np.array_equal(a.midspan, b.midspan) for a, b in zip(smooth, zero))


def test_same_seed_same_run_other_seed_other_run():
    def run(seed: int) -> np.ndarray:
        s = load_scenario('sprung_mass_beam', ['solver.duration=0.3', 'solver.dt=0.001',
                                               'irregularity.spectrum=chinese_hsr',
                                               f'irregularity.seed={seed}'])
        return np.array([f.body_acceleration[0, 2] for f in Simulation(s).frames()])
    a, b, c = run(3), run(3), run(4)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    assert np.abs(a).max() > 0


def test_bad_profile_file_is_a_scenario_error(tmp_path: Path):
    bad = tmp_path / 'bad.csv'
    bad.write_text('x,z_left,z_right,y_left,y_right\n0,0,0,0,0\n1,nan,0,0,0\n'
                   + ''.join(f'{i},0,0,0,0\n' for i in range(2, 8)))
    s = load_scenario('sprung_mass_beam', [f'irregularity.file={bad}'])
    with pytest.raises(ScenarioError, match='row 3'):
        Simulation(s)
