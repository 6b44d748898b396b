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
The linear substructure U of one piled pier as the coupled model sees it.

A :class:`FoundationOperator` is what the train-track-bridge model (O) needs
of a pier-cap-pile-soil substructure: dense mass, damping and stiffness
matrices over generalised coordinates q, whose first six entries are the
physical pier-top DOFs (ux, uy, uz, rx, ry, rz in track axes, at the bearing
level, as a bridge pier-top node), and the rows that recover what sensors
record from q: pile-head displacements and soil-point displacements (apply to
q, or to its second derivative for accelerations).

How q is chosen is the builder's business: a pier column on springs
(:func:`spring_pier`, the ``springs`` foundation as a substructure, used to
check the coupling against the monolithic bridge), or the reduced 3-D
pile-soil model. The bridge attaches it through its bearings only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Optional

import numpy as np

from ttb_sim.fe.assembly import assemble
from ttb_sim.fe.beam import BeamSection, global_matrices, NODE_DOFS

TOP = np.arange(NODE_DOFS)
"""Indices of the pier-top DOFs in q (always the first six)."""


@dataclass(frozen=True)
class InterfaceRows:
    """
    The pile-soil interface of a linear substructure, at its Gauss points, from q.

    The reduced model keeps the Desai interface at its initial (geostatic)
    tangent; these rows give the tractions that tangent implies, and the
    Mohr-Coulomb strength they are to be compared with, so that a run can show
    the interface stayed in its initial, linear range (see
    :func:`~.reduction.interface_mobilisation`).

    Attributes
    ----------
    normal : array (g, n)
        Normal traction increment from the geostatic state (Pa, tension
        positive) at each of the g Gauss points, from q.
    shear : array (2 g, n)
        The two shear tractions (Pa) per Gauss point, point-major, from q.
    sigma_n0 : array (g,)
        Geostatic normal compression (Pa).
    cohesion, tan_delta : arrays (g,)
        Adhesion c (Pa) and friction coefficient tan(delta): the strength is
        c + (sigma_n0 - normal) tan(delta).

    """

    normal: np.ndarray
    shear: np.ndarray
    sigma_n0: np.ndarray
    cohesion: np.ndarray
    tan_delta: np.ndarray

    @property
    def n_points(self) -> int:
        """Number of Gauss points g."""
        return int(self.normal.shape[0])


@dataclass(frozen=True)
class FoundationOperator:
    """
    Dense linear model M q'' + C q' + K q = B f of one piled pier.

    Attributes
    ----------
    mass, damping, stiffness : arrays (n, n)
        Symmetric matrices over q; q[:6] are the pier-top DOFs (see :data:`TOP`).
    pile_heads : array (3 n_piles, n)
        Mean pile-head displacement (ux, uy, uz per pile, pile-major) from q.
    pile_positions : array (n_piles, 2)
        Plan position of each pile relative to the pier axis (m).
    soil_points : array (3 p, n)
        Displacement of each soil observation point from q.
    soil_point_names : tuple of str
    soil_point_positions : array (p, 3)
        Positions relative to the pier axis at the ground surface (m).
    depth : float
        Depth of the ground surface below the pier top (m): the pier height
        plus the cap thickness.
    summary : dict
        What the builder wants reported (DOF counts, reduction, accuracy).
    pile_rotations : array (3 n_piles, n) or None
        Rigid rotation of each pile head from q (apply to q' for the rate).
    interface : InterfaceRows or None
        Pile-soil interface tractions and strength from q (None: no interface).
    pile_strain : array (n_piles n_layers, n) or None
        Axial strain (tension positive) of each pile's element layers, head down, from q
        (:func:`~.observation.pile_strain_operator` through the reduction; None: no piles).
    pile_layer_depths : array (n_layers + 1,) or None
        Depths of the layers' planes below the pile heads (m), 0 first.

    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    pile_heads: np.ndarray
    pile_positions: np.ndarray
    soil_points: np.ndarray
    soil_point_names: tuple[str, ...]
    soil_point_positions: np.ndarray
    depth: float
    summary: dict[str, Any] = field(default_factory=dict)
    pile_rotations: np.ndarray | None = None
    interface: Optional[InterfaceRows] = None
    pile_strain: np.ndarray | None = None
    pile_layer_depths: np.ndarray | None = None

    @property
    def size(self) -> int:
        """Number of generalised coordinates n."""
        return int(self.mass.shape[0])

    @property
    def n_piles(self) -> int:
        """Number of piles observed."""
        return int(self.pile_positions.shape[0])


def pier_column(height: float, elements: int, section: BeamSection
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """
    Return the full (M, K, C=0) matrices of a vertical pier column, top node first.

    The column runs from the pier top (node 0, z = 0) down to its base (node
    ``elements``, z = -height); the matrices are dense over the 6 (elements + 1)
    node DOFs, with no supports.
    """
    z = -np.linspace(0.0, height, elements + 1)
    xyz = np.column_stack([np.zeros_like(z), np.zeros_like(z), z])
    conn = np.column_stack([np.arange(elements), np.arange(1, elements + 1)])
    ke, me, _ = global_matrices(xyz[conn[:, 0]], xyz[conn[:, 1]], section)
    n = NODE_DOFS * (elements + 1)
    edofs = (conn[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    return (assemble(n, edofs, me).toarray(), assemble(n, edofs, ke).toarray(),
            np.zeros((n, n)))


def spring_pier(height: float, elements: int, section: BeamSection,
                springs: np.ndarray, damping: np.ndarray,
                rayleigh: tuple[float, float] = (0.0, 0.0)) -> FoundationOperator:
    """
    Return a pier column on six foundation springs at its base as a substructure.

    This is the ``springs`` foundation of the bridge written as a
    :class:`FoundationOperator` (q = the column's node DOFs, top first): the
    coupled model with it must reproduce the monolithic spring-founded bridge.

    Parameters
    ----------
    height, elements, section
        The column.
    springs, damping : arrays (6,)
        Base spring stiffness and dashpot per DOF (ux, uy, uz, rx, ry, rz).
    rayleigh : (a0, a1)
        Rayleigh damping of the column, C = a0 M + a1 K (without the springs).

    """
    m, k, _ = pier_column(height, elements, section)
    c = rayleigh[0] * m + rayleigh[1] * k
    base = NODE_DOFS * elements + np.arange(NODE_DOFS)
    k[base, base] += springs
    c[base, base] += damping
    n = m.shape[0]
    return FoundationOperator(mass=m, damping=c, stiffness=k,
                              pile_heads=np.zeros((0, n)), pile_positions=np.zeros((0, 2)),
                              soil_points=np.zeros((0, n)), soil_point_names=(),
                              soil_point_positions=np.zeros((0, 3)), depth=height,
                              summary={'model': 'pier column on springs',
                                       'dofs': n})
