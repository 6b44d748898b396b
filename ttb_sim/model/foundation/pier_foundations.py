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
The foundations of the bridge's piers, as the structure composes them.

:class:`FoundationParameters` chooses them: rigid supports, the foundation
springs of [P] Table 4 under the pier bases, or (``piled``) some piers on the
cap-pile-soil substructure of :mod:`.reduction`. Abutments are always rigid.
A piled pier coupled monolithically ([P] Eq. 11) enters the structure as a
block of pseudo-nodes after the beams (:func:`piled_blocks`) carrying its
dense operator (:func:`add_piled_blocks`); partitioned, it stays outside.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import scipy.sparse as sp

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.fe.assembly import dense_block, diagonal
from ttb_sim.fe.beam import NODE_DOFS
from ttb_sim.model.foundation.operator import FoundationOperator


@dataclass(frozen=True)
class FoundationParameters:
    """Foundations of the intermediate piers; abutments are always rigid."""

    model: str = param('rigid', '-', "'rigid': bearings sit on fixed supports; 'springs': "
                       "piers on foundation springs ([P] Table 4); 'piled': the piers of "
                       'piled_piers stand on the 3-D cap-pile-soil substructure of the soil, '
                       'piles, cap and interface keys, the others on springs.',
                       choices=('rigid', 'springs', 'piled'))
    piled_piers: tuple[int, ...] = param((), '-', 'Supports on piled foundations when model = '
                                         "'piled', numbered 1 (first abutment) to n_spans + 1 "
                                         '(last abutment): intermediate piers only. '
                                         'VALIDATION.md: [7, 8].', low=2, high=50)
    vertical_stiffness: float = param(6e9, 'N/m', 'Vertical foundation spring ([P] Table 4).',
                                      low=0.0, high=1e15, low_inclusive=False)
    lateral_stiffness: float = param(6e8, 'N/m', 'Lateral and longitudinal foundation spring '
                                     '([P] Table 4).', low=0.0, high=1e15, low_inclusive=False)
    rotational_stiffness: float = param(1e11, 'N*m/rad', 'Rocking and twisting foundation '
                                        'spring (assumed; not in [P]).', low=0.0, high=1e18,
                                        low_inclusive=False)
    damping: float = param(0.0, 'N*s/m', 'Translational foundation damping ([P] Table 4: 0).',
                           low=0.0, high=1e12)

    def __post_init__(self) -> None:
        """Check every field against its declaration, and the piled piers."""
        check_declared(self, 'foundation parameter')
        piers = self.piled_piers
        if any(isinstance(p, bool) or not isinstance(p, int) or p < 2 for p in piers):
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} is invalid; allowed: '
                             'support numbers >= 2 (1 is the first abutment)')
        if len(set(piers)) != len(piers):
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} names a pier twice')
        if self.model == 'piled' and not piers:
            raise ModelError("foundation.model = 'piled' needs foundation.piled_piers, e.g. "
                             '[7, 8] (support numbers of the piled piers)')
        if self.model != 'piled' and piers:
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} needs '
                             f"foundation.model = 'piled' (got {self.model!r})")

    @property
    def piled(self) -> tuple[int, ...]:
        """0-based support indices of the piled piers, in ascending order."""
        return tuple(sorted(p - 1 for p in self.piled_piers))


def foundation_springs(fd: FoundationParameters, bases: np.ndarray,
                       n_full: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Return (K, C) of the foundation springs under the pier base nodes ``bases``."""
    bdofs = (bases[:, None] * NODE_DOFS + np.arange(NODE_DOFS)).ravel()
    kf = np.tile([fd.lateral_stiffness, fd.lateral_stiffness, fd.vertical_stiffness,
                  fd.rotational_stiffness, fd.rotational_stiffness,
                  fd.rotational_stiffness], bases.size)
    cf = np.tile([fd.damping, fd.damping, fd.damping, 0.0, 0.0, 0.0], bases.size)
    return diagonal(n_full, bdofs, kf), diagonal(n_full, bdofs, cf)


@dataclass(frozen=True)
class PiledBlocks:
    """Monolithic piled piers: their coordinates q as pseudo-nodes after the beams."""

    coordinates: dict[int, np.ndarray]
    """Support -> full DOF index of each coordinate q (q[:6], the pier top, is one node)."""
    padding: np.ndarray
    """Full DOFs that pad each block's last node to whole nodes (constrained)."""
    pier_top: np.ndarray
    """Pier top node per support (-1: none), with the piled piers' pseudo-nodes."""
    n_nodes: int
    """Number of nodes, beams and pseudo-nodes."""


def piled_blocks(foundations: Mapping[int, FoundationOperator], piled: tuple[int, ...],
                 n_nodes: int, pier_top: np.ndarray) -> PiledBlocks:
    """
    Return the coordinates of the piled piers numbered as pseudo-nodes from ``n_nodes`` on.

    Parameters
    ----------
    foundations : mapping
        The substructure of each piled pier by 0-based support index.
    piled : tuple of int
        The piled supports, in the order of numbering.
    n_nodes : int
        Nodes of the beams (the first pseudo-node's number).
    pier_top : numpy.ndarray
        Pier top node per support (-1: none); not changed.

    """
    pier_top = pier_top.copy()
    coordinates: dict[int, np.ndarray] = {}
    padding: list[np.ndarray] = []
    for support in piled:
        size = foundations[support].size
        count = -(-size // NODE_DOFS)
        pier_top[support] = n_nodes
        coordinates[support] = n_nodes * NODE_DOFS + np.arange(size)
        padding.append(n_nodes * NODE_DOFS + np.arange(size, count * NODE_DOFS))
        n_nodes += count
    pad = np.concatenate(padding) if padding else np.zeros(0, dtype=int)
    return PiledBlocks(coordinates, pad, pier_top, n_nodes)


def add_piled_blocks(matrix: sp.csr_matrix, blocks: PiledBlocks,
                     foundations: Mapping[int, FoundationOperator],
                     name: str) -> sp.csr_matrix:
    """Return ``matrix`` plus each block's dense ``name`` matrix (mass, damping, stiffness)."""
    n_full = matrix.shape[0]
    for support, full in blocks.coordinates.items():
        matrix = matrix + dense_block(n_full, full, getattr(foundations[support], name))
    return matrix
