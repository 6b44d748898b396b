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
The mesh of the pier-cap-pile-soil block and what each of its cells is.

:func:`soil_grid` places the node planes of the layered block at every pile
face, pile tip, cap face and layer interface, graded away from the piles.
:func:`tag_cells` marks each grid cell soil, pile or cap (soil cells inside the
piles are replaced by pile cells, [P] section 2.4; the cap is solid cells on the
ground surface), with its material (layer index, then pile, then cap) and pile,
and drops the cells above ground outside the cap. :func:`split_interface`
duplicates the nodes on the pile shafts and tips for the Desai thin-layer
interface and returns its face pairs (with a ``bonded`` interface the nodes stay
shared). :func:`check_aspect` refuses a mesh of too elongated cells.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.fe.mesh import graded_planes, Grid, GridCells, HEX_FACES, Mesh
from ttb_sim.model.foundation.records import FoundationError, Substructure

#: Cell kinds.
SOIL, PILE, CAP = 0, 1, 2


def soil_grid(spec: Substructure) -> Grid:
    """Return the coordinate planes of the block's structured mesh."""
    soil, piles, cap, size = spec.soil, spec.piles, spec.cap, spec.mesh
    tops = soil.layer_tops()
    zkeys = tops + [-soil.depth]
    xkeys: list[float] = []
    ykeys: list[float] = []
    xzones: list[tuple[float, float]] = []
    yzones: list[tuple[float, float]] = []
    zzones: list[tuple[float, float]] = []
    zlimits: list[tuple[float, float, float]] = []
    top = 0.0
    if piles is not None:
        half = 0.5 * piles.width
        cx = sorted({c[0] for c in piles.centres()})
        cy = sorted({c[1] for c in piles.centres()})
        xkeys += [x + s for x in cx for s in (-half, half)]
        ykeys += [y + s for y in cy for s in (-half, half)]
        pad = 1.0
        xzones.append((cx[0] - half - pad, cx[-1] + half + pad))
        yzones.append((cy[0] - half - pad, cy[-1] + half + pad))
        zkeys.append(-piles.length)
        zzones += [(0.0, 0.0), (-piles.length, -piles.length)]
        zlimits.append((-piles.length, 0.0, size.shaft))
        if cap.enabled:
            xkeys += [-0.5 * cap.lx + piles.centre[0], 0.5 * cap.lx + piles.centre[0]]
            ykeys += [-0.5 * cap.ly + piles.centre[1], 0.5 * cap.ly + piles.centre[1]]
            top = cap.thickness
            zkeys.append(top)
            zlimits.append((0.0, top, size.shaft))
    xs = graded_planes(-0.5 * soil.lx, 0.5 * soil.lx, xkeys, xzones, size.h, size.growth,
                       size.h_max)
    ys = graded_planes(-0.5 * soil.ly, 0.5 * soil.ly, ykeys, yzones, size.h, size.growth,
                       size.h_max)
    zs = graded_planes(-soil.depth, top, zkeys, zzones, size.h, size.growth, size.h_max,
                       zlimits)
    return Grid(xs, ys, zs)


def planned_nodes(spec: Substructure) -> int:
    """Return the number of grid nodes the mesh of ``spec`` will have (cheap: planes only)."""
    nx, ny, nz = soil_grid(spec).shape
    return nx * ny * nz


def layer_of(z: np.ndarray, spec: Substructure) -> np.ndarray:
    """Return the index of the soil layer at heights ``z`` (clipped to the layers)."""
    tops = np.array(spec.soil.layer_tops())
    return np.clip(np.searchsorted(-tops, -z, side='right') - 1, 0, len(tops) - 1)


@dataclass(frozen=True)
class CellTags:
    """What each cell is: kind (SOIL, PILE, CAP), material, pile (-1: none), kept or not."""

    kind: np.ndarray
    material: np.ndarray
    """Layer index for soil, then ``n_layers`` for piles, ``n_layers + 1`` for the cap."""
    pile: np.ndarray
    keep: np.ndarray

    def kept(self) -> CellTags:
        """Return the tags of the kept cells only."""
        keep = self.keep
        return CellTags(self.kind[keep], self.material[keep], self.pile[keep],
                        np.ones(int(keep.sum()), dtype=bool))


def tag_cells(spec: Substructure, grid: Grid) -> CellTags:
    """Return the tags of every cell of ``grid``; the cells above ground but the cap's dropped."""
    soil, piles, cap = spec.soil, spec.piles, spec.cap
    centres = grid.cell_centres()
    n_layers = len(soil.layers)
    kind = np.full(len(centres), SOIL)
    material = layer_of(centres[:, 2], spec)
    pile_of = np.full(len(centres), -1)
    keep = centres[:, 2] < 0
    if piles is not None:
        half = 0.5 * piles.width
        for p, (x, y) in enumerate(piles.centres()):
            inside = ((np.abs(centres[:, 0] - x) < half) & (np.abs(centres[:, 1] - y) < half)
                      & (centres[:, 2] > -piles.length) & (centres[:, 2] < 0))
            pile_of[inside] = p
        kind[pile_of >= 0] = PILE
        material[pile_of >= 0] = n_layers
        if cap.enabled:
            on_cap = ((np.abs(centres[:, 0] - piles.centre[0]) < 0.5 * cap.lx)
                      & (np.abs(centres[:, 1] - piles.centre[1]) < 0.5 * cap.ly)
                      & (centres[:, 2] > 0))
            kind[on_cap] = CAP
            material[on_cap] = n_layers + 1
            keep |= on_cap
    return CellTags(kind, material, pile_of, keep)


@dataclass(frozen=True)
class InterfaceSplit:
    """
    The mesh with the pile-soil interface's nodes duplicated, and the interface's faces.

    Attributes
    ----------
    nodes : array, shape (n, 3)
        The mesh's nodes, then the copies of the nodes on the pile surfaces.
    cells : array of int, shape (m, 8)
        Node ids of each cell: pile and cap cells on the copies.
    faces_a, faces_b : arrays of int, shape (k, 4)
        The interface faces on the soil side (a) and on the pile side (b), in
        the same node order; b's normal points into the soil.
    face_layer : array of int, shape (k,)
        Soil layer of the soil cell of each face.

    """

    nodes: np.ndarray
    cells: np.ndarray
    faces_a: np.ndarray
    faces_b: np.ndarray
    face_layer: np.ndarray


def split_interface(spec: Substructure, cut: GridCells, tags: CellTags) -> InterfaceSplit:
    """
    Duplicate the nodes the pile cells share with soil cells (Desai interface only).

    Pile and cap cells move to the copies; each pile-cell face whose neighbour is
    a soil cell becomes an interface face pair. Without piles, or with a
    ``bonded`` interface, the mesh is returned as it is, with no faces.
    """
    nodes, cells = cut.nodes, cut.cells.copy()
    kind, material = tags.kind, tags.material
    none = np.zeros((0, 4), dtype=int)
    if spec.piles is None or spec.interface.model != 'desai':
        return InterfaceSplit(nodes, cells, none, none.copy(), np.zeros(0, dtype=int))
    n_soil_nodes = len(nodes)
    pile_nodes = np.unique(cells[kind == PILE])
    soil_nodes = np.unique(cells[kind == SOIL])
    shared = np.intersect1d(pile_nodes, soil_nodes)
    dup = np.arange(n_soil_nodes)
    dup[shared] = n_soil_nodes + np.arange(len(shared))
    original = cells.copy()
    structural = kind != SOIL
    cells[structural] = dup[cells[structural]]
    nodes = np.vstack([nodes, nodes[shared]])
    # interface faces: pile-cell faces whose neighbour is a soil cell
    pid = np.flatnonzero(kind == PILE)
    fa, fb, fl = [], [], []
    for f in range(len(HEX_FACES)):
        neighbour = cut.neighbours(pid, f)
        ok = neighbour >= 0
        ok[ok] = kind[neighbour[ok]] == SOIL
        sel = pid[ok]
        fb.append(cells[sel][:, HEX_FACES[f]])
        fa.append(original[sel][:, HEX_FACES[f]])
        fl.append(material[neighbour[ok]])
    return InterfaceSplit(nodes, cells, np.vstack(fa), np.vstack(fb), np.concatenate(fl))


def check_aspect(spec: Substructure, coordinates: np.ndarray,
                 material: np.ndarray) -> np.ndarray:
    """
    Return each cell's aspect ratio, checked against ``mesh.max_aspect``.

    Parameters
    ----------
    spec : Substructure
        The records (``mesh.max_aspect``).
    coordinates : array, shape (m, 8, 3)
        Corner coordinates of the cells (m).
    material : array of int, shape (m,)
        Material of each cell.

    Raises
    ------
    FoundationError
        If a cell's longest over shortest edge exceeds ``mesh.max_aspect``.

    """
    aspect = Mesh(coordinates.reshape(-1, 3), np.arange(8 * len(coordinates)).reshape(-1, 8),
                  material).aspect_ratios()
    if aspect.max() > spec.mesh.max_aspect:
        message = (f'the mesh has elements of aspect ratio {aspect.max():.3g} > '
                   f'soil.mesh.max_aspect = {spec.mesh.max_aspect:g}; lower soil.mesh.h_max '
                   f'or soil.mesh.h_shaft, or raise soil.mesh.h')
        raise FoundationError(message)
    return aspect
