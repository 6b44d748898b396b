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
The stepping core: build step, integrators, couplings, the simulation loop, frames.

``build`` turns a scenario into model objects (the only reader of the scenario
tree), ``integrators`` holds the integrator protocol and Newmark, ``coupling`` the
vehicle-structure couplings behind one protocol, ``simulation`` the one stepping
loop that yields :class:`Frame` objects, ``variants`` the solver variants.

The names below are the package's face: the layers above (commands, node,
validation) take what they need of the stepping core from here.
"""

from ttb_sim.sim.build import (build_foundation, build_structure, build_vehicle,
                               pier_column_parameters, probe_rows, ProbeRows)
from ttb_sim.sim.cost import CostEstimate, estimate_cost, STEP_BUDGET
from ttb_sim.sim.frames import Frame, Layout, SOIL_VALUES
from ttb_sim.sim.integrators.newmark import Newmark
from ttb_sim.sim.runner import make_runner, Runner
from ttb_sim.sim.simulation import Simulation
from ttb_sim.sim.substructure import reference_refusal, substructure_dof_counts, SubstructureRun
from ttb_sim.sim.variants import blas_threads, solver_variant, VARIANTS

__all__ = ['blas_threads', 'build_foundation', 'build_structure', 'build_vehicle',
           'CostEstimate', 'estimate_cost', 'Frame', 'Layout', 'make_runner', 'Newmark',
           'pier_column_parameters', 'probe_rows', 'ProbeRows', 'reference_refusal', 'Runner',
           'Simulation', 'SOIL_VALUES', 'solver_variant', 'STEP_BUDGET',
           'substructure_dof_counts', 'SubstructureRun', 'VARIANTS']
