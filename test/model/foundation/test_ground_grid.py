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

"""The ground-surface grid of soil points around a pile group (output.soil_grid_*)."""

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.model.foundation.observation import ground_grid


def test_the_grid_covers_the_cap_and_its_margin_at_the_spacing() -> None:
    """[P]'s 15 x 9 m cap, 3 m margin, 1.5 m: 15 x 11 points from -10.5 to 10.5, -7.5 to 7.5."""
    spec = load_scenario('paper_ttbcpsi', ['output.soil_grid_spacing=1.5',
                                           'output.soil_grid_margin=3']).substructure()
    positions, names = ground_grid(spec)
    centre = np.array(spec.piles.centre)
    x, y = positions[:, 0] - centre[0], positions[:, 1] - centre[1]
    assert positions.shape == (165, 3) and len(set(names)) == 165
    assert (x.min(), x.max(), y.min(), y.max()) == pytest.approx((-10.5, 10.5, -7.5, 7.5))
    assert np.all(positions[:, 2] == 0.0)
    assert np.unique(np.round(np.diff(np.unique(x)), 12)).tolist() == [1.5]
    assert names[0] == 'grid_01_01' and names[14] == 'grid_01_15' and names[15] == 'grid_02_01'


def test_a_spacing_that_does_not_divide_keeps_both_edges_and_never_exceeds_it() -> None:
    spec = load_scenario('paper_ttbcpsi', ['output.soil_grid_spacing=2',
                                           'output.soil_grid_margin=1']).substructure()
    positions, _ = ground_grid(spec)
    xs = np.unique(positions[:, 0] - spec.piles.centre[0])
    assert xs[0] == pytest.approx(-8.5) and xs[-1] == pytest.approx(8.5)
    assert np.max(np.diff(xs)) <= 2.0 + 1e-12


def test_without_a_cap_the_grid_covers_the_pile_group() -> None:
    """single_pile has no cap: the footprint is the pile's own square."""
    spec = load_scenario('single_pile', ['output.soil_grid_spacing=1',
                                         'output.soil_grid_margin=2']).substructure()
    positions, _ = ground_grid(spec)
    half = 0.5 * spec.piles.width + 2.0
    assert np.ptp(positions[:, 0]) == pytest.approx(2 * half)
