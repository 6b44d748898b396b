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
The linear pile-soil model with the cap top tied rigidly to a 6-DOF master.

:func:`tie_cap` is the first step of the reduction (:mod:`.reduction`): the
cap-top nodes follow a master at the group centre on the cap top
(u_i = u_m + theta x r_i), on which the pier column will stand.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe.mesh import node_dofs
from ttb_sim.model.foundation.records import FoundationError, Substructure
from ttb_sim.model.foundation.soil_mesh import CAP
from ttb_sim.model.foundation.substructure import PileSoilModel


@dataclass(frozen=True)
class TiedSubstructure:
    """
    The linear pile-soil model with the cap top tied to a 6-DOF master (sparse).

    Coordinates x = [master (ux, uy, uz, rx, ry, rz), free DOFs not on the cap
    top]; the full displacement is u = ``transform`` @ x.

    Attributes
    ----------
    model : PileSoilModel
        The finite-element substructure.
    transform : csr (n_dofs, n_x)
        u = T x.
    mass, damping, stiffness : csr (n_x, n_x)
        T^T M T, T^T C T, T^T K T (K with the interface at its initial tangent).
    master : array (3,)
        Master position: the group centre on the cap top (m).

    """

    model: PileSoilModel
    transform: sp.csr_matrix
    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    master: np.ndarray

    @property
    def size(self) -> int:
        """Number of coordinates n_x."""
        return int(self.transform.shape[1])

    @property
    def kept(self) -> np.ndarray:
        """The free DOFs off the cap top, in the order of x[6:] (one 1 per column of T)."""
        return self.transform[:, 6:].tocsc().indices


def check_spec(spec: Substructure) -> None:
    """
    Refuse a substructure that cannot carry a reduced pier.

    Raises
    ------
    FoundationError
        No piles, the cap disabled, or a boundary without static support.

    """
    if spec.piles is None:
        raise FoundationError('piles = none: a piled pier needs piles (set piles.rows and '
                              'piles.cols)')
    if not spec.cap.enabled:
        raise FoundationError('cap.enabled = False: the pier stands on the cap top; allowed '
                              'for a piled pier: cap.enabled = true')
    if spec.soil.boundary == 'lysmer':
        raise FoundationError("soil.boundary = 'lysmer' leaves the block without static "
                              "support; allowed for a piled pier: 'viscoelastic', 'fixed' "
                              "or 'rigid_base'")


def cap_tie(model: PileSoilModel) -> tuple[sp.csr_matrix, np.ndarray, np.ndarray]:
    """
    Return the tie of the cap top to its master: (T, kept, master).

    u = T x with x = [master (6), the free DOFs ``kept`` not on the cap top];
    ``master`` is the group centre on the cap top (m).
    """
    spec = model.spec
    check_spec(spec)
    assert spec.piles is not None
    nodes = model.mesh.nodes
    top = spec.cap.thickness
    cap_nodes = np.unique(model.mesh.cells[model.cell_kind == CAP])
    tied = cap_nodes[np.abs(nodes[cap_nodes, 2] - top) <= 1e-9 * max(1.0, top)]
    master = np.array([spec.piles.centre[0], spec.piles.centre[1], top], dtype=float)
    n_dofs = model.n_dofs
    on_top = np.zeros(n_dofs, dtype=bool)
    on_top[node_dofs(tied[:, None]).ravel()] = True
    kept = np.flatnonzero(model.free & ~on_top)
    r = nodes[tied] - master
    one = np.ones(len(tied))
    # u = u_m + theta x r: (theta_y r_z - theta_z r_y, theta_z r_x - theta_x r_z,
    # theta_x r_y - theta_y r_x)
    terms = [(0, 0, one), (0, 4, r[:, 2]), (0, 5, -r[:, 1]),
             (1, 1, one), (1, 5, r[:, 0]), (1, 3, -r[:, 2]),
             (2, 2, one), (2, 3, r[:, 1]), (2, 4, -r[:, 0])]
    rows = [kept] + [3 * tied + axis for axis, _, _ in terms]
    cols = [6 + np.arange(len(kept))] + [np.full(len(tied), c) for _, c, _ in terms]
    vals = [np.ones(len(kept))] + [v for _, _, v in terms]
    transform = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows),
                                                      np.concatenate(cols))),
                              shape=(n_dofs, 6 + len(kept)))
    return transform, kept, master


def tie_cap(model: PileSoilModel) -> TiedSubstructure:
    """Return the linear model with the cap top tied rigidly to a master at its centre."""
    transform, _, master = cap_tie(model)
    k = model.linear_stiffness() + model.initial_interface_stiffness()
    c = model.linear_damping()
    m = sp.diags(model.mass)
    t_t = transform.T.tocsr()

    def project(a: sp.spmatrix) -> sp.csr_matrix:
        out = (t_t @ a @ transform).tocsr()
        return ((out + out.T) * 0.5).tocsr()

    return TiedSubstructure(model, transform, project(m), project(c), project(k), master)
