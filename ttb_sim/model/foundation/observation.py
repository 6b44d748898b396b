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
The observation operators of the pile-soil substructure: pile heads, ground surface, soil points.

Pile-head displacement is the area-weighted mean over the head nodes (the
work-conjugate of a uniform head pressure), pile-head rotation a weighted
least-squares rigid fit, the piles' axial strain the difference of such means
over each layer of their bricks; the ground surface carries tributary areas for
uniform surface loads; soil points interpolate trilinearly in the containing
cell.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import FEError
from ttb_sim.fe import hex8
from ttb_sim.fe.assembly import skew
from ttb_sim.fe.mesh import GridCells, HEX_FACES, node_dofs
from ttb_sim.fe.quad import face_frames, FACE_N
from ttb_sim.model.foundation.records import FoundationError, Substructure
from ttb_sim.model.foundation.soil_mesh import CAP

#: Local face of a cell on its top (+z), and on its bottom (-z).
_TOP = 5
_BOTTOM = 4


@dataclass(frozen=True)
class SoilPoints:
    """Soil observation points: positions (p, 3) m, names, interpolation (3p x n_dofs)."""

    positions: np.ndarray
    names: tuple[str, ...]
    operator: sp.csr_matrix


def _on_ground(cut: GridCells) -> np.ndarray:
    """Return the mask of cells whose top face lies on the ground surface z = 0."""
    return np.abs(cut.grid.zs[cut.index[2] + 1]) < 1e-9


def _tributary(faces: np.ndarray, weights: np.ndarray, n_nodes: int) -> np.ndarray:
    """Return the tributary area int N_a dA of each node over faces (n_nodes,) (m^2)."""
    return np.bincount(faces.ravel(), weights=np.einsum('ga,eg->ea', FACE_N, weights).ravel(),
                       minlength=n_nodes)


def _head_rows(nodes: np.ndarray, w: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return the head nodes, their normalised weights and the (3, k, 3) rigid-rotation fit."""
    head = np.flatnonzero(w)
    wn = w[head] / w[head].sum()
    r = nodes[head] - wn @ nodes[head]
    inertia = np.einsum('a,a->', wn, (r**2).sum(1)) * np.eye(3) - np.einsum('a,ai,aj->ij',
                                                                            wn, r, r)
    op = np.einsum('ij,a,ajk->iak', np.linalg.inv(inertia), wn, skew(r))
    return head, wn, op


def head_operators(n_piles: int, cut: GridCells, cells: np.ndarray, nodes: np.ndarray,
                   pile: np.ndarray, n_dofs: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """
    Return the pile-head mean displacement and rigid rotation operators (3 n_piles, n_dofs).

    Rows are (pile, axis). The head of a pile is the top face of its cells on the
    ground surface; ``cells`` and ``nodes`` are the mesh's (interface copies
    included), ``pile`` the pile of each cell (-1: none).
    """
    rows_d, cols_d, vals_d = [], [], []
    rows_r, cols_r, vals_r = [], [], []
    on_ground = _on_ground(cut)
    for p in range(n_piles):
        sel = np.flatnonzero((pile == p) & on_ground)
        faces = cells[sel][:, HEX_FACES[_TOP]]
        _, weights = face_frames(nodes[faces])
        head, wn, op = _head_rows(nodes, _tributary(faces, weights, len(nodes)))
        for axis in range(3):
            rows_d.append(np.full(len(head), 3 * p + axis))
            cols_d.append(3 * head + axis)
            vals_d.append(wn)
        for axis in range(3):
            rows_r.append(np.full(3 * len(head), 3 * p + axis))
            cols_r.append(node_dofs(head[:, None]).ravel())
            vals_r.append(op[axis].ravel())
    shape = (3 * n_piles, n_dofs)

    def op_matrix(r: list, c: list, v: list) -> sp.csr_matrix:
        if not r:
            return sp.csr_matrix(shape)
        return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                             shape=shape)

    return op_matrix(rows_d, cols_d, vals_d), op_matrix(rows_r, cols_r, vals_r)


def pile_strain_operator(n_piles: int, cut: GridCells, cells: np.ndarray, nodes: np.ndarray,
                         pile: np.ndarray, n_dofs: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """
    Return the piles' axial strain per element layer and the depths of the layers' planes.

    Row ``pile * n_layers + layer`` (layers from the head down) is the cross-section mean
    of eps_zz = du_z/dz over that layer of the pile's bricks: the area-weighted mean
    vertical displacement of its top face less that of its bottom face, over the layer's
    height (exact for trilinear bricks, whose du_z/dz does not vary along z; tension
    positive). ``depths`` (n_layers + 1,) are the planes below the ground surface (the
    pile head), 0 first (m). Piles of one group share their planes.
    """
    kz = cut.index[2]
    layers = np.unique(kz[pile >= 0])[::-1]   # top down (grid z rises with k)
    zs = cut.grid.zs
    depths = 0.0 - np.concatenate([zs[layers[:1] + 1], zs[layers]]) if layers.size \
        else np.zeros(1)
    rows, cols, vals = [], [], []
    for p in range(n_piles):
        for n, k in enumerate(layers):
            sel = np.flatnonzero((pile == p) & (kz == k))
            height = zs[k + 1] - zs[k]
            for face, sign in ((_TOP, 1.0), (_BOTTOM, -1.0)):
                faces = cells[sel][:, HEX_FACES[face]]
                _, weights = face_frames(nodes[faces])
                w = _tributary(faces, weights, len(nodes))
                at = np.flatnonzero(w)
                rows.append(np.full(len(at), p * len(layers) + n))
                cols.append(3 * at + 2)
                vals.append(sign * w[at] / (w[at].sum() * height))
    shape = (n_piles * len(layers), n_dofs)
    if not rows:
        return sp.csr_matrix(shape), depths
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=shape), depths


def gauge_rows(strain: np.ndarray | sp.csr_matrix, depths: np.ndarray,
               gauges: Sequence[tuple[int, float]]) -> np.ndarray | sp.csr_matrix:
    """
    Return the rows of :func:`pile_strain_operator` (or their reduction) the gauges read.

    ``gauges`` are (pile, 0-based; depth below the head, m): each reads the layer of
    bricks whose planes enclose its depth, the lower one at a plane (the first layer at
    the head, the last at the tip).

    Raises
    ------
    FoundationError
        For a pile not in the group or a depth below the pile tip.

    """
    n_layers = len(depths) - 1
    n_piles = strain.shape[0] // max(n_layers, 1)
    index = []
    for pile, depth in gauges:
        if not 0 <= pile < n_piles:
            raise FoundationError(f'pile {pile + 1} does not exist; the group has {n_piles} '
                                  f'(1 to {n_piles})')
        if not 0.0 <= depth <= depths[-1] * (1 + 1e-9):
            raise FoundationError(f'depth {depth:g} m is off the pile; allowed 0 to '
                                  f'{depths[-1]:g} m below the head (piles.length)')
        layer = int(np.searchsorted(depths, depth, side='right')) - 1
        index.append(pile * n_layers + min(max(layer, 0), n_layers - 1))
    return strain[np.asarray(index, dtype=np.intp)]


def surface_weights(cut: GridCells, kind: np.ndarray, cells: np.ndarray,
                    n_nodes: int) -> np.ndarray:
    """Return the tributary area of the ground-surface nodes outside the cap (n_nodes,) (m^2)."""
    top_cells = np.flatnonzero(_on_ground(cut) & (kind != CAP))
    faces = cells[top_cells][:, HEX_FACES[_TOP]]
    _, weights = face_frames(cut.coordinates[top_cells][:, HEX_FACES[_TOP]])
    return _tributary(faces, weights, n_nodes)


def cap_top_weights(nodes: np.ndarray, cells: np.ndarray, kind: np.ndarray,
                    top: float) -> np.ndarray:
    """Return the tributary area of the cap-top nodes (z = ``top``), shape (n_nodes,) (m^2)."""
    faces = cells[kind == CAP][:, HEX_FACES[_TOP]]
    faces = faces[np.all(np.abs(nodes[faces][..., 2] - top) <= 1e-9 * max(1.0, top), axis=1)]
    if len(faces) == 0:
        return np.zeros(len(nodes))
    _, weights = face_frames(nodes[faces])
    return _tributary(faces, weights, len(nodes))


def _positions(spec: Substructure) -> tuple[list[tuple[float, float, float]], list[str]]:
    """Return the positions and names of the soil points ``spec.observation`` asks for."""
    obs, piles = spec.observation, spec.piles
    positions: list[tuple[float, float, float]] = []
    names: list[str] = []
    if piles is not None:
        centres = piles.centres()
        if obs.line_points > 0:
            y = centres[0][1] + 0.5 * piles.spacing
            x0 = centres[0][0] - 0.5 * piles.spacing
            x1 = centres[piles.cols - 1][0] + 0.5 * piles.spacing
            for n, x in enumerate(np.linspace(x0, x1, obs.line_points)):
                positions.append((float(x), y, 0.0))
                names.append(f'line_{n + 1:02d}')
        if obs.val_points and piles.count >= 14:
            off = 0.5 * piles.width + 1.0
            a = (centres[4][0], centres[4][1] - off, 0.0)
            b = (centres[13][0], centres[13][1] + off, 0.0)
            mid = tuple(0.5 * (p + q) for p, q in zip(a, b))
            positions += [a, b, mid]  # type: ignore[list-item]
            names += ['val_1', 'val_2', 'val_3']
    for n, point in enumerate(obs.points):
        positions.append(tuple(float(v) for v in point))  # type: ignore[arg-type]
        names.append(f'user_{n + 1:02d}')
    if obs.grid_spacing > 0 and piles is not None:
        grid, grid_names = ground_grid(spec)
        positions += [tuple(float(v) for v in p) for p in grid]  # type: ignore[misc]
        names += grid_names
    return positions, names


def ground_grid(spec: Substructure) -> tuple[np.ndarray, list[str]]:
    """
    Return the ground-surface grid of ``spec.observation`` (positions (p, 3), names).

    The grid covers the cap's footprint (the pile group's outer faces without a
    cap) plus the margin on every side, centred on the group, with points at
    most ``grid_spacing`` apart and on both edges; named ``grid_RR_CC`` (row
    along y, column along x, 1-based, x fastest).
    """
    obs, piles = spec.observation, spec.piles
    assert piles is not None
    if spec.cap.enabled:
        half = (0.5 * spec.cap.lx, 0.5 * spec.cap.ly)
    else:
        half = (0.5 * ((piles.cols - 1) * piles.spacing + piles.width),
                0.5 * ((piles.rows - 1) * piles.spacing + piles.width))
    axes = []
    for centre, h in zip(piles.centre, half):
        extent = h + obs.grid_margin
        count = int(np.ceil(2 * extent / obs.grid_spacing - 1e-9)) + 1
        axes.append(np.linspace(centre - extent, centre + extent, count))
    x, y = np.meshgrid(*axes)
    positions = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    names = [f'grid_{r + 1:02d}_{c + 1:02d}' for r in range(len(axes[1]))
             for c in range(len(axes[0]))]
    return positions, names


def soil_points(spec: Substructure, cut: GridCells, cells: np.ndarray,
                n_dofs: int) -> SoilPoints:
    """
    Return the soil observation points and their trilinear interpolation.

    Raises
    ------
    FoundationError
        If a point lies outside the modelled solid.

    """
    positions, names = _positions(spec)
    if not positions:
        return SoilPoints(np.zeros((0, 3)), (), sp.csr_matrix((0, n_dofs)))
    pos = np.array(positions, dtype=float)
    grid, cell_map = cut.grid, cut.cell_map
    try:
        structured, local = grid.locate(pos)
    except FEError as err:
        raise FoundationError(f'output.soil_points: {err}') from None
    cell = cell_map[structured]
    # a point on the ground outside the cap falls in a dropped cell above: take the one below
    cx, cy, _ = grid.cell_shape
    below = (cell < 0) & (local[:, 2] <= -1 + 1e-9)
    if np.any(below):
        cell[below] = cell_map[structured[below] - cx * cy]
        local[below, 2] = 1.0
    if np.any(cell < 0):
        bad = pos[cell < 0].tolist()
        raise FoundationError(f'output.soil_points {bad} lie outside the modelled solid')
    shape = hex8.shape_functions(local)
    node_ids = cells[cell]
    rows = (3 * np.arange(len(pos))[:, None, None] + np.arange(3)[None, None, :])
    rows = np.broadcast_to(rows, (len(pos), 8, 3))
    cols = 3 * node_ids[:, :, None] + np.arange(3)
    vals = np.broadcast_to(shape[:, :, None], (len(pos), 8, 3))
    op = sp.csr_matrix((vals.ravel(), (rows.ravel(), cols.ravel())), shape=(3 * len(pos),
                                                                            n_dofs))
    return SoilPoints(pos, tuple(names), op)
