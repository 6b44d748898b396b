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
:class:`PileSoilModel` in named steps: the structured brick mesh of the layered
block with node planes at every pile face, pile tip, cap face and layer
interface, its cells tagged soil, pile ([P] section 2.4) or cap (solid cells on
the ground surface, sharing nodes with the pile heads and the soil surface
under it) and the pile-soil interface's nodes duplicated on the pile shafts and
tips, or shared (``bonded``) (:mod:`.soil_mesh`); the materials; the assembly
of the linear operators; the viscous-spring, dashpot or fixed boundary on the
sides and base; the Desai thin-layer interface elements; the observation rows
(:mod:`.observation`).

The model keeps the *linear* operators (lumped mass, soil and structure
stiffness and Rayleigh damping, boundary springs and dashpots) apart from the
interface (:class:`~ttb_sim.fe.interface.InterfaceSet` plus its
:class:`~.desai.DesaiLaw`), so that a reduced-order model can later replace
the linear part behind the same attributes. It also holds the observation
operators of :mod:`.observation`: pile-head displacement and rotation, ground
surface weights and soil points.

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
from typing import cast, Optional

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe import hex8
from ttb_sim.fe.assembly import assemble_chunked
from ttb_sim.fe.boundary import boundary_matrix, Lumping, viscoelastic_coefficients
from ttb_sim.fe.interface import interface_set, InterfaceSet
from ttb_sim.fe.mesh import FACE_NAMES, Grid, grid_cells, GridCells, HEX_FACES, Mesh, node_dofs
from ttb_sim.fe.quad import FACE_N
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.foundation.consistency import check_substructure
from ttb_sim.model.foundation.desai import DesaiLaw, initial_moduli
from ttb_sim.model.foundation.observation import (cap_top_weights, head_operators,
                                                  pile_strain_operator, soil_points,
                                                  SoilPoints, surface_weights)
from ttb_sim.model.foundation.records import PileLoad, Substructure
from ttb_sim.model.foundation.soil_mesh import (CAP, CellTags, check_aspect, InterfaceSplit,
                                                PILE, SOIL, soil_grid, split_interface,
                                                tag_cells)

LOG = logging.getLogger(__name__)


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
    cell_coordinates : array, shape (m, 8, 3)
        Corner coordinates of each cell (m), those the element matrices were
        integrated on (``mesh.nodes[mesh.cells]`` but across a periodic seam).
    pile_strain : csr, shape (n_piles n_layers, n_dofs)
        Axial strain (tension positive) of each pile's element layers, head down
        (:func:`~.observation.pile_strain_operator`; apply to u).
    pile_layer_depths : array, shape (n_layers + 1,)
        Depths of the layers' planes below the pile heads (m), 0 first.

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
    cell_coordinates: np.ndarray = field(default_factory=lambda: np.zeros((0, 8, 3)))
    pile_strain: sp.csr_matrix = field(default_factory=lambda: sp.csr_matrix((0, 0)))
    pile_layer_depths: np.ndarray = field(default_factory=lambda: np.zeros(1))

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
        a surface load is a uniform pressure on the whole ground surface, a cap
        load one on the cap top.
        """
        axis = 'xyz'.index(load.direction)
        if load.target == 'cap':
            w = cap_top_weights(self.mesh.nodes, self.mesh.cells, self.cell_kind,
                                self.spec.cap.thickness)
            f = np.zeros(self.n_dofs)
            f[axis::3] = load.amplitude * w / w.sum()
            return f
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


def build(spec: Substructure, load: Optional[PileLoad] = None) -> PileSoilModel:
    """
    Build the substructure of ``spec`` (and check it against ``load`` if given).

    Raises
    ------
    FoundationError
        On inconsistent records (see :func:`~.consistency.check_substructure`) or a
        mesh whose aspect ratio exceeds ``mesh.max_aspect``.

    """
    check_substructure(spec, load)
    grid = soil_grid(spec)
    tags = tag_cells(spec, grid)
    cut = grid_cells(grid, tags.keep, spec.soil.periodic)
    tags = tags.kept()
    split = split_interface(spec, cut, tags)
    outer = _outer_faces(cut, tags, spec.soil.periodic)
    mesh = _mesh(split, tags, outer)
    aspect = check_aspect(spec, cut.coordinates, tags.material)
    n_dofs = 3 * mesh.n_nodes
    mats = materials(spec)
    cells = mesh.cells
    dofs = node_dofs(cells)
    lumped = hex8.lumped_mass(cut.coordinates, mats.density[tags.material])
    mass = np.bincount(np.repeat(cells.ravel(), 3) * 3 + np.tile(np.arange(3), cells.size),
                       weights=np.repeat(lumped.ravel(), 3), minlength=n_dofs)
    k_soil, c_soil = _linear_operators(np.flatnonzero(tags.kind == SOIL), dofs, cut.coordinates,
                                       tags.material, mats, lumped, n_dofs,
                                       spec.mesh.enriches(soil=True))
    k_str, c_str = _linear_operators(np.flatnonzero(tags.kind != SOIL), dofs, cut.coordinates,
                                     tags.material, mats, lumped, n_dofs,
                                     spec.mesh.enriches(soil=False))
    structure_dofs = np.zeros(n_dofs, dtype=bool)
    structure_dofs[dofs[tags.kind != SOIL].ravel()] = True
    free, k_b, c_b = _boundary(spec, mesh, outer, cut.coordinates, mats, n_dofs)
    iface, law = _interface(spec, split, n_dofs)
    head_d, head_r = head_operators(spec.piles.count if spec.piles else 0, cut, cells,
                                    mesh.nodes, tags.pile, n_dofs)
    strain, layer_depths = pile_strain_operator(spec.piles.count if spec.piles else 0, cut,
                                                cells, mesh.nodes, tags.pile, n_dofs)
    surface_w = surface_weights(cut, tags.kind, cells, mesh.n_nodes)
    points = soil_points(spec, cut, cells, n_dofs)
    summary = _summary(spec, mesh, tags.kind, aspect, iface, n_dofs, free)
    _report(summary, load)
    return PileSoilModel(spec, grid, mesh, tags.kind, free, mass, k_soil, c_soil, k_str, c_str,
                         k_b, c_b, iface, law, structure_dofs, head_d, head_r, surface_w,
                         points, summary, cut.coordinates, strain, layer_depths)


def _outer_faces(cut: GridCells, tags: CellTags,
                 periodic: bool) -> list[tuple[str, int, np.ndarray]]:
    """Return (name, face, soil cells) of the sides and base (the base alone if periodic)."""
    faces = (4,) if periodic else (0, 1, 2, 3, 4)
    return [(FACE_NAMES[f], f, np.flatnonzero(cut.on_outer_face(f) & (tags.kind == SOIL)))
            for f in faces]


def _mesh(split: InterfaceSplit, tags: CellTags,
          outer: list[tuple[str, int, np.ndarray]]) -> Mesh:
    """Return the mesh: cell sets 'soil', 'pile', 'cap'; face and node sets of the outside."""
    kind = tags.kind
    mesh = Mesh(split.nodes, split.cells, tags.material)
    mesh.cell_sets = {'soil': np.flatnonzero(kind == SOIL), 'pile': np.flatnonzero(kind == PILE),
                      'cap': np.flatnonzero(kind == CAP)}
    for name, f, sel in outer:
        faces = split.cells[sel][:, HEX_FACES[f]]
        mesh.face_sets[name] = faces
        mesh.node_sets[name] = np.unique(faces)
    return mesh


@dataclass(frozen=True)
class Materials:
    """Per material (the layers, then pile, then cap): elastic constants and Rayleigh damping."""

    young: np.ndarray
    poisson: np.ndarray
    density: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray


def materials(spec: Substructure) -> Materials:
    """Return the materials of the layers, the piles and the cap."""
    soil, piles, cap = spec.soil, spec.piles, spec.cap
    young = np.array([lay.E for lay in soil.layers] + [piles.E if piles else 1.0, cap.E])
    poisson = np.array([lay.nu for lay in soil.layers] + [piles.nu if piles else 0.0, cap.nu])
    density = np.array([lay.rho for lay in soil.layers] + [piles.rho if piles else 1.0, cap.rho])
    zeta = np.array([lay.damping_ratio for lay in soil.layers]
                    + [piles.damping_ratio if piles else 0.0, cap.damping_ratio])
    alpha, beta = rayleigh_coefficients(zeta, spec.rayleigh_frequencies)
    return Materials(young, poisson, density, alpha, beta)


def _linear_operators(sel: np.ndarray, dofs: np.ndarray, coords: np.ndarray,
                      material: np.ndarray, mats: Materials, lumped: np.ndarray,
                      n_dofs: int, incompatible: bool = False
                      ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """
    Return the stiffness K and Rayleigh damping alpha M + beta K of the cells ``sel``.

    ``incompatible``: bricks with Wilson's incompatible modes
    (``soil.mesh.incompatible_modes``).

    K and beta K are assembled together, as the real and imaginary parts of one
    complex matrix, so that they share one pattern.
    """
    if len(sel) == 0:
        z = sp.csr_matrix((n_dofs, n_dofs))
        return z, z

    def kernel(ids: np.ndarray) -> np.ndarray:
        e = sel[ids]
        k = hex8.stiffness(coords[e], mats.young[material[e]], mats.poisson[material[e]],
                           incompatible=incompatible)
        return k * (1.0 + 1j * mats.beta[material[e]])[:, None, None]

    both = assemble_chunked(n_dofs, dofs[sel], kernel, dtype=complex)
    stiff = sp.csr_matrix((both.data.real.copy(), both.indices, both.indptr), shape=both.shape)
    m_alpha = np.bincount(dofs[sel].ravel(),
                          weights=np.repeat(lumped[sel] * mats.alpha[material[sel]][:, None],
                                            3, axis=1).ravel(), minlength=n_dofs)
    damp = sp.csr_matrix((both.data.imag.copy(), both.indices, both.indptr),
                         shape=both.shape) + sp.diags(m_alpha)
    return stiff, damp.tocsr()


def _boundary(spec: Substructure, mesh: Mesh, outer: list[tuple[str, int, np.ndarray]],
              coords: np.ndarray, mats: Materials, n_dofs: int
              ) -> tuple[np.ndarray, sp.csr_matrix, sp.csr_matrix]:
    """
    Return the free DOFs and the boundary's springs and dashpots (K, C).

    ``fixed`` fixes the base and the sides' normal displacement; ``viscoelastic``
    puts springs and dashpots on the outer faces, ``lysmer`` dashpots only;
    ``rigid_base`` fixes the base and puts springs and dashpots on the sides.
    """
    soil, piles = spec.soil, spec.piles
    lumping = cast(Lumping, soil.boundary_lumping)
    source = np.array([piles.centre[0], piles.centre[1], 0.0]) if piles else np.zeros(3)
    free = np.ones(n_dofs, dtype=bool)
    k_b = sp.csr_matrix((n_dofs, n_dofs))
    c_b = sp.csr_matrix((n_dofs, n_dofs))
    for name, f, sel in outer:
        faces = mesh.face_sets[name]
        if soil.boundary in ('fixed', 'rigid_base') and name == 'zmin':
            free[node_dofs(mesh.node_sets[name][:, None]).ravel()] = False
            continue
        if soil.boundary == 'fixed':
            free[3 * mesh.node_sets[name] + 'xy'.index(name[0])] = False
            continue
        lay = mesh.material[sel]
        g = np.array([soil.layers[m].G for m in lay])
        rho = mats.density[lay]
        vs = np.array([soil.layers[m].vs for m in lay])
        vp = np.array([soil.layers[m].vp for m in lay])
        face_xyz = coords[sel][:, HEX_FACES[f]]
        r = np.linalg.norm(face_xyz.mean(axis=1) - source, axis=1)
        kn, kt, cn, ct = viscoelastic_coefficients(g, rho, vs, vp, r, soil.alpha_t,
                                                   soil.alpha_n)
        if soil.boundary == 'lysmer':
            kn, kt = 0 * kn, 0 * kt
        else:
            k_b = k_b + boundary_matrix(n_dofs, mesh.nodes, faces, kn, kt, lumping,
                                        coords=face_xyz)
        c_b = c_b + boundary_matrix(n_dofs, mesh.nodes, faces, cn, ct, lumping, coords=face_xyz)
    return free, k_b.tocsr(), c_b.tocsr()


def _interface(spec: Substructure, split: InterfaceSplit,
               n_dofs: int) -> tuple[Optional[InterfaceSet], Optional[DesaiLaw]]:
    """
    Return the Desai interface elements and their law at the geostatic state (or None).

    Initial stress: sigma_v = sum rho g h above the Gauss point, K0 sigma_v on the
    shafts and sigma_v under the tips.
    """
    if not len(split.faces_a):
        return None, None
    soil, interface = spec.soil, spec.interface
    nodes, faces_b = split.nodes, split.faces_b
    iface = interface_set(nodes, split.faces_a, faces_b, interface.thickness, n_dofs)
    gp = np.einsum('ga,eai->egi', FACE_N, nodes[faces_b])
    lay = np.broadcast_to(split.face_layer[:, None], gp.shape[:2])
    e_l = np.array([x.E for x in soil.layers])[lay]
    nu_l = np.array([x.nu for x in soil.layers])[lay]
    phi = np.radians(np.array([x.phi for x in soil.layers]))[lay]
    c_l = np.array([x.c for x in soil.layers])[lay]
    k_n0, k_s0 = initial_moduli(e_l, nu_l, 'lame' if interface.shear_modulus == 'lame'
                                else 'G')
    sigma_v = vertical_stress(gp[..., 2], spec)
    k0 = (1 - np.sin(phi)) if interface.k0 <= 0 else interface.k0
    vertical = np.abs(iface.frames[:, :, 0, 2]) > 0.5
    sigma_n0 = np.where(vertical, sigma_v, k0 * sigma_v)
    law = DesaiLaw(k_n0, k_s0, interface.adhesion_ratio * c_l,
                   interface.friction_ratio * np.tan(phi), sigma_n0, interface.failure_ratio)
    return iface, law


def _report(summary: dict, load: Optional[PileLoad]) -> None:
    """Log the model's size, and warn when a dynamic load is above what the mesh carries."""
    LOG.info('pile-soil substructure: %d nodes, %d DOFs, %d soil / %d pile / %d cap cells, '
             '%d interface elements, f_max %.3g Hz', summary['nodes'], summary['dofs'],
             summary['soil_cells'], summary['pile_cells'], summary['cap_cells'],
             summary['interface_elements'], summary['f_max'])
    dynamic = load is not None and load.type not in ('static', 'none')
    if dynamic and load is not None and load.frequency > summary['f_max']:
        LOG.warning('load frequency %.3g Hz is above the %.3g Hz the coarsest soil elements '
                    'carry: outgoing waves are under-resolved far from the piles',
                    load.frequency, summary['f_max'])


def _summary(spec: Substructure, mesh: Mesh, kind: np.ndarray, aspect: np.ndarray,
             iface: Optional[InterfaceSet], n_dofs: int, free: np.ndarray) -> dict:
    """Return DOF and cell counts, element sizes and the highest frequency carried."""
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
