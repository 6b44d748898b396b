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
The mirror-symmetry classes of a tied piled pier's master components.

A group centred in a block symmetric about x = 0 and y = 0 splits the
master's six components into classes of one parity each (uz; ux with ry; uy
with rx; rz). The response to a class's loads lies in the class's part of the
unknowns (:func:`ttb_sim.fe.symmetry.mirror_reduction`), about a quarter of
them, so each class is solved on its own: exactly, and at a fraction of the
whole system's cost. The frequency-domain reference
(:mod:`.master_response`) and the reduction basis (:mod:`.krylov`) both use
these classes.
"""

from __future__ import annotations

import logging
from typing import Literal, Sequence

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe.symmetry import has_parity, mirror_nodes, mirror_reduction, MirrorPlane
from ttb_sim.model.foundation.substructure import PileSoilModel

__all__ = ['class_coordinates', 'invariant', 'symmetry_classes']

log = logging.getLogger(__name__)

Classes = list[tuple[tuple[int, ...], tuple[MirrorPlane, ...]]]


def symmetry_classes(model: PileSoilModel, transform: sp.csr_matrix) -> Classes:
    """
    Group the master components by their mirror parities: [(components, planes)].

    A component's unit motion (a column of the tie ``transform``) is a nodal
    field; a plane of the mesh's symmetry is used for the class when that field
    has one of its two parities there.
    """
    mesh = model.mesh
    images: dict[Literal['x', 'y'], np.ndarray] = {}
    if not model.spec.soil.periodic:
        axes: tuple[Literal['x', 'y'], ...] = ('x', 'y')
        for axis in axes:
            try:
                images[axis] = mirror_nodes(mesh.nodes, mesh.cells, mesh.material, axis)
            except FEError as exc:  # not a symmetric mesh
                log.debug('no mirror about %s = 0: %s', axis, exc)
    groups: dict[tuple[MirrorPlane, ...], list[int]] = {}
    for j in range(6):
        motion = transform[:, j].toarray().ravel()
        planes = []
        for axis, image in images.items():
            for parity in ('symmetric', 'antisymmetric'):
                plane = MirrorPlane(axis, parity)
                if has_parity(motion, image, plane):
                    planes.append(plane)
                    break
        groups.setdefault(tuple(planes), []).append(j)
    return [(tuple(comps), planes) for planes, comps in groups.items()]


def class_coordinates(model: PileSoilModel, kept: np.ndarray, components: Sequence[int],
                      planes: tuple[MirrorPlane, ...]) -> sp.csr_matrix:
    """
    Return P (n_x x n): the tie's coordinates from [the class's components, its interior].

    The tie's coordinates are x = [master (6), the free DOFs ``kept`` off the
    cap top] (:func:`~.tied.cap_tie`); the interior part is their mirror
    reduction (one ±1 per row, disjoint columns).
    """
    mesh = model.mesh
    if planes:
        t = mirror_reduction(mesh.nodes, mesh.cells, mesh.material, planes)[kept].tocsc()
        t = t[:, np.flatnonzero(np.diff(t.indptr) > 0)]
    else:
        t = sp.identity(len(kept), format='csc')
    k = len(components)
    pick = sp.csr_matrix((np.ones(k), (np.asarray(components), np.arange(k))), shape=(6, k))
    return sp.block_diag([pick, t]).tocsr()


def invariant(matrices: Sequence[sp.spmatrix], coordinates: sp.csr_matrix,
              seed: int = 0, tolerance: float = 1e-10) -> bool:
    """
    Return whether every matrix maps the class's part of the unknowns into itself.

    The check the class split rests on: A P y, for a random y, must equal its
    own projection P (P^T P)^-1 P^T A P y onto the class (P^T P is diagonal,
    the columns having disjoint supports). A model whose stiffness, damping or
    mass breaks the mirror (an asymmetric material or interface state) fails it.
    """
    p = coordinates
    y = np.random.default_rng(seed).standard_normal(p.shape[1])
    counts = np.asarray(p.multiply(p).sum(axis=0)).ravel()
    for a in matrices:
        z = a @ (p @ y)
        back = p @ ((p.T @ z) / counts)
        if np.linalg.norm(z - back) > tolerance * max(float(np.linalg.norm(z)), 1e-300):
            return False
    return True
