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
Hexahedral meshes: nodes, 8-node cells, named node, face and cell sets.

The node order of a cell is the usual one of the trilinear brick: nodes 0-3 on
the face zeta = -1 counter-clockwise seen from +zeta, nodes 4-7 above them.
Faces are stored as four node ids ordered so that (x1 - x0) x (x3 - x0) points
out of the cell they were taken from (:data:`HEX_FACES`).

:func:`structured_hex` builds a brick mesh from three sorted lists of
coordinate planes, :func:`grid_cells` the mesh of some of the cells of such a
grid (:class:`GridCells`: the nodes renumbered over the cells kept, optionally
periodic, with each cell's neighbours and outer faces), and
:func:`graded_planes` makes such lists: nodes at given coordinates, a size
``h`` inside given zones, growing by a factor per element away from them up to
``h_max``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import math
from typing import Sequence

import numpy as np

from ttb_sim.errors import FEError

#: Local node ids of the six faces of a hexahedron, outward oriented:
#: -x, +x, -y, +y, -z, +z.
HEX_FACES = np.array([[0, 4, 7, 3], [1, 2, 6, 5], [0, 1, 5, 4],
                      [3, 7, 6, 2], [0, 3, 2, 1], [4, 5, 6, 7]])

#: Names of the six faces of :data:`HEX_FACES`.
FACE_NAMES = ('xmin', 'xmax', 'ymin', 'ymax', 'zmin', 'zmax')

#: Step (di, dj, dk) from a cell of a grid to its neighbour across each face of
#: :data:`HEX_FACES`.
FACE_STEPS = ((-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1))

#: Grid offsets (di, dj, dk) of the eight nodes of a cell, in the node order of a cell.
CELL_CORNERS = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                         [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])


@dataclass
class Mesh:
    """
    A mesh of 8-node hexahedra.

    Attributes
    ----------
    nodes : array, shape (n, 3)
        Node coordinates (m).
    cells : array of int, shape (m, 8)
        Node ids of each cell.
    material : array of int, shape (m,)
        Material index of each cell.
    node_sets, face_sets, cell_sets : dict
        Named sets: node ids (k,), faces as node ids (k, 4), cell ids (k,).

    """

    nodes: np.ndarray
    cells: np.ndarray
    material: np.ndarray
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    face_sets: dict[str, np.ndarray] = field(default_factory=dict)
    cell_sets: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return int(len(self.nodes))

    @property
    def n_cells(self) -> int:
        """Number of cells."""
        return int(len(self.cells))

    def cell_coordinates(self, cells: np.ndarray | None = None) -> np.ndarray:
        """Return the node coordinates of cells, shape (m, 8, 3)."""
        c = self.cells if cells is None else self.cells[cells]
        return self.nodes[c]

    def cell_dofs(self, cells: np.ndarray | None = None) -> np.ndarray:
        """Return the 24 global DOFs (3 per node, x y z) of cells, shape (m, 24)."""
        c = self.cells if cells is None else self.cells[cells]
        return node_dofs(c)

    def aspect_ratios(self) -> np.ndarray:
        """Return each cell's longest over shortest edge, shape (m,)."""
        x = self.nodes[self.cells]
        edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4],
                          [0, 4], [1, 5], [2, 6], [3, 7]])
        lengths = np.linalg.norm(x[:, edges[:, 1]] - x[:, edges[:, 0]], axis=2)
        return lengths.max(axis=1) / lengths.min(axis=1)


def node_dofs(node_ids: np.ndarray) -> np.ndarray:
    """Return the DOFs (3 per node, x y z) of an array of node ids, last axis expanded."""
    node_ids = np.asarray(node_ids)
    d = 3 * node_ids[..., None] + np.arange(3)
    return d.reshape(node_ids.shape[:-1] + (3 * node_ids.shape[-1],)) \
        if node_ids.ndim > 1 else d.reshape(-1)


@dataclass(frozen=True)
class Grid:
    """
    The coordinate planes of a structured brick mesh.

    Node (i, j, k) has id ``i + nx (j + ny k)``; cell (i, j, k) has id
    ``i + (nx - 1) (j + (ny - 1) k)``.
    """

    xs: np.ndarray
    ys: np.ndarray
    zs: np.ndarray

    @property
    def shape(self) -> tuple[int, int, int]:
        """Number of nodes along x, y, z."""
        return len(self.xs), len(self.ys), len(self.zs)

    @property
    def cell_shape(self) -> tuple[int, int, int]:
        """Number of cells along x, y, z."""
        return len(self.xs) - 1, len(self.ys) - 1, len(self.zs) - 1

    def node_id(self, i: np.ndarray, j: np.ndarray, k: np.ndarray) -> np.ndarray:
        """Return the node id of index triples."""
        nx, ny, _ = self.shape
        return np.asarray(i) + nx * (np.asarray(j) + ny * np.asarray(k))

    def cell_id(self, i: np.ndarray, j: np.ndarray, k: np.ndarray) -> np.ndarray:
        """Return the cell id of index triples."""
        cx, cy, _ = self.cell_shape
        return np.asarray(i) + cx * (np.asarray(j) + cy * np.asarray(k))

    def cell_index(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return the (i, j, k) index of every cell, in cell-id order."""
        cx, cy, cz = self.cell_shape
        k, j, i = np.meshgrid(np.arange(cz), np.arange(cy), np.arange(cx), indexing='ij')
        return i.ravel(), j.ravel(), k.ravel()

    def cell_centres(self) -> np.ndarray:
        """Return the centre of every cell, shape (m, 3)."""
        i, j, k = self.cell_index()
        xc = 0.5 * (self.xs[1:] + self.xs[:-1])
        yc = 0.5 * (self.ys[1:] + self.ys[:-1])
        zc = 0.5 * (self.zs[1:] + self.zs[:-1])
        return np.column_stack([xc[i], yc[j], zc[k]])

    def locate(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Find the cell containing each point and the point's local coordinates.

        Returns
        -------
        (cell ids (p,), local coordinates in [-1, 1]^3 (p, 3)).

        Raises
        ------
        FEError
            If a point lies outside the grid.

        """
        points = np.atleast_2d(np.asarray(points, dtype=float))
        index = []
        local = []
        for axis, planes in enumerate((self.xs, self.ys, self.zs)):
            p = points[:, axis]
            tol = 1e-9 * (planes[-1] - planes[0])
            if np.any(p < planes[0] - tol) or np.any(p > planes[-1] + tol):
                message = (f'points {points.tolist()} lie outside the grid '
                           f'[{planes[0]:g}, {planes[-1]:g}] along axis {"xyz"[axis]}')
                raise FEError(message)
            i = np.clip(np.searchsorted(planes, p, side='right') - 1, 0, len(planes) - 2)
            index.append(i)
            local.append(2.0 * (p - planes[i]) / (planes[i + 1] - planes[i]) - 1.0)
        return self.cell_id(*index), np.column_stack(local)


def structured_hex(grid: Grid) -> Mesh:
    """
    Build the brick mesh of a grid, with face sets of its six outer faces.

    Node sets 'xmin' ... 'zmax' hold the nodes on each outer plane; face sets
    of the same names hold the outer faces, outward oriented.
    """
    nx, ny, nz = grid.shape
    z, y, x = np.meshgrid(grid.zs, grid.ys, grid.xs, indexing='ij')
    nodes = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    i, j, k = grid.cell_index()
    cells = grid.node_id(i[:, None] + CELL_CORNERS[:, 0], j[:, None] + CELL_CORNERS[:, 1],
                         k[:, None] + CELL_CORNERS[:, 2])
    mesh = Mesh(nodes, cells, np.zeros(len(cells), dtype=int))
    cx, cy, cz = grid.cell_shape
    on_face = (i == 0, i == cx - 1, j == 0, j == cy - 1, k == 0, k == cz - 1)
    node_index = np.unravel_index(np.arange(len(nodes)), (nz, ny, nx))
    node_on = (node_index[2] == 0, node_index[2] == nx - 1, node_index[1] == 0,
               node_index[1] == ny - 1, node_index[0] == 0, node_index[0] == nz - 1)
    for f, name in enumerate(FACE_NAMES):
        mesh.face_sets[name] = cells[on_face[f]][:, HEX_FACES[f]]
        mesh.node_sets[name] = np.flatnonzero(node_on[f])
    return mesh


@dataclass(frozen=True)
class GridCells:
    """
    Some of the cells of a :class:`Grid` as an unstructured mesh.

    Attributes
    ----------
    grid : Grid
        The grid the cells were taken from.
    nodes : array, shape (n, 3)
        Coordinates of the nodes the cells use (m), in grid-node order.
    cells : array of int, shape (m, 8)
        Node ids of each cell, in grid-cell order.
    coordinates : array, shape (m, 8, 3)
        Corner coordinates of each cell (m): ``nodes[cells]`` but for periodic
        ties, which join nodes without moving the cells' corners.
    index : tuple of three arrays of int, shape (m,)
        Grid index (i, j, k) of each cell.
    cell_map : array of int, shape (n_grid_cells,)
        Cell of each grid cell, -1 where the grid cell was dropped.

    """

    grid: Grid
    nodes: np.ndarray
    cells: np.ndarray
    coordinates: np.ndarray
    index: tuple[np.ndarray, np.ndarray, np.ndarray]
    cell_map: np.ndarray

    def on_outer_face(self, face: int) -> np.ndarray:
        """Return the mask of cells whose face ``face`` (:data:`HEX_FACES` order) is outside."""
        i, j, k = self.index
        cx, cy, cz = self.grid.cell_shape
        return (i == 0, i == cx - 1, j == 0, j == cy - 1, k == 0, k == cz - 1)[face]

    def neighbours(self, cells: np.ndarray, face: int) -> np.ndarray:
        """Return the cell across face ``face`` of each of ``cells``, -1 outside or dropped."""
        cx, cy, cz = self.grid.cell_shape
        di, dj, dk = FACE_STEPS[face]
        ci, cj, ck = self.index
        ni, nj, nk = ci[cells] + di, cj[cells] + dj, ck[cells] + dk
        inside = (ni >= 0) & (ni < cx) & (nj >= 0) & (nj < cy) & (nk >= 0) & (nk < cz)
        neighbour = np.full(len(cells), -1)
        neighbour[inside] = self.cell_map[self.grid.cell_id(ni[inside], nj[inside],
                                                            nk[inside])]
        return neighbour


def grid_cells(grid: Grid, keep: np.ndarray, periodic: bool = False) -> GridCells:
    """
    Return the cells of ``grid`` that ``keep`` selects, on the nodes they use.

    Parameters
    ----------
    grid : Grid
        The coordinate planes.
    keep : array of bool, shape (n_grid_cells,)
        The grid cells to keep, in grid-cell order.
    periodic : bool
        Tie the nodes of the last x and y planes to those of the first (a
        laterally periodic block); the cells' corner coordinates stay.

    """
    nx, ny, nz = grid.shape
    ci, cj, ck = grid.cell_index()
    ii = ci[:, None] + CELL_CORNERS[:, 0]
    jj = cj[:, None] + CELL_CORNERS[:, 1]
    kk = ck[:, None] + CELL_CORNERS[:, 2]
    zg, yg, xg = np.meshgrid(grid.zs, grid.ys, grid.xs, indexing='ij')
    all_xyz = np.column_stack([xg.ravel(), yg.ravel(), zg.ravel()])
    coordinates = all_xyz[grid.node_id(ii, jj, kk)[keep]]
    if periodic:
        ii = np.where(ii == nx - 1, 0, ii)
        jj = np.where(jj == ny - 1, 0, jj)
    structured_cells = grid.node_id(ii, jj, kk)
    kept = np.flatnonzero(keep)
    cell_map = np.full(len(ci), -1)
    cell_map[kept] = np.arange(len(kept))
    cells_s = structured_cells[kept]
    used = np.unique(cells_s)
    node_map = np.full(nx * ny * nz, -1)
    node_map[used] = np.arange(len(used))
    return GridCells(grid, all_xyz[used], node_map[cells_s], coordinates,
                     (ci[kept], cj[kept], ck[kept]), cell_map)


def graded_planes(start: float, stop: float, keys: Sequence[float],
                  zones: Sequence[tuple[float, float]], h: float, growth: float,
                  h_max: float,
                  limits: Sequence[tuple[float, float, float]] = ()) -> np.ndarray:
    """
    Return sorted coordinate planes on [start, stop] graded away from fine zones.

    The target element size is ``min(h_max, h + (growth - 1) d)``, d the
    distance to the nearest zone: the size of a sequence of elements growing by
    ``growth`` from ``h``. Between consecutive key coordinates (always planes)
    the planes equidistribute the integral of 1 / size, so each interval gets
    ``ceil`` of that many elements.

    Parameters
    ----------
    start, stop : float
        Ends of the line (m).
    keys : sequence of float
        Coordinates that must be planes (m); those outside [start, stop] are dropped.
    zones : sequence of (float, float)
        Intervals where the size is ``h`` (m).
    h, growth, h_max : float
        Fine size (m), growth factor per element (>= 1), largest size (m).
    limits : sequence of (float, float, float)
        Intervals (a, b) with a largest size there (m), e.g. along a pile shaft.

    """
    tol = 1e-9 * max(abs(stop - start), 1.0)
    fixed = np.unique(np.concatenate([[start, stop],
                                      [k for k in keys if start - tol <= k <= stop + tol]]))
    fixed = fixed[np.concatenate([[True], np.diff(fixed) > tol])]
    fixed[0], fixed[-1] = start, stop

    def size(x: np.ndarray) -> np.ndarray:
        d = np.full_like(x, np.inf)
        for a, b in zones:
            d = np.minimum(d, np.maximum(0.0, np.maximum(a - x, x - b)))
        s = np.where(np.isinf(d), h_max, np.minimum(h_max, h + (growth - 1.0) * np.where(
            np.isinf(d), 0.0, d)))
        for a, b, largest in limits:
            s = np.where((x >= a - tol) & (x <= b + tol), np.minimum(s, largest), s)
        return s

    planes = [fixed[:1]]
    for a, b in zip(fixed[:-1], fixed[1:]):
        s = np.linspace(a, b, 2001)
        inv = 1.0 / size(s)
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * np.diff(s))])
        n = max(1, math.ceil(cum[-1] - 1e-6))
        targets = np.linspace(0.0, cum[-1], n + 1)[1:]
        inner = np.interp(targets, cum, s)
        inner[-1] = b
        planes.append(inner)
    return np.concatenate(planes)
