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
Pier-cap-pile-soil substructures stepped beside the bridge, or on their own.

``stepping`` advances one pile-soil block ([P] Eqs. 12-14: the partitioned
Newmark scheme) over ``stable_step`` (the implicit-explicit partition and the
explicit stable step) and ``state`` (the state, its observation, the interface
response); ``statics`` solves the block under a static load. ``piled_piers``
couples the reduced substructures of piled piers to the bridge through the
bearings, and ``standalone`` runs one substructure alone
(``scenario.substructure_only``).
"""

from ttb_sim.sim.substructure.piled_piers import PiledFoundations
from ttb_sim.sim.substructure.stable_step import implicit_dofs
from ttb_sim.sim.substructure.standalone import (reference_refusal, substructure_dof_counts,
                                                 SubstructureRun)
from ttb_sim.sim.substructure.state import observe, State
from ttb_sim.sim.substructure.statics import static_solve
from ttb_sim.sim.substructure.stepping import PartitionedNewmark, states

__all__ = ['implicit_dofs', 'observe', 'PartitionedNewmark', 'PiledFoundations',
           'reference_refusal', 'State', 'states', 'static_solve', 'substructure_dof_counts',
           'SubstructureRun']
