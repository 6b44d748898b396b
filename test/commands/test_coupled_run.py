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
A coupled run through ``ttb-sim run``: the bag holds the bearing, pile and soil streams.

Eight moving-force cars over four spans with pier 3 on a coarse pile group: the
pile heads of the piled pier settle under the train by what its bearings carry
over the group's stiffness, the ground points are where the summary says, and
the summary reports Eq. 16 and the interface check.
"""

import json

import numpy as np
import pytest
from ttb_sim.cli import main
from ttb_sim.io.reader import read_bag
from ttb_sim.validation.cases.coupled import FAST


def test_coupled_bag_holds_bearing_pile_and_soil_streams(tmp_path):
    out = tmp_path / 'bag'
    sets = [arg for key in (*FAST, 'output.rate_hz=200') for arg in ('--set', key)]
    assert main(['run', 'paper_ttbcpsi', '--out', str(out), *sets]) == 0
    summary = json.loads((out / 'summary.json').read_text())
    arrays = read_bag(out)
    piles = sorted(t for t in arrays if t.startswith('/ttb_sim/piles/pier03/'))
    assert len(piles) == 30                       # 15 piles, displacement and imu
    assert not [t for t in arrays if '/piles/pier02/' in t or '/piles/pier04/' in t]
    for s in range(1, 6):
        assert f'/ttb_sim/bearings/pier{s:02d}/left' in arrays
    # the piled pier's heads settle while the train is on its spans, and come back
    z = np.array([arrays[f'/ttb_sim/piles/pier03/pile{m:02d}/displacement']['vector'][:, 2]
                  for m in range(1, 16)])
    assert z.min() < -1e-4 and abs(z[:, -1]).max() < 0.2 * abs(z.min())
    # the group settles as a body under the rigid cap: heads within 10 % of each other
    low = z[:, np.argmin(z.mean(axis=0))]
    assert low.max() - low.min() < 0.1 * abs(low.mean())
    # the load that settles it is what the bearings of pier 3 carry
    bearing = sum(arrays[f'/ttb_sim/bearings/pier03/{side}']['force'][:, 2]
                  for side in ('left', 'right'))
    assert bearing.min() < -1e5
    # every head reports its own rotation rate (not a stub zero), small beside its settlement
    rates = np.array([arrays[f'/ttb_sim/piles/pier03/pile{m:02d}/imu']['angular_velocity']
                      for m in range(1, 16)])
    assert (np.abs(rates).max(axis=(1, 2)) > 0).all()
    assert np.abs(rates).max() < 1e-3               # rad/s, against mm/s of settlement rate
    soil = arrays['/ttb_sim/soil/points']['points']
    assert soil.shape[1] == 24                    # [P]'s line of 21 and the 3 VAL points
    assert np.allclose(soil[0, :, 0].mean(), 2 * 32.0, atol=6.0)   # under pier 3
    about = summary['solver']
    assert about['coupling']['substructure_steps'] == 3
    assert about['dofs']['piled_piers']['pier03']['coordinates'] > 6
    girders = {r['girder']: r for r in about['rigid_displacement']}
    assert set(girders) == {2, 3}
    # Eq. 16: a rigid girder 3 on settling pier 3 and rigid pier 4 drops half the settlement
    assert girders[3]['rigid_peak'] == pytest.approx(0.5 * abs(low.mean()), rel=1e-3)
    assert girders[3]['computed_peak'] > girders[3]['rigid_peak']
    assert 0 < about['interface_mobilisation']['pier03']['train'] < 1
