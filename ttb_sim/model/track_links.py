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
The spring-dashpot links of the track: discrete fasteners and continuous layers.

A :class:`LinkSet` holds links between DOFs (rigid ground where a DOF is -1)
with the rows of their relative x, y, z motion and roll; :func:`node_link`
gives those rows for two nodes' arm tips (a fastener), :func:`layer`
integrates a continuous layer between two beam lines by Gauss quadrature.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.fe.assembly import link_kinematics
from ttb_sim.fe.beam import NODE_DOFS
from ttb_sim.model.beam_line import BeamLine

GAUSS_POINTS = 3
_GX, _GW = np.polynomial.legendre.leggauss(GAUSS_POINTS)


@dataclass(frozen=True)
class LinkSet:
    """
    Spring-dashpot links between DOFs: discrete fasteners or quadrature points of a layer.

    Attributes
    ----------
    dofs : numpy.ndarray
        (n, n_local) full DOFs; -1 stands for rigid ground.
    kinematics : numpy.ndarray
        (n, 4, n_local) rows of the relative x, y, z displacement and roll.
    stiffness, damping : numpy.ndarray
        (n, 4) per direction (N/m, N m/rad; N s/m, N m s/rad), quadrature
        weights included.

    """

    dofs: np.ndarray
    kinematics: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray


def node_dof_rows(nodes: np.ndarray) -> np.ndarray:
    """Return the full DOFs (n, 6) of nodes (n,)."""
    return nodes[:, None] * NODE_DOFS + np.arange(NODE_DOFS)


def node_link(arm_a: np.ndarray, arm_b: np.ndarray) -> np.ndarray:
    """Return (4, 12) rows of the relative motion and roll of two nodes' arm tips."""
    roll = np.zeros((1, 12))
    roll[0, 3], roll[0, 9] = 1.0, -1.0
    return np.concatenate([link_kinematics(arm_a, arm_b)[0], roll])


def layer(upper: BeamLine, arm: np.ndarray, lower: BeamLine, lower_arm: np.ndarray,
          stiffness: float, damping: float, width: float) -> LinkSet:
    """
    Integrate a continuous spring-dashpot layer under every element of ``upper``.

    The layer resists relative x, y, z motion with ``stiffness`` per metre of
    track (x assumed equal to y) and relative roll with stiffness * width^2 / 12
    (vertical springs spread over the width). Where ``lower`` has no element
    (beyond its ends, in its gaps), the layer rests on rigid ground.

    Returns
    -------
    LinkSet
        One link per quadrature point, over 24 DOFs (upper element, lower).

    """
    n_el = upper.start.size
    xi = np.tile(0.5 * (_GX + 1.0), n_el)
    element = np.repeat(np.arange(n_el), GAUSS_POINTS)
    weight = np.tile(0.5 * _GW, n_el) * upper.length[element]
    x = upper.start[element] + xi * upper.length[element]
    dofs_a, rows_a, _ = upper.link_rows(x, arm)
    dofs_b, rows_b, on = lower.link_rows(x, lower_arm)
    dofs = np.concatenate([dofs_a, np.where(on[:, None], dofs_b, -1)], axis=1)
    kin = np.concatenate([rows_a, -rows_b], axis=2)
    per_length = np.array([1.0, 1.0, 1.0, width**2 / 12.0])
    return LinkSet(dofs, kin, weight[:, None] * stiffness * per_length,
                   weight[:, None] * damping * per_length)
