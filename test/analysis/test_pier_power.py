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
Pier tops in the frames and the power flow into the piers through their bearings.

The pier top of a pier on foundation springs carries, at quasi-static loading, the
bearing force over the series stiffness of the column (EA/h) and the spring; the
power a spring-dashpot pier takes from a harmonic bearing force is c w^2 A^2 / 2
(the spring stores and returns, the dashpot takes): both through the pipeline
the analysis runs.
"""

from pathlib import Path

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.io.streams import Series, Streams
from ttb_sim.io.topics import topic_table
from ttb_sim.report.metrics import pier_power_flows
from ttb_sim.sim import Simulation


def test_a_pier_top_settles_as_its_bearing_force_over_column_and_spring_in_series():
    """ten_span_train's forces at 36 km/h (quasi-static): F / u within 1 % of 1/(h/EA + 1/k_f)."""
    scenario = load_scenario('ten_span_train',
                             values=[('train.speed_kmh', 36.0), ('solver.duration', 3.3)])
    sim = Simulation(scenario)
    assert sim.layout.piers == tuple(range(2, 11))   # the nine piers; abutments have none
    names = [t.name for t in topic_table(sim.layout)]
    assert 'piers/pier02/top' in names and 'piers/pier01/top' not in names
    frame = list(sim.frames())[-1]
    pr, fd = scenario.piers, scenario.foundation
    k_series = 1.0 / (pr.height / pr.axial_stiffness + 1.0 / fd.vertical_stiffness)
    pier = 1   # pier02: the first axles have crossed span01 onto it
    force = frame.bearings[pier, :, 2].sum()
    assert force < -1e5
    assert frame.pier_tops[0, 2] == pytest.approx(force / k_series, rel=0.01)


def _series(t: np.ndarray, values: np.ndarray) -> Series:
    return Series(t, values)


def test_the_power_into_a_spring_dashpot_pier_is_what_its_dashpot_takes():
    """A harmonic pier top under F = k u + c u' (two bearings) takes c w^2 A^2 / 2 on average."""
    rate, f0, amp, k, c = 500.0, 4.0, 1e-4, 5e9, 2e6
    t = np.arange(0, 5.0, 1 / rate)
    w = 2 * np.pi * f0
    u = amp * np.sin(w * t)
    force = k * u + c * amp * w * np.cos(w * t)
    zeros = np.zeros_like(t)
    top = np.column_stack([zeros, zeros, u])
    half = np.column_stack([zeros, zeros, 0.5 * force])
    s = Streams(Path('x'), 'x', pier_top={7: _series(t, top)},
                bearing={(7, 'left'): _series(t, half), (7, 'right'): _series(t, half)})
    (pier, (freq, power)), = pier_power_flows(s).items()
    assert pier == 7
    expected = 0.5 * c * (w * amp) ** 2
    assert power.sum() == pytest.approx(expected, rel=0.01)
    assert freq[np.argmax(np.abs(power))] == pytest.approx(f0, abs=0.25)


def test_a_pier_without_both_bearings_has_no_power_flow():
    t = np.arange(0, 1.0, 0.01)
    s = Streams(Path('x'), 'x', pier_top={3: _series(t, np.zeros((t.size, 3)))},
                bearing={(3, 'left'): _series(t, np.zeros((t.size, 3)))})
    assert pier_power_flows(s) == {}


def test_the_ground_grid_map_reads_the_named_points_into_rows_and_columns(tmp_path):
    """A 2 x 3 grid of pier07 after one line point: x, y axes and RMS az in (row, column)."""
    from ttb_sim.io.topics import SOIL_FIELDS
    from ttb_sim.report.figures import soil_grid
    from ttb_sim.report.soil import ground_grid_rms
    t = np.arange(0, 1.0, 0.01)
    names = ('pier07/line_01', *(f'pier07/grid_{r:02d}_{c:02d}' for r in (1, 2)
                                 for c in (1, 2, 3)))
    cloud = np.zeros((t.size, len(names), len(SOIL_FIELDS)))
    az = SOIL_FIELDS.index('az')
    for k, (x, y) in enumerate([(0.0, 0.0)] + [(x, y) for y in (-1.0, 1.0)
                                               for x in (10.0, 11.0, 12.0)]):
        cloud[:, k, 0], cloud[:, k, 1] = x, y
        cloud[:, k, az] = (k + 1) * np.sin(2 * np.pi * 5 * t)
    s = Streams(Path('x'), 'x', soil=_series(t, cloud), soil_fields=SOIL_FIELDS,
                soil_names=names)
    (pier, (x, y, rms)), = ground_grid_rms(s).items()
    assert pier == 'pier07'
    assert x.tolist() == [10.0, 11.0, 12.0] and y.tolist() == [-1.0, 1.0]
    np.testing.assert_allclose(rms, np.sqrt(0.5) * np.arange(2, 8).reshape(2, 3), rtol=1e-3)
    (note,) = soil_grid([s], tmp_path)
    assert (tmp_path / note.name).stat().st_size > 0
