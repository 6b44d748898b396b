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

"""DofMap: full and free numbering, substructure blocks and interfaces (fe/dofs.py)."""

import numpy as np
import pytest
from ttb_sim.config import load_scenario
from ttb_sim.errors import ModelError
from ttb_sim.fe.dofs import DofMap
from ttb_sim.sim import build_structure


def test_free_numbering_skips_constrained_dofs_and_keeps_an_extended_zero_slot():
    mask = np.zeros(3 * 2, dtype=bool)
    mask[[0, 3]] = True
    dm = DofMap.compose(3, 2, mask, {'a': [0, 1], 'b': [2]}, {'ab': [1]})
    assert dm.n_free == 4
    assert dm.free.tolist() == [1, 2, 4, 5]
    assert dm.full_to_free.tolist() == [4, 0, 1, 4, 2, 3]
    assert dm.block_dofs('a').tolist() == [0, 1]       # DOFs 0 and 3 are constrained
    assert dm.block_dofs('b').tolist() == [2, 3]
    assert dm.interface_dofs('ab').tolist() == [[1, 4]]


def test_refusals_name_the_problem():
    with pytest.raises(ModelError, match='shape'):
        DofMap.compose(2, 2, np.zeros(3, dtype=bool))
    with pytest.raises(ModelError, match='overlap'):
        DofMap.compose(2, 1, np.zeros(2, dtype=bool), {'a': [0, 1], 'b': [1]})
    with pytest.raises(ModelError, match='outside'):
        DofMap.compose(2, 1, np.zeros(2, dtype=bool), interfaces={'i': [2]})


@pytest.mark.parametrize('scenario, overrides', [
    ('ten_span_train', []),
    ('moving_force_beam', []),
    ('track_approach', ['bridge.n_spans=2', 'foundation.model=springs',
                        'bearings.model=elastic']),
])
def test_bridge_substructures_partition_the_model(scenario, overrides):
    """Blocks own every node once; their free DOFs partition the solver state."""
    st = build_structure(load_scenario(scenario, overrides))
    dm = st.dofs
    nodes = np.sort(np.concatenate(list(dm.blocks.values())))
    assert nodes.tolist() == list(range(dm.n_full // dm.node_dofs))
    free = np.sort(np.concatenate([dm.block_dofs(b) for b in dm.blocks]))
    assert free.tolist() == list(range(st.n_free))
    s = load_scenario(scenario, overrides)
    n_piers = s.bridge.n_spans - 1 if s.foundation.model == 'springs' else 0
    assert dm.interfaces['foundations'].size == n_piers
    assert dm.interfaces['bearings'].size == 2 * s.bridge.n_spans + n_piers
    assert (dm.blocks['track'].size > 0) == (s.track.model == 'slab')
