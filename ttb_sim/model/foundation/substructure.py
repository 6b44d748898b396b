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
The 3-D pier-cap-pile-soil substructure assembled from its records.

:func:`build` turns a :class:`~.records.Substructure` into a
:class:`PileSoilModel`: a structured brick mesh of the layered block with node
planes at every pile face, pile tip, cap face and layer interface; soil cells
inside the piles replaced by pile cells ([P] section 2.4); the cap as solid
cells on the ground surface, sharing nodes with the pile heads and the soil
surface under it; the pile-soil interface as Desai thin-layer elements between
duplicated nodes on the pile shafts and tips, or shared nodes (``bonded``);
the viscous-spring, dashpot or fixed boundary on the sides and base.

The model keeps the *linear* operators (lumped mass, soil and structure
stiffness and Rayleigh damping, boundary springs and dashpots) apart from the
interface (:class:`~ttb_sim.fe.interface.InterfaceSet` plus its
:class:`~.desai.DesaiLaw`), so that a reduced-order model can later replace
the linear part behind the same attributes. It also holds the observation
operators: pile-head displacement (area-weighted mean over the head nodes, the
work-conjugate of a uniform head pressure), pile-head rotation (weighted
least-squares rigid fit) and soil points (trilinear interpolation in the
containing cell).

Damping: Rayleigh C = alpha M + beta K per material, with each material's
damping ratio at the two ``rayleigh_frequencies``. Interface initial stress:
geostatic, sigma_v = sum rho g h above the point (total stress, no water
table), K0 sigma_v on the shafts (Jaky's K0 = 1 - sin(phi) unless given) and
sigma_v under the tips.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import logging
import math
from typing import Optional

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe import hex8
from ttb_sim.fe.assembly import assemble, assemble_chunked
from ttb_sim.fe.boundary import face_matrices, viscoelastic_coefficients
from ttb_sim.fe.interface import interface_set, InterfaceSet
from ttb_sim.fe.mesh import graded_planes, Grid, HEX_FACES, Mesh, node_dofs
from ttb_sim.fe.quad import face_frames, FACE_N
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.foundation.desai import DesaiLaw, initial_moduli
from ttb_sim.model.foundation.records import (check_substructure, FoundationError, PileLoad,
                                              Substructure)

LOG = logging.getLogger(__name__)

#: Cell kinds.
SOIL, PILE, CAP = 0, 1, 2


@dataclass(frozen=True)
class SoilPoints:
    """Soil observation points: positions (p, 3) m, names, interpolation (3p x n_dofs)."""

    positions: np.ndarray
    names: tuple[str, ...]
    operator: sp.csr_matrix


@dataclass
class PileSoilModel:
    """
    The assembled substructure (see the module docstring).

    Attributes
    ----------
    spec : Substructure
        The records it was built from.
    grid : Grid
        Coordinate planes of the structured mesh.
    mesh : Mesh
        Nodes and cells (material = layer index, then pile, then cap); cell
        sets 'soil', 'pile', 'cap'.
    cell_kind : array of int
        SOIL, PILE or CAP per cell.
    free : array of bool, shape (n_dofs,)
        DOFs not fixed by the boundary.
    mass : array, shape (n_dofs,)
        Lumped mass (kg).
    soil_stiffness, soil_damping, structure_stiffness, structure_damping : csr
        Linear operators of the soil cells and of the pile and cap cells.
    boundary_stiffness, boundary_damping : csr
        Boundary springs and dashpots.
    interface : InterfaceSet or None
        Desai elements (None when bonded or without piles).
    law : DesaiLaw or None
        Interface law, arrays shaped (k, 4) per Gauss point.
    structure_dofs : array of bool
        DOFs of pile and cap cells.
    head_displacement, head_rotation : csr, shape (3 n_piles, n_dofs)
        Pile-head mean displacement (apply to u, a) and rigid rotation (apply
        to u, or to v for the rotation rate), rows (pile, axis).
    surface_weights : array, shape (n_nodes,)
        Tributary area of the ground-surface nodes (m^2).
    soil_points : SoilPoints
        Observation points in the soil.
    summary : dict
        DOF and cell counts, element sizes, highest frequency carried.

    """

    spec: Substructure
    grid: Grid
    mesh: Mesh
    cell_kind: np.ndarray
    free: np.ndarray
    mass: np.ndarray
    soil_stiffness: sp.csr_matrix
    soil_damping: sp.csr_matrix
    structure_stiffness: sp.csr_matrix
    structure_damping: sp.csr_matrix
    boundary_stiffness: sp.csr_matrix
    boundary_damping: sp.csr_matrix
    interface: Optional[InterfaceSet]
    law: Optional[DesaiLaw]
    structure_dofs: np.ndarray
    head_displacement: sp.csr_matrix
    head_rotation: sp.csr_matrix
    surface_weights: np.ndarray
    soil_points: SoilPoints
    summary: dict = field(default_factory=dict)

    @property
    def n_dofs(self) -> int:
        """Number of DOFs (3 per node)."""
        return 3 * self.mesh.n_nodes

    @property
    def n_piles(self) -> int:
        """Number of piles."""
        return self.head_displacement.shape[0] // 3

    def linear_stiffness(self) -> sp.csr_matrix:
        """Return soil + structure + boundary stiffness (interface excluded)."""
        return (self.soil_stiffness + self.structure_stiffness
                + self.boundary_stiffness).tocsr()

    def linear_damping(self) -> sp.csr_matrix:
        """Return soil + structure + boundary damping."""
        return (self.soil_damping + self.structure_damping + self.boundary_damping).tocsr()

    def initial_interface_stiffness(self) -> sp.csr_matrix:
        """Return the interface tangent at the geostatic state (zero matrix if none)."""
        if self.interface is None or self.law is None:
            return sp.csr_matrix((self.n_dofs, self.n_dofs))
        return self.interface.stiffness(self.law.initial_tangent())

    def load_vector(self, load: PileLoad) -> np.ndarray:
        """
        Return the nodal force vector of a unit-factor load (N).

        A pile load is a uniform pressure on the pile head of total force
        ``load.amplitude`` (nodal forces proportional to the tributary areas,
        i.e. the transpose of the head-displacement operator times the force);
        a surface load is a uniform pressure on the whole ground surface.
        """
        axis = 'xyz'.index(load.direction)
        if load.target == 'pile':
            row = 3 * (load.pile - 1) + axis
            f = np.asarray(self.head_displacement[row].toarray()).ravel()
            return load.amplitude * f
        f = np.zeros(self.n_dofs)
        f[axis::3] = load.amplitude * self.surface_weights / self.surface_weights.sum()
        return f


def rayleigh_coefficients(damping_ratio: np.ndarray,
                          frequencies: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """Return Rayleigh (alpha, beta) giving ``damping_ratio`` at both frequencies (Hz)."""
    w1, w2 = (2 * math.pi * f for f in frequencies)
    zeta = np.asarray(damping_ratio, dtype=float)
    return 2 * zeta * w1 * w2 / (w1 + w2), 2 * zeta / (w1 + w2)


def _planes(spec: Substructure) -> Grid:
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


def _layer_of(z: np.ndarray, spec: Substructure) -> np.ndarray:
    tops = np.array(spec.soil.layer_tops())
    return np.clip(np.searchsorted(-tops, -z, side='right') - 1, 0, len(tops) - 1)


def vertical_stress(z: np.ndarray, spec: Substructure) -> np.ndarray:
    """Return the geostatic total vertical stress at depth -z (Pa, compression positive)."""
    z = np.minimum(np.asarray(z, dtype=float), 0.0)
    out = np.zeros_like(z)
    top = 0.0
    for layer in spec.soil.layers:
        bottom = top - layer.thickness
        inside = np.clip(top - z, 0.0, layer.thickness)
        out += layer.rho * GRAVITY * inside
        top = bottom
    return out


def planned_nodes(spec: Substructure) -> int:
    """Return the number of grid nodes the mesh of ``spec`` will have (cheap: planes only)."""
    nx, ny, nz = _planes(spec).shape
    return nx * ny * nz


def build(spec: Substructure, load: Optional[PileLoad] = None) -> PileSoilModel:
    """
    Build the substructure of ``spec`` (and check it against ``load`` if given).

    Raises
    ------
    FoundationError
        On inconsistent records (see :func:`~.records.check_substructure`) or a
        mesh whose aspect ratio exceeds ``mesh.max_aspect``.

    """
    check_substructure(spec, load)
    soil, piles, cap = spec.soil, spec.piles, spec.cap
    grid = _planes(spec)
    nx, ny, nz = grid.shape
    ci, cj, ck = grid.cell_index()
    centres = grid.cell_centres()
    n_layers = len(soil.layers)
    kind = np.full(len(centres), SOIL)
    material = _layer_of(centres[:, 2], spec)
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
    # structured node ids of every cell, then periodic ties and node renumbering
    corner = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                       [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
    ii = ci[:, None] + corner[:, 0]
    jj = cj[:, None] + corner[:, 1]
    kk = ck[:, None] + corner[:, 2]
    zg, yg, xg = np.meshgrid(grid.zs, grid.ys, grid.xs, indexing='ij')
    all_xyz = np.column_stack([xg.ravel(), yg.ravel(), zg.ravel()])
    cell_xyz = all_xyz[grid.node_id(ii, jj, kk)[keep]]
    if soil.periodic:
        ii = np.where(ii == nx - 1, 0, ii)
        jj = np.where(jj == ny - 1, 0, jj)
    structured_cells = grid.node_id(ii, jj, kk)
    kept = np.flatnonzero(keep)
    cell_map = np.full(len(centres), -1)
    cell_map[kept] = np.arange(len(kept))
    cells_s = structured_cells[kept]
    used = np.unique(cells_s)
    node_map = np.full(nx * ny * nz, -1)
    node_map[used] = np.arange(len(used))
    cells = node_map[cells_s]
    nodes = all_xyz[used]
    kind = kind[kept]
    material = material[kept]
    pile_of = pile_of[kept]
    ci, cj, ck = ci[kept], cj[kept], ck[kept]
    n_soil_nodes = len(nodes)

    # duplicate the nodes on the pile surfaces for the Desai interface
    faces_a = np.zeros((0, 4), dtype=int)
    faces_b = np.zeros((0, 4), dtype=int)
    face_layer = np.zeros(0, dtype=int)
    if piles is not None and spec.interface.model == 'desai':
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
        cx, cy, cz = grid.cell_shape
        steps = [(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, -1), (0, 0, 1)]
        pid = np.flatnonzero(kind == PILE)
        fa, fb, fl = [], [], []
        for f, (di, dj, dk) in enumerate(steps):
            ni, nj, nk = ci[pid] + di, cj[pid] + dj, ck[pid] + dk
            inside = (ni >= 0) & (ni < cx) & (nj >= 0) & (nj < cy) & (nk >= 0) & (nk < cz)
            neighbour = np.full(len(pid), -1)
            neighbour[inside] = cell_map[grid.cell_id(ni[inside], nj[inside], nk[inside])]
            ok = neighbour >= 0
            ok[ok] = kind[neighbour[ok]] == SOIL
            sel = pid[ok]
            fb.append(cells[sel][:, HEX_FACES[f]])
            fa.append(original[sel][:, HEX_FACES[f]])
            fl.append(material[neighbour[ok]])
        faces_a = np.vstack(fa)
        faces_b = np.vstack(fb)
        face_layer = np.concatenate(fl)

    mesh = Mesh(nodes, cells, material)
    mesh.cell_sets = {'soil': np.flatnonzero(kind == SOIL), 'pile': np.flatnonzero(kind == PILE),
                      'cap': np.flatnonzero(kind == CAP)}
    n_dofs = 3 * len(nodes)
    aspect = Mesh(cell_xyz.reshape(-1, 3), np.arange(8 * len(cells)).reshape(-1, 8),
                  material).aspect_ratios()
    if aspect.max() > spec.mesh.max_aspect:
        message = (f'the mesh has elements of aspect ratio {aspect.max():.3g} > '
                   f'soil.mesh.max_aspect = {spec.mesh.max_aspect:g}; lower soil.mesh.h_max '
                   f'or soil.mesh.h_shaft, or raise soil.mesh.h')
        raise FoundationError(message)

    # materials
    young = np.array([lay.E for lay in soil.layers] + [piles.E if piles else 1.0, cap.E])
    poisson = np.array([lay.nu for lay in soil.layers] + [piles.nu if piles else 0.0, cap.nu])
    density = np.array([lay.rho for lay in soil.layers] + [piles.rho if piles else 1.0, cap.rho])
    zeta = np.array([lay.damping_ratio for lay in soil.layers]
                    + [piles.damping_ratio if piles else 0.0, cap.damping_ratio])
    alpha, beta = rayleigh_coefficients(zeta, spec.rayleigh_frequencies)
    dofs = node_dofs(cells)
    coords = cell_xyz
    lumped = hex8.lumped_mass(coords, density[material])
    mass = np.bincount(np.repeat(cells.ravel(), 3) * 3 + np.tile(np.arange(3), cells.size),
                       weights=np.repeat(lumped.ravel(), 3), minlength=n_dofs)

    def group(sel: np.ndarray) -> tuple[sp.csr_matrix, sp.csr_matrix]:
        if len(sel) == 0:
            z = sp.csr_matrix((n_dofs, n_dofs))
            return z, z

        def kernel(ids: np.ndarray) -> np.ndarray:
            e = sel[ids]
            k = hex8.stiffness(coords[e], young[material[e]], poisson[material[e]])
            return k * (1.0 + 1j * beta[material[e]])[:, None, None]

        both = assemble_chunked(n_dofs, dofs[sel], kernel, dtype=complex)
        stiff = sp.csr_matrix((both.data.real.copy(), both.indices, both.indptr),
                              shape=both.shape)
        m_alpha = np.bincount(dofs[sel].ravel(),
                              weights=np.repeat(lumped[sel] * alpha[material[sel]][:, None],
                                                3, axis=1).ravel(), minlength=n_dofs)
        damp = sp.csr_matrix((both.data.imag.copy(), both.indices, both.indptr),
                             shape=both.shape) + sp.diags(m_alpha)
        return stiff, damp.tocsr()

    k_soil, c_soil = group(np.flatnonzero(kind == SOIL))
    k_str, c_str = group(np.flatnonzero(kind != SOIL))
    structure_dofs = np.zeros(n_dofs, dtype=bool)
    structure_dofs[dofs[kind != SOIL].ravel()] = True

    # boundary
    source = np.array([piles.centre[0], piles.centre[1], 0.0]) if piles else np.zeros(3)
    cx, cy, cz = grid.cell_shape
    outer = [('xmin', ci == 0, 0), ('xmax', ci == cx - 1, 1), ('ymin', cj == 0, 2),
             ('ymax', cj == cy - 1, 3), ('zmin', ck == 0, 4)]
    if soil.periodic:
        outer = outer[-1:]
    free = np.ones(n_dofs, dtype=bool)
    k_b = sp.csr_matrix((n_dofs, n_dofs))
    c_b = sp.csr_matrix((n_dofs, n_dofs))
    for name, on, f in outer:
        sel = np.flatnonzero(on & (kind == SOIL))
        faces = cells[sel][:, HEX_FACES[f]]
        mesh.face_sets[name] = faces
        mesh.node_sets[name] = np.unique(faces)
        if soil.boundary == 'fixed':
            if name == 'zmin':
                free[node_dofs(mesh.node_sets[name][:, None]).ravel()] = False
            else:
                free[3 * mesh.node_sets[name] + 'xy'.index(name[0])] = False
            continue
        lay = material[sel]
        g = np.array([soil.layers[m].G for m in lay])
        rho = density[lay]
        vs = np.array([soil.layers[m].vs for m in lay])
        vp = np.array([soil.layers[m].vp for m in lay])
        face_xyz = cell_xyz[sel][:, HEX_FACES[f]]
        r = np.linalg.norm(face_xyz.mean(axis=1) - source, axis=1)
        kn, kt, cn, ct = viscoelastic_coefficients(g, rho, vs, vp, r, soil.alpha_t,
                                                   soil.alpha_n)
        if soil.boundary == 'lysmer':
            kn, kt = 0 * kn, 0 * kt
        else:
            k_b = k_b + _faces_matrix(n_dofs, face_xyz, faces, kn, kt, soil.boundary_lumping)
        c_b = c_b + _faces_matrix(n_dofs, face_xyz, faces, cn, ct, soil.boundary_lumping)

    # interface
    iface: Optional[InterfaceSet] = None
    law: Optional[DesaiLaw] = None
    if len(faces_a):
        iface = interface_set(nodes, faces_a, faces_b, spec.interface.thickness, n_dofs)
        gp = np.einsum('ga,eai->egi', FACE_N, nodes[faces_b])
        lay = np.broadcast_to(face_layer[:, None], gp.shape[:2])
        e_l = np.array([x.E for x in soil.layers])[lay]
        nu_l = np.array([x.nu for x in soil.layers])[lay]
        phi = np.radians(np.array([x.phi for x in soil.layers]))[lay]
        c_l = np.array([x.c for x in soil.layers])[lay]
        k_n0, k_s0 = initial_moduli(e_l, nu_l, 'lame' if spec.interface.shear_modulus == 'lame'
                                    else 'G')
        sigma_v = vertical_stress(gp[..., 2], spec)
        k0 = (1 - np.sin(phi)) if spec.interface.k0 <= 0 else spec.interface.k0
        vertical = np.abs(iface.frames[:, :, 0, 2]) > 0.5
        sigma_n0 = np.where(vertical, sigma_v, k0 * sigma_v)
        law = DesaiLaw(k_n0, k_s0, spec.interface.adhesion_ratio * c_l,
                       spec.interface.friction_ratio * np.tan(phi), sigma_n0,
                       spec.interface.failure_ratio)

    # observation: pile heads
    n_piles = piles.count if piles else 0
    rows_d, cols_d, vals_d = [], [], []
    rows_r, cols_r, vals_r = [], [], []
    for p in range(n_piles):
        sel = np.flatnonzero((pile_of == p) & (np.abs(grid.zs[ck + 1]) < 1e-9))
        faces = cells[sel][:, HEX_FACES[5]]
        _, weights = face_frames(nodes[faces])
        w = np.bincount(faces.ravel(), weights=np.einsum('ga,eg->ea', FACE_N, weights).ravel(),
                        minlength=len(nodes))
        head = np.flatnonzero(w)
        wn = w[head] / w[head].sum()
        for axis in range(3):
            rows_d.append(np.full(len(head), 3 * p + axis))
            cols_d.append(3 * head + axis)
            vals_d.append(wn)
        r = nodes[head] - wn @ nodes[head]
        inertia = np.einsum('a,a->', wn, (r**2).sum(1)) * np.eye(3) - np.einsum('a,ai,aj->ij',
                                                                                wn, r, r)
        cross = np.zeros((len(head), 3, 3))
        cross[:, 0, 1], cross[:, 0, 2] = -r[:, 2], r[:, 1]
        cross[:, 1, 0], cross[:, 1, 2] = r[:, 2], -r[:, 0]
        cross[:, 2, 0], cross[:, 2, 1] = -r[:, 1], r[:, 0]
        op = np.einsum('ij,a,ajk->iak', np.linalg.inv(inertia), wn, cross)
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

    head_d = op_matrix(rows_d, cols_d, vals_d)
    head_r = op_matrix(rows_r, cols_r, vals_r)

    # ground surface weights
    top_cells = np.flatnonzero((np.abs(grid.zs[ck + 1]) < 1e-9) & (kind != CAP))
    faces = cells[top_cells][:, HEX_FACES[5]]
    _, weights = face_frames(cell_xyz[top_cells][:, HEX_FACES[5]])
    surface_w = np.bincount(faces.ravel(),
                            weights=np.einsum('ga,eg->ea', FACE_N, weights).ravel(),
                            minlength=len(nodes))

    points = _soil_points(spec, grid, cell_map, cells, n_dofs)
    summary = _summary(spec, mesh, kind, aspect, iface, n_dofs, free)
    LOG.info('pile-soil substructure: %d nodes, %d DOFs, %d soil / %d pile / %d cap cells, '
             '%d interface elements, f_max %.3g Hz', len(nodes), n_dofs,
             summary['soil_cells'], summary['pile_cells'], summary['cap_cells'],
             summary['interface_elements'], summary['f_max'])
    dynamic = load is not None and load.type not in ('static', 'none')
    if dynamic and load is not None and load.frequency > summary['f_max']:
        LOG.warning('load frequency %.3g Hz is above the %.3g Hz the coarsest soil elements '
                    'carry: outgoing waves are under-resolved far from the piles',
                    load.frequency, summary['f_max'])
    return PileSoilModel(spec, grid, mesh, kind, free, mass, k_soil, c_soil, k_str, c_str,
                         k_b.tocsr(), c_b.tocsr(), iface, law, structure_dofs, head_d, head_r,
                         surface_w, points, summary)


def _faces_matrix(n_dofs: int, face_xyz: np.ndarray, faces: np.ndarray, normal: np.ndarray,
                  tangential: np.ndarray, lumping: str) -> sp.csr_matrix:
    if len(faces) == 0:
        return sp.csr_matrix((n_dofs, n_dofs))
    mats = face_matrices(face_xyz, normal, tangential, lumping)  # type: ignore[arg-type]
    return assemble(n_dofs, node_dofs(faces), mats)


def _soil_points(spec: Substructure, grid: Grid, cell_map: np.ndarray, cells: np.ndarray,
                 n_dofs: int) -> SoilPoints:
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
    if not positions:
        return SoilPoints(np.zeros((0, 3)), (), sp.csr_matrix((0, n_dofs)))
    pos = np.array(positions, dtype=float)
    try:
        structured, local = grid.locate(pos)
    except ValueError as err:
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


def _summary(spec: Substructure, mesh: Mesh, kind: np.ndarray, aspect: np.ndarray,
             iface: Optional[InterfaceSet], n_dofs: int, free: np.ndarray) -> dict:
    x = mesh.nodes[mesh.cells]
    soil = kind == SOIL
    span = x.max(axis=1) - x.min(axis=1)
    longest = span.max(axis=1)
    vs = np.array([lay.vs for lay in spec.soil.layers])
    carried = vs[mesh.material[soil]] / (spec.mesh.points_per_wavelength * longest[soil])
    return {
        'nodes': mesh.n_nodes, 'dofs': n_dofs, 'free_dofs': int(free.sum()),
        'soil_cells': int(soil.sum()), 'pile_cells': int((kind == PILE).sum()),
        'cap_cells': int((kind == CAP).sum()),
        'interface_elements': 0 if iface is None else iface.n_elements,
        'h_min': float(span.min()), 'h_max': float(longest.max()),
        'max_aspect_ratio': float(aspect.max()),
        'f_max': float(carried.min()),
        'f_max_estimate': float(spec.soil.vs_min
                                / (spec.mesh.points_per_wavelength * spec.mesh.h_max)),
    }
