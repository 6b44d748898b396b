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
Finite elements without physics names: elements, assembly, numbering, factorisation.

``beam`` (3-D Euler-Bernoulli), ``mindlin`` (MITC4 plate), ``hex8`` (trilinear
hexahedron), ``quad`` and ``interface`` (4-node faces, Desai thin-layer elements),
``boundary`` (viscous-spring boundary faces), ``mesh`` (hexahedral meshes: nodes, cells,
named sets; structured grids and their cuts), ``assembly`` (the one COO-once sparse
assembler, chunked for large meshes, and spring-dashpot links), ``dofs`` (:class:`DofMap`:
full/free numbering, substructure blocks and interfaces), ``factorization`` (symmetric
sparse direct solvers behind one function), ``complex_solve`` (complex symmetric sparse
solves), ``symmetry`` (mirror-symmetry reduction of a mesh), ``bisection`` (a long matrix
solved as two halves on two cores), ``compiled`` (numba compilation of the package's kernels).
"""

from ttb_sim.fe.assembly import assemble, assemble_links, link_kinematics
from ttb_sim.fe.dofs import DofMap
from ttb_sim.fe.factorization import factorize

__all__ = ['assemble', 'assemble_links', 'DofMap', 'factorize', 'link_kinematics']
