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
The bearings between girder ends and supports: their record, links and forces.

Bearings sit at y = +/- spacing/2 under each girder end. Elastic bearings are
point spring-dashpots ([P] Eq. 1 lumped to a point) between the girder end and
the pier top (or rigid ground on abutments and rigid foundations). Rigid
bearings make the girder ends ideal pins (uy, uz and twist fixed at both ends,
ux at the first end); their reactions come from the constrained rows of the
structure's matrices.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import scipy.sparse as sp

from ttb_sim.declarations import check_declared, param
from ttb_sim.fe.assembly import assemble_links, link_kinematics
from ttb_sim.fe.beam import NODE_DOFS

if TYPE_CHECKING:
    from ttb_sim.model.structure import Structure


@dataclass(frozen=True)
class BearingParameters:
    """Bearings between girder ends and supports ([P] Eq. 1 as point springs)."""

    model: str = param('rigid', '-', "'rigid': ideal pinned supports; 'elastic': "
                       'spring-dashpot bearings on the supports.', choices=('rigid', 'elastic'))
    spacing: float = param(4.4, 'm', 'Lateral distance between the left and right bearings '
                           '(assumed).', low=0.0, high=50.0, low_inclusive=False)
    vertical_stiffness: float = param(5e9, 'N/m', 'Vertical stiffness per bearing (assumed; '
                                      'typical 1e9-1e10).', low=0.0, high=1e14,
                                      low_inclusive=False)
    lateral_stiffness: float = param(5e8, 'N/m', 'Lateral stiffness per bearing (assumed).',
                                     low=0.0, high=1e14, low_inclusive=False)
    longitudinal_stiffness: float = param(5e7, 'N/m', 'Longitudinal stiffness per bearing '
                                          '(assumed).', low=0.0, high=1e14,
                                          low_inclusive=False)
    vertical_damping: float = param(0.0, 'N*s/m', 'Vertical damping per bearing.', low=0.0,
                                    high=1e12)
    lateral_damping: float = param(0.0, 'N*s/m', 'Lateral and longitudinal damping per '
                                   'bearing.', low=0.0, high=1e12)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'bearing parameter')


@dataclass(frozen=True)
class Bearings:
    """Elastic bearings as spring-dashpot links between girder ends and supports."""

    kinematics: np.ndarray
    """(n, 3, 12) relative displacement of the bearing from the two nodes' DOFs."""
    dofs: np.ndarray
    """(n, 12) extended free indices (ground = the zero slot)."""
    stiffness: np.ndarray
    """(n, 3) stiffness along x, y, z (N/m)."""
    damping: np.ndarray
    """(n, 3) damping along x, y, z (N s/m)."""
    support: np.ndarray
    """(n,) support index (0 = first abutment)."""
    side: np.ndarray
    """(n,) 0 = left (+y), 1 = right (-y)."""


@dataclass(frozen=True)
class BearingLinks:
    """The elastic bearings on the full DOF numbering, before the free DOFs are known."""

    kinematics: np.ndarray
    """(n, 3, 12) relative displacement of the bearing from the two nodes' DOFs."""
    full_dofs: np.ndarray
    """(n, 12) full DOFs of the girder end and the pier top; -1 for rigid ground."""
    stiffness: np.ndarray
    """(n, 3) stiffness along x, y, z (N/m)."""
    damping: np.ndarray
    """(n, 3) damping along x, y, z (N s/m)."""
    support: np.ndarray
    """(n,) support index (0 = first abutment)."""
    side: np.ndarray
    """(n,) 0 = left (+y), 1 = right (-y)."""

    def matrices(self, n_full: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        """Return the links' (K, C) on the full DOFs."""
        return (assemble_links(n_full, self.full_dofs, self.kinematics, self.stiffness),
                assemble_links(n_full, self.full_dofs, self.kinematics, self.damping))

    def numbered(self, full_to_free: np.ndarray, n_free: int) -> Bearings:
        """Return the bearings on the extended free DOFs (ground: the zero slot ``n_free``)."""
        link_full = self.full_dofs
        ext = np.where(link_full >= 0, full_to_free[np.maximum(link_full, 0)], n_free)
        return Bearings(kinematics=self.kinematics, dofs=ext, stiffness=self.stiffness,
                        damping=self.damping, support=self.support, side=self.side)


@dataclass(frozen=True)
class RigidSupports:
    """Ideal pinned girder ends: reactions come from the constrained rows."""

    rows_k: sp.csr_matrix
    rows_c: sp.csr_matrix
    rows_m: sp.csr_matrix
    """Rows of K, C, M for the constrained DOFs, over the extended free DOFs."""
    full_dofs: np.ndarray
    """(n_c,) full DOF index of each constrained DOF (for its applied load)."""
    support: np.ndarray
    """(n_c,) support index of each constrained DOF."""
    component: np.ndarray
    """(n_c,) 0..2 = force x, y, z; 3 = moment about x."""


@dataclass(frozen=True)
class RigidEnds:
    """The constrained DOFs of ideal pinned girder ends, before the free DOFs are known."""

    full_dofs: np.ndarray
    """(n_c,) full DOF index of each constrained DOF."""
    support: np.ndarray
    """(n_c,) support index of each constrained DOF."""
    component: np.ndarray
    """(n_c,) 0..2 = force x, y, z; 3 = moment about x."""

    def supports(self, stiffness: sp.csr_matrix, damping: sp.csr_matrix, mass: sp.csr_matrix,
                 free: np.ndarray) -> RigidSupports:
        """Return the supports with the constrained rows of the full K, C, M."""
        cdofs = self.full_dofs

        def rows(a: sp.csr_matrix) -> sp.csr_matrix:
            r = a[cdofs][:, free].tocsc()
            return sp.hstack([r, sp.csc_matrix((cdofs.size, 1))]).tocsr()

        return RigidSupports(rows_k=rows(stiffness), rows_c=rows(damping), rows_m=rows(mass),
                             full_dofs=cdofs, support=self.support, component=self.component)


def rigid_ends(ends: np.ndarray, end_support: np.ndarray) -> RigidEnds:
    """
    Return the constrained DOFs of ideal pinned girder ends.

    Parameters
    ----------
    ends : numpy.ndarray
        (n_spans, 2) node of the first and last end of each girder.
    end_support : numpy.ndarray
        (n_spans, 2) support index under each end.

    """
    n_spans = ends.shape[0]
    comp_list, dof_list, sup_list = [], [], []
    for end in (0, 1):
        comps = (0, 1, 2, 3) if end == 0 else (1, 2, 3)
        for c in comps:
            dof_list.append(ends[:, end] * NODE_DOFS + c)
            sup_list.append(end_support[:, end])
            comp_list.append(np.full(n_spans, c))
    return RigidEnds(np.concatenate(dof_list), np.concatenate(sup_list),
                     np.concatenate(comp_list))


def bearing_links(br: BearingParameters, ends: np.ndarray, end_support: np.ndarray,
                  pier_top: np.ndarray, moving: np.ndarray,
                  stiffness_factors: np.ndarray | None = None) -> BearingLinks:
    """
    Return the elastic bearings as links between girder ends and pier tops (or ground).

    ``moving`` marks the supports (partitioned piled piers) whose pier top is not
    a node of the structure: their links are assembled as on ground, but the
    kinematics keep the pier-top arm for the substructure's motion.
    ``stiffness_factors`` (n_supports, 2), if given, multiply the three stiffnesses of
    the bearings of each support and side (damage,
    :func:`ttb_sim.model.damage.bearing_stiffness_factors`).

    Returns
    -------
    BearingLinks
        One link per girder end and side.

    """
    e = br.spacing / 2
    girder_end = np.repeat(ends.ravel(), 2)               # node, per side
    support = np.repeat(end_support.ravel(), 2)
    side = np.tile([0, 1], ends.size)
    arm = np.column_stack([np.zeros(side.size), np.where(side == 0, e, -e),
                           np.zeros(side.size)])
    top = pier_top[support]
    kin = link_kinematics(arm, np.where(((top >= 0) | moving[support])[:, None], arm, 0.0))
    kdir = np.tile([br.longitudinal_stiffness, br.lateral_stiffness,
                    br.vertical_stiffness], (side.size, 1))
    if stiffness_factors is not None:
        kdir = kdir * stiffness_factors[support, side][:, None]
    cdir = np.tile([br.lateral_damping, br.lateral_damping, br.vertical_damping],
                   (side.size, 1))
    node_b = np.where(top >= 0, top, 0)
    full_b = node_b[:, None] * NODE_DOFS + np.arange(NODE_DOFS)
    ground = np.repeat(top < 0, NODE_DOFS).reshape(-1, NODE_DOFS)
    link_full = np.concatenate([girder_end[:, None] * NODE_DOFS + np.arange(NODE_DOFS),
                                np.where(ground, -1, full_b)], axis=1)
    return BearingLinks(kin, link_full, kdir, cdir, support, side)


def bearing_forces(structure: Structure, u: np.ndarray, v: np.ndarray, a: np.ndarray,
                   load_full: np.ndarray,
                   tops: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """
    Return the force each support receives from its bearings (N).

    Parameters
    ----------
    structure : Structure
        The assembled bridge.
    u, v, a : arrays
        Extended free displacement, velocity and acceleration (last slot zero).
    load_full : array
        Applied load on the full DOFs (used for loads sitting on a rigid support).
    tops : (u, v) arrays (n_supports, 6), optional
        Displacement and velocity of the pier tops that are not structure DOFs
        (partitioned piled piers; zero rows elsewhere).

    Returns
    -------
    numpy.ndarray
        Shape (n_supports, 2, 3): left/right bearings, force (x, y, z) in track
        axes acting ON the support (downward = negative z).

    """
    out = np.zeros((structure.n_supports, 2, 3))
    if structure.bearings is not None:
        bg = structure.bearings
        d = np.einsum('eai,ei->ea', bg.kinematics, u[bg.dofs])
        dv = np.einsum('eai,ei->ea', bg.kinematics, v[bg.dofs])
        if tops is not None:
            pier = bg.kinematics[:, :, NODE_DOFS:]
            d += np.einsum('eai,ei->ea', pier, tops[0][bg.support])
            dv += np.einsum('eai,ei->ea', pier, tops[1][bg.support])
        force = bg.stiffness * d + bg.damping * dv
        np.add.at(out, (bg.support, bg.side), force)
        return out
    rg = structure.rigid
    assert rg is not None, 'a structure has either elastic bearings or rigid supports'
    reaction = rg.rows_k @ u + rg.rows_c @ v + rg.rows_m @ a - load_full[rg.full_dofs]
    on_support = -reaction
    e2 = structure.bearing_spacing
    comp = rg.component
    for c in (0, 1, 2):
        sel = comp == c
        np.add.at(out, (rg.support[sel], 0, c), 0.5 * on_support[sel])
        np.add.at(out, (rg.support[sel], 1, c), 0.5 * on_support[sel])
    sel = comp == 3
    np.add.at(out, (rg.support[sel], 0, 2), on_support[sel] / e2)
    np.add.at(out, (rg.support[sel], 1, 2), -on_support[sel] / e2)
    return out
