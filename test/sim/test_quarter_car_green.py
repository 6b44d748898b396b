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
The quarter-car step with the girder Green's function equals the multi-column Woodbury step.

Both paths solve the same coupled equations; they differ only in the order of
operations, so girder, sprung-mass and contact histories must agree to rounding
(1e-9 relative), here on three quarter cars over two elastic spans with an
irregular track.
"""

import numpy as np
import pytest
from ttb_sim.config import load_scenario
import ttb_sim.sim.coupling.quarter_car.wheels as quarter_car
from ttb_sim.sim.simulation import Simulation

OVERRIDES = [('bridge.n_spans', 2), ('bridge.elements_per_span', 8),
             ('train.axle_offsets', [0.0, 2.5, 17.5]), ('bearings.model', 'elastic'),
             ('irregularity.spectrum', 'chinese_hsr'), ('irregularity.grid_spacing', 0.05),
             ('solver.duration', 0.3), ('train.unsprung_mass', 1500.0),
             ('train.suspension_damping', 5.0e4)]


def history(limit: int, monkeypatch: pytest.MonkeyPatch) -> np.ndarray:
    monkeypatch.setattr(quarter_car, 'DENSE_GIRDER_LIMIT', limit)
    sim = Simulation(load_scenario('sprung_mass_beam', [], OVERRIDES))
    rows = []
    for frame in sim.frames():
        rows.append(np.concatenate([np.ravel(frame.midspan), np.ravel(frame.wheel_rail),
                                    np.ravel(frame.body_acceleration)]))
    return np.array(rows)


def test_green_path_equals_woodbury_columns(monkeypatch: pytest.MonkeyPatch) -> None:
    green = history(quarter_car.DENSE_GIRDER_LIMIT, monkeypatch)
    columns = history(0, monkeypatch)
    assert green.shape == columns.shape and green.shape[0] > 100
    scale = np.abs(columns).max(axis=0) + 1e-30
    assert np.max(np.abs(green - columns) / scale) < 1e-9
    assert np.ptp(columns[:, -1]) > 0  # the sprung masses move: the check is not vacuous
