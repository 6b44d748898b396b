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
Mirror symmetry of a hexahedral mesh: a field that is even or odd about x = 0 or y = 0.

A mesh that is its own mirror image about the plane x = 0 (or y = 0), with
materials that match, carries two kinds of response to a load of the same
symmetry: *symmetric* (the mirror image of the displacement is the
displacement: u_x flips sign, u_y and u_z do not) and *antisymmetric* (the
opposite signs). :func:`mirror_reduction` returns the sparse T with one
±1 per row that writes every DOF in terms of the DOFs of the representative
nodes (x >= 0 and y >= 0 for the planes used), the components that must vanish
on a plane left out. A problem Z u = f whose load lies in the range of T is
solved exactly by the Galerkin projection T^T Z T u_r = T^T f, u = T u_r, on
a quarter (or half) of the unknowns.

Mirror nodes are found through the cells, not the coordinates alone: the
duplicated nodes of a thin-layer interface share their coordinates, and the
mirror of a soil cell's node is the node of the mirror soil cell.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ttb_sim.errors import FEError

Parity = Literal['symmetric', 'antisymmetric']

#: Sign of each displacement component in the mirror image of a symmetric field, per plane.
_SYMMETRIC_SIGNS = {'x': np.array([-1.0, 1.0, 1.0]), 'y': np.array([1.0, -1.0, 1.0])}


@dataclass(frozen=True)
class MirrorPlane:
    """A plane of mirror symmetry: ``axis`` = 0 is the plane, with the field's parity."""

    axis: Literal['x', 'y']
    parity: Parity

    def signs(self) -> np.ndarray:
        """Return the sign of (u_x, u_y, u_z) at a node's mirror image."""
        s = _SYMMETRIC_SIGNS[self.axis]
        return s if self.parity == 'symmetric' else -s


def mirror_nodes(nodes: np.ndarray, cells: np.ndarray, material: np.ndarray, axis: str,
                 tolerance: float = 1e-6) -> np.ndarray:
    """
    Return the mirror node of every node about ``axis`` = 0 (an index array).

    Raises
    ------
    FEError
        When a cell has no mirror cell of the same material, i.e. the mesh is
        not symmetric about the plane.

    """
    k = 'xyz'.index(axis)
    flip = np.ones(3)
    flip[k] = -1.0
    xyz = nodes[cells]
    centres = xyz.mean(axis=1)
    tree = cKDTree(centres)
    dist, partner = tree.query(centres * flip)
    scale = tolerance * max(float(np.ptp(nodes, axis=0).max()), 1.0)
    bad = (dist > scale) | (material[partner] != material)
    if np.any(bad):
        worst = int(np.flatnonzero(bad)[0])
        raise FEError(f'the mesh is not symmetric about {axis} = 0: cell {worst} at '
                      f'{np.round(centres[worst], 4).tolist()} has no mirror cell')
    # local node b of the partner cell that is the mirror of local node a of each cell
    gap = np.linalg.norm((xyz * flip)[:, :, None, :] - xyz[partner][:, None, :, :], axis=-1)
    local = gap.argmin(axis=2)
    if np.any(gap.min(axis=2) > scale):
        raise FEError(f'the mesh is not symmetric about {axis} = 0: a cell and its '
                      'mirror do not share node positions')
    image = np.arange(len(nodes))
    image[cells.ravel()] = cells[partner[:, None], local].ravel()
    return image


def mirror_reduction(nodes: np.ndarray, cells: np.ndarray, material: np.ndarray,
                     planes: tuple[MirrorPlane, ...]) -> sp.csr_matrix:
    """
    Return T (3 n_nodes x n_reduced): full DOFs from the representative DOFs.

    Each row has one ±1 (or none, for a component that vanishes on a plane).
    Columns are the kept DOFs of the representative nodes in ascending order.
    """
    n = len(nodes)
    owner = np.arange(n)
    sign = np.ones((n, 3))
    on_plane = np.zeros((n, 3), dtype=bool)
    for plane in planes:
        k = 'xyz'.index(plane.axis)
        image = mirror_nodes(nodes, cells, material, plane.axis)
        if np.any(image[image] != np.arange(n)):
            raise FEError(f'the mirror about {plane.axis} = 0 is not an involution')
        below = nodes[owner, k] < 0.0
        sign[below] *= plane.signs()
        owner = np.where(below, image[owner], owner)
        fixed = plane.signs() < 0
        on_plane |= (image == np.arange(n))[:, None] & fixed[None, :]
    rep_dof = 3 * owner[:, None] + np.arange(3)[None, :]
    zero = on_plane[owner]
    kept = np.zeros(3 * n, dtype=bool)
    kept[rep_dof[~zero]] = True
    column = np.cumsum(kept) - 1
    rows = np.flatnonzero(~zero.ravel())
    cols = column[rep_dof.ravel()[rows]]
    return sp.csr_matrix((sign.ravel()[rows], (rows, cols)), shape=(3 * n, int(kept.sum())))


def has_parity(field: np.ndarray, image: np.ndarray, plane: MirrorPlane,
               tolerance: float = 1e-9) -> bool:
    """
    Return whether the nodal ``field`` (3 per node) has ``plane``'s parity.

    ``image`` is the mirror of every node about the plane (:func:`mirror_nodes`):
    the field at a node's image must be the field there times the plane's signs.
    """
    u = np.asarray(field, dtype=float).reshape(-1, 3)
    gap = float(np.linalg.norm(u[image] - u * plane.signs()))
    return gap <= tolerance * max(float(np.linalg.norm(u)), 1e-300)
