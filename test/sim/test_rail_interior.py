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
The rail under a wheel does not depend on the rail mesh (the element's interior flexibility).

Euler beam elements give exact nodal displacements under a point load anywhere,
so the static motion of the rail head under a wheel, the nodes' interpolation
plus the loaded element's interior deflection, is the same on any rail mesh
whose nodes include the fasteners. Checked through the assembled track of the
scenario (rails on fasteners, slabs, base plates, one span) with 1, 2 and 4
rail elements per fastener bay at points all over a bay: the full 3 x 3 static
flexibility of the rail head (1e-9 relative, measured 5e-12; without the
interior part it is too stiff laterally by up to 7.9 / 3.5 / 1.7 % on 1 / 2 / 4
elements per bay, as the elements interpolate the rail's twist linearly), and
the static start of a car standing on them (compressions within 1e-10 m;
without it they differ by up to 16 um on one element per bay).
"""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.config import load_scenario
from ttb_sim.fe.beam import interior_compliance, point_rows
from ttb_sim.fe.factorization import factorize
from ttb_sim.sim.coupling.train_track.multibody import rail_section_columns
from ttb_sim.sim.simulation import Simulation

SMALL = [('train.vehicle', 'car'), ('track.model', 'slab'), ('train.n_cars', 1),
         ('bridge.n_spans', 1), ('bearings.model', 'elastic'), ('solver.duration', 1e-3)]
MESHES = (1, 2, 4)


def car_on_track(per_bay: int, start: float = 0.0) -> Simulation:
    return Simulation(load_scenario('moving_force_beam', values=SMALL + [
        ('track.rail_elements_per_bay', per_bay), ('train.start_position', start)]))


def head_flexibility(sim: Simulation, x: np.ndarray, interior: bool) -> np.ndarray:
    """Return the static (n, 3, 3) flexibility of the left rail head at x (m/N)."""
    st = sim.structure
    rail = st.track.rails[0]
    arm = np.array([0.0, 0.0, st.track.rail_head])
    element, xi, inside = rail.locate(x)
    assert np.all(inside)
    rows = point_rows(xi, rail.length[element], arm)                  # (n, 3, 12)
    dofs = st.full_to_free[rail.dofs[element]]                        # (n, 12)
    n_free = st.n_free
    load = np.zeros((n_free + 1, 3 * x.size))
    for p in range(x.size):
        np.add.at(load[:, 3 * p:3 * p + 3], dofs[p], rows[p].T)
    u = np.vstack([factorize(st.stiffness.tocsc()).solve(load[:n_free]),
                   np.zeros((1, 3 * x.size))])
    flex = np.stack([rows[p] @ u[dofs[p], 3 * p:3 * p + 3] for p in range(x.size)])
    if interior:
        section = rail_section_columns(rail)[element]
        flex += interior_compliance(xi, rail.length[element], *section.T, float(arm[2]))
    return flex


@pytest.fixture(scope='module')
def cars() -> dict[int, Simulation]:
    return {n: car_on_track(n) for n in MESHES}


def test_static_head_flexibility_is_the_same_on_every_rail_mesh(cars):
    rail = cars[1].structure.track.rails[0]
    bay = float(rail.length[0])
    middle = rail.start[rail.start.size // 2]             # a fastener mid-track
    x = middle + bay * np.array([0.0, 0.1, 0.25, 0.4, 0.5, 0.63, 0.9])
    want = head_flexibility(cars[4], x, interior=True)
    assert want[0, 1, 1] < want[4, 1, 1]                 # softer between the fasteners
    for n in MESHES[:-1]:
        got = head_flexibility(cars[n], x, interior=True)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())
    # Without the interior part the one-element bay is visibly stiffer laterally.
    nodes_only = head_flexibility(cars[1], x, interior=False)
    assert np.max(np.abs(nodes_only - want)[:, 1, 1] / want[:, 1, 1]) > 0.05


def test_static_start_is_the_same_on_every_rail_mesh():
    # The car's wheels at all kinds of places within their bays.
    starts = {n: car_on_track(n, start=0.37) for n in MESHES}
    for sim in starts.values():
        sim.coupling.start(0.37)
    want = starts[4].coupling
    for n in MESHES[:-1]:
        got = starts[n].coupling
        np.testing.assert_allclose(got.compression, want.compression, rtol=0, atol=1e-10)
        np.testing.assert_allclose(got.force[..., 2], want.force[..., 2], rtol=1e-7)
    assert np.ptp(want.compression) > 0.0
