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
DOF numbering of a model composed of substructures: :class:`DofMap`.

Every node carries the same number of DOFs, numbered node by node (full
numbering). A substructure owns a block of nodes; where two substructures meet,
an interface names the nodes they share or link. Constrained DOFs are removed:
the solver state holds the *free* DOFs, and gathers use an *extended* free
vector with one more slot, index ``n_free``, that stands for every constrained
DOF and always holds zero.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from ttb_sim.errors import ModelError

__all__ = ['DofMap']


@dataclass(frozen=True)
class DofMap:
    """
    Full, free and per-substructure DOF numbering.

    Build it with :meth:`compose`.
    """

    n_full: int
    """Number of DOFs of all nodes."""
    node_dofs: int
    """DOFs per node."""
    free: np.ndarray
    """(n_free,) full index of each free DOF, increasing."""
    full_to_free: np.ndarray
    """(n_full,) extended free index of each full DOF (constrained ones: ``n_free``)."""
    blocks: Mapping[str, np.ndarray] = field(default_factory=dict)
    """Substructure name -> its nodes (full node numbers, increasing)."""
    interfaces: Mapping[str, np.ndarray] = field(default_factory=dict)
    """Interface name -> its nodes (full node numbers)."""

    @classmethod
    def compose(cls, n_nodes: int, node_dofs: int, constrained: np.ndarray,
                blocks: Mapping[str, np.ndarray] | None = None,
                interfaces: Mapping[str, np.ndarray] | None = None) -> DofMap:
        """
        Build the numbering of ``n_nodes`` nodes with some of their DOFs constrained.

        Parameters
        ----------
        n_nodes, node_dofs
            Nodes and DOFs per node.
        constrained : numpy.ndarray
            (n_nodes * node_dofs,) bool, True for a constrained DOF.
        blocks, interfaces
            Named node sets of the substructures and of their interfaces.

        Raises
        ------
        ModelError
            If the mask has the wrong size, blocks overlap, or a named set
            holds a node outside the model.

        """
        n_full = n_nodes * node_dofs
        mask = np.asarray(constrained, dtype=bool)
        if mask.shape != (n_full,):
            raise ModelError(f'constrained mask has shape {mask.shape}; expected ({n_full},)')
        blocks = {k: np.asarray(v, dtype=np.intp) for k, v in (blocks or {}).items()}
        interfaces = {k: np.asarray(v, dtype=np.intp) for k, v in (interfaces or {}).items()}
        for name, nodes in {**blocks, **interfaces}.items():
            if nodes.size and (nodes.min() < 0 or nodes.max() >= n_nodes):
                raise ModelError(f'node set {name!r} holds nodes outside 0..{n_nodes - 1}')
        owned = np.concatenate(list(blocks.values())) if blocks else np.zeros(0, int)
        if np.unique(owned).size != owned.size:
            raise ModelError('substructure blocks overlap: a node belongs to one block only')
        free = np.flatnonzero(~mask)
        full_to_free = np.full(n_full, free.size)
        full_to_free[free] = np.arange(free.size)
        return cls(n_full=n_full, node_dofs=node_dofs, free=free, full_to_free=full_to_free,
                   blocks=blocks, interfaces=interfaces)

    @property
    def n_free(self) -> int:
        """Number of free DOFs."""
        return int(self.free.size)

    def node_dof_indices(self, nodes: np.ndarray) -> np.ndarray:
        """Return the full DOF indices (len(nodes), node_dofs) of nodes."""
        return np.asarray(nodes)[:, None] * self.node_dofs + np.arange(self.node_dofs)

    def block_dofs(self, name: str) -> np.ndarray:
        """Return the free DOF indices of a substructure (its constrained DOFs dropped)."""
        ext = self.full_to_free[self.node_dof_indices(self.blocks[name]).ravel()]
        return ext[ext < self.n_free]

    def interface_dofs(self, name: str) -> np.ndarray:
        """Return the extended free indices (n_nodes, node_dofs) of an interface's nodes."""
        return self.full_to_free[self.node_dof_indices(self.interfaces[name])]
