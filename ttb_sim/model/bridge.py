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
Multi-span simply supported girders on bearings, piers and foundations.

Geometry (REP 103 track frame: x along the track, y left, z up): girder k
(0-based) spans x in [k L, (k + 1) L] at z = 0 and rests on supports k and k + 1.
Supports 0 and n_spans are abutments (always rigid ground); the intermediate ones
are piers. Bearings are point spring-dashpots ([P] Eq. 1 lumped to a point) at
y = +/- spacing/2 under each girder end. With rigid bearings the girder ends are
ideal pins (uy, uz and twist fixed at both ends, ux at the first end). With
spring foundations each pier is a column of 3-D beam elements from z = 0 down to
z = -height, on 6-DOF foundation springs ([P] Table 4).

All structural displacements are increments over the dead-load state of the
bridge, as a monitoring system zeroed before the passage would measure them.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Mapping

import numpy as np
import scipy.sparse as sp

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.fe.assembly import assemble, assemble_links, link_kinematics
from ttb_sim.fe.beam import BeamSection, global_matrices, NODE_DOFS, vertical_row, W_DOFS
from ttb_sim.fe.dofs import DofMap
from ttb_sim.model.foundation.operator import FoundationOperator
from ttb_sim.model.track import BeamLine, build_track, TrackMesh, TrackParameters


@dataclass(frozen=True)
class BridgeParameters:
    """Simply supported girders, modelled as 3-D Euler-Bernoulli beams."""

    n_spans: int = param(1, '-', 'Number of simply supported spans.', low=1, high=50)
    span_length: float = param(32.0, 'm', 'Length of each span between bearings.', low=0.0,
                               high=500.0, low_inclusive=False)
    bending_stiffness: float = param(4.646e11, 'N*m^2', 'Vertical bending stiffness EI of a '
                                     'girder (E = 3.55e10 Pa, I = 13.088 m^4, [P] Table 3).',
                                     low=0.0, high=1e16, low_inclusive=False)
    lateral_bending_stiffness: float = param(3.087e12, 'N*m^2', 'Lateral bending stiffness '
                                             '(I = 86.951 m^4, [P] Table 3).', low=0.0,
                                             high=1e17, low_inclusive=False)
    torsional_stiffness: float = param(3.4e11, 'N*m^2', 'Torsional stiffness GJ (G = E/2.4, '
                                       'J = 22.984 m^4).', low=0.0, high=1e17,
                                       low_inclusive=False)
    axial_stiffness: float = param(3.16e11, 'N', 'Axial stiffness EA (A = 8.9 m^2 mid-span '
                                   'box section).', low=0.0, high=1e16, low_inclusive=False)
    mass_per_length: float = param(35200.0, 'kg/m', 'Mass per metre: 8.9 m^2 box girder plus '
                                   '13 t/m secondary dead load (Table 3 prints 47.8 m^2, '
                                   '119.5 t/m: see PHYSICS.md section 5).', low=0.0, high=1e7,
                                   low_inclusive=False)
    torsional_inertia: float = param(3.2e5, 'kg*m^2/m', 'Mass moment of inertia about the '
                                     'girder axis per metre (assumed).', low=0.0, high=1e9,
                                     low_inclusive=False)
    damping_ratio: float = param(0.02, '-', 'Rayleigh damping ratio, exact at the first and '
                                 'second vertical bending modes of a span.', low=0.0,
                                 high=0.5, high_inclusive=False)
    elements_per_span: int = param(16, '-', 'Beam elements per span (even, so that a node '
                                   'sits at mid-span).', low=2, high=400)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'bridge parameter')


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
class PierParameters:
    """Pier columns under the intermediate supports (used with spring foundations)."""

    height: float = param(10.0, 'm', 'Pier height from foundation to bearing.', low=0.0,
                          high=200.0, low_inclusive=False)
    axial_stiffness: float = param(2.6e11, 'N', 'Axial stiffness EA (C35, 8 m^2, assumed).',
                                   low=0.0, high=1e16, low_inclusive=False)
    bending_stiffness: float = param(2.6e11, 'N*m^2', 'Bending stiffness EI about both axes '
                                     '(8 m^4, assumed).', low=0.0, high=1e16,
                                     low_inclusive=False)
    torsional_stiffness: float = param(2.2e11, 'N*m^2', 'Torsional stiffness GJ (assumed).',
                                       low=0.0, high=1e16, low_inclusive=False)
    mass_per_length: float = param(20000.0, 'kg/m', 'Mass per metre of pier (assumed).',
                                   low=0.0, high=1e7, low_inclusive=False)
    elements: int = param(4, '-', 'Beam elements per pier.', low=1, high=100)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'pier parameter')


@dataclass(frozen=True)
class FoundationParameters:
    """Foundations of the intermediate piers; abutments are always rigid."""

    model: str = param('rigid', '-', "'rigid': bearings sit on fixed supports; 'springs': "
                       "piers on foundation springs ([P] Table 4); 'piled': the piers of "
                       'piled_piers stand on the 3-D cap-pile-soil substructure of the soil, '
                       'piles, cap and interface keys, the others on springs.',
                       choices=('rigid', 'springs', 'piled'))
    piled_piers: tuple[int, ...] = param((), '-', 'Supports on piled foundations when model = '
                                         "'piled', numbered 1 (first abutment) to n_spans + 1 "
                                         '(last abutment): intermediate piers only. '
                                         'VALIDATION.md: [7, 8].', low=2, high=50)
    vertical_stiffness: float = param(6e9, 'N/m', 'Vertical foundation spring ([P] Table 4).',
                                      low=0.0, high=1e15, low_inclusive=False)
    lateral_stiffness: float = param(6e8, 'N/m', 'Lateral and longitudinal foundation spring '
                                     '([P] Table 4).', low=0.0, high=1e15, low_inclusive=False)
    rotational_stiffness: float = param(1e11, 'N*m/rad', 'Rocking and twisting foundation '
                                        'spring (assumed; not in [P]).', low=0.0, high=1e18,
                                        low_inclusive=False)
    damping: float = param(0.0, 'N*s/m', 'Translational foundation damping ([P] Table 4: 0).',
                           low=0.0, high=1e12)

    def __post_init__(self) -> None:
        """Check every field against its declaration, and the piled piers."""
        check_declared(self, 'foundation parameter')
        piers = self.piled_piers
        if any(isinstance(p, bool) or not isinstance(p, int) or p < 2 for p in piers):
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} is invalid; allowed: '
                             'support numbers >= 2 (1 is the first abutment)')
        if len(set(piers)) != len(piers):
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} names a pier twice')
        if self.model == 'piled' and not piers:
            raise ModelError("foundation.model = 'piled' needs foundation.piled_piers, e.g. "
                             '[7, 8] (support numbers of the piled piers)')
        if self.model != 'piled' and piers:
            raise ModelError(f'foundation.piled_piers = {list(piers)!r} needs '
                             f"foundation.model = 'piled' (got {self.model!r})")

    @property
    def piled(self) -> tuple[int, ...]:
        """0-based support indices of the piled piers, in ascending order."""
        return tuple(sorted(p - 1 for p in self.piled_piers))


@dataclass(frozen=True)
class GirderLine:
    """
    Lookup from a position along the track to the girder element under it.

    DOF indices are *extended free* indices: constrained DOFs map to ``n_free``,
    a slot that always holds zero (see :class:`Structure`).
    """

    span_length: float
    n_spans: int
    elements_per_span: int
    w_dofs: np.ndarray
    """(n_elements, 4) extended free index of (uz1, ry1, uz2, ry2)."""
    w_dofs_full: np.ndarray
    """(n_elements, 4) full DOF index of the same."""

    @property
    def length(self) -> float:
        """Total length of the bridge (m)."""
        return self.span_length * self.n_spans

    @property
    def element_length(self) -> float:
        """Length of one girder element (m)."""
        return self.span_length / self.elements_per_span

    def locate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Find the element and local coordinate of positions along the track.

        Returns
        -------
        (element, xi, on_bridge)
            Element index (clipped to valid), local coordinate in [0, 1], and a
            mask that is True where 0 <= x <= length.

        """
        x = np.asarray(x, dtype=float)
        on = (x >= 0.0) & (x <= self.length)
        h = self.element_length
        n_el = self.n_spans * self.elements_per_span
        element = np.clip(np.floor(x / h).astype(int), 0, n_el - 1)
        xi = np.clip(x / h - element, 0.0, 1.0)
        return element, xi, on

    def rows(self, x: np.ndarray, derivatives: tuple[int, ...] = (0,)
             ) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        """
        Return the rows that map element DOFs to the girder deflection w at x.

        Positions off the bridge get zero rows. The positions are located once
        for all the requested derivatives.

        Returns
        -------
        (element, rows)
            Element index (n_points,) and, per requested derivative (0: w,
            1: dw/dx, 2: d2w/dx2), coefficients (n_points, 4) on the element's
            (uz1, ry1, uz2, ry2); index ``w_dofs`` or ``w_dofs_full`` with the
            element to get the DOFs.

        """
        element, xi, on = self.locate(x)
        mask = on[:, None]
        return element, tuple(vertical_row(xi, self.element_length, d) * mask
                              for d in derivatives)


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
class PiledPier:
    """
    A pier standing on a cap-pile-soil substructure (``foundation.model: piled``).

    The bridge meets it only through the bearings of its support. Monolithic: its
    coordinates q are DOFs of the structure (``block``); partitioned: it is
    stepped beside the bridge (:mod:`ttb_sim.sim.piled_foundations`) and the
    bearings of the support see its pier top as a moving support.
    """

    support: int
    """0-based support index."""
    operator: FoundationOperator
    links: np.ndarray
    """Indices of the support's bearings in :attr:`Structure.bearings`."""
    block: np.ndarray | None
    """Monolithic: extended free index of each coordinate q; partitioned: None."""


@dataclass(frozen=True)
class Structure:
    """
    Assembled bridge: free-DOF matrices and the sensors defined on them.

    The state vectors of the solver hold the free DOFs; gathers use an extended
    vector with one more slot, index ``n_free``, that stands for every
    constrained DOF and always holds zero.
    """

    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix
    dofs: DofMap
    """Numbering: substructure blocks 'girders', 'piers', 'track'; interfaces 'bearings'
    (girder ends and pier tops) and 'foundations' (pier bases, where springs or piles
    carry the piers)."""
    girder: GirderLine
    midspan_dofs: np.ndarray
    """(n_spans, 3) extended free indices of ux, uy, uz at each mid-span node."""
    bearings: Bearings | None
    rigid: RigidSupports | None
    n_supports: int
    bearing_spacing: float
    fundamental_frequency: float
    """First vertical bending frequency of a simply supported span (Hz)."""
    rayleigh: tuple[float, float]
    """Rayleigh coefficients (a0, a1) of C = a0 M + a1 K for the beams."""
    girder_beam: BeamLine
    """The girders as a beam line (full DOFs), for point lookups of all six fields."""
    track: TrackMesh | None = None
    """The slab track (full DOF numbering), if modelled."""
    piled: tuple[PiledPier, ...] = ()
    """The piled piers, by support."""

    @property
    def n_free(self) -> int:
        """Number of free DOFs."""
        return self.dofs.n_free

    @property
    def n_full(self) -> int:
        """Number of DOFs of all nodes."""
        return self.dofs.n_full

    @property
    def free(self) -> np.ndarray:
        """Full DOF index of each free DOF."""
        return self.dofs.free

    @property
    def full_to_free(self) -> np.ndarray:
        """Extended free index of each full DOF (constrained: ``n_free``)."""
        return self.dofs.full_to_free


def span_frequency(span_length: float, bending_stiffness: float, mass_per_length: float,
                   mode: int = 1) -> float:
    """Return f_j = j^2 pi / (2 L^2) sqrt(EI/m) of a simply supported beam (Hz)."""
    root = math.sqrt(bending_stiffness / mass_per_length)
    return mode**2 * math.pi / (2 * span_length**2) * root


def rayleigh_coefficients(ratio: float, f1: float, f2: float) -> tuple[float, float]:
    """Return (a0, a1) giving the damping ratio exactly at f1 and f2 (Hz)."""
    w1, w2 = 2 * math.pi * f1, 2 * math.pi * f2
    return 2 * ratio * w1 * w2 / (w1 + w2), 2 * ratio / (w1 + w2)


@dataclass(frozen=True)
class BeamBlock:
    """A substructure of beam elements in the global node numbering."""

    coords: np.ndarray
    """(n_nodes, 3) coordinates of the block's own nodes (m)."""
    elements: np.ndarray
    """(n_el, 2) global node numbers of each element."""
    section: BeamSection
    """Section of each element."""


def girder_block(b: BridgeParameters) -> tuple[BeamBlock, np.ndarray]:
    """
    Return the girders (nodes 0.., ``elements_per_span`` elements per span) and their nodes.

    Returns
    -------
    (BeamBlock, (n_spans, ne + 1) node numbers of each span)

    """
    n_spans, ne, span = b.n_spans, b.elements_per_span, b.span_length
    xg = (np.arange(n_spans)[:, None] * span
          + np.linspace(0.0, span, ne + 1)[None, :]).ravel()
    girder_nodes = np.arange(n_spans * (ne + 1)).reshape(n_spans, ne + 1)
    first = girder_nodes[:, :-1].ravel()
    elements = np.column_stack([first, first + 1])
    section = _uniform_section(elements.shape[0], b.axial_stiffness, b.torsional_stiffness,
                               b.bending_stiffness, b.lateral_bending_stiffness,
                               b.mass_per_length, b.torsional_inertia)
    coords = np.column_stack([xg, np.zeros_like(xg), np.zeros_like(xg)])
    return BeamBlock(coords, elements, section), girder_nodes


def pier_block(pr: PierParameters, n_spans: int, span: float, first_node: int,
               skip: tuple[int, ...] = ()) -> tuple[BeamBlock, np.ndarray, np.ndarray]:
    """
    Return the pier columns under the intermediate supports but ``skip`` (top node first).

    Returns
    -------
    (BeamBlock, pier top node per support, pier base node per support); -1 where a
    support (the abutments) has no pier.

    """
    n_supports = n_spans + 1
    pier_top = np.full(n_supports, -1)
    pier_base = np.full(n_supports, -1)
    npe = pr.elements
    zp = -np.linspace(0.0, pr.height, npe + 1)
    coords, conn = [np.zeros((0, 3))], [np.zeros((0, 2), dtype=int)]
    n_nodes = first_node
    piers = [s for s in range(1, n_spans) if s not in skip]
    for s in piers:
        ids = n_nodes + np.arange(npe + 1)
        coords.append(np.column_stack([np.full(npe + 1, s * span), np.zeros(npe + 1), zp]))
        conn.append(np.column_stack([ids[:-1], ids[1:]]))
        pier_top[s], pier_base[s] = ids[0], ids[-1]
        n_nodes += npe + 1
    section = pier_section(pr, len(piers) * npe)
    return BeamBlock(np.concatenate(coords), np.concatenate(conn), section), pier_top, pier_base


def pier_section(pr: PierParameters, n: int | None = None) -> BeamSection:
    """Return the section of ``n`` pier elements (default: one pier's)."""
    return _uniform_section(pr.elements if n is None else n, pr.axial_stiffness,
                            pr.torsional_stiffness, pr.bending_stiffness, pr.bending_stiffness,
                            pr.mass_per_length, pr.mass_per_length)


def _rigid_end_dofs(ends: np.ndarray, end_support: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return (full DOF, support, component) of ideal pinned girder ends."""
    n_spans = ends.shape[0]
    comp_list, dof_list, sup_list = [], [], []
    for end in (0, 1):
        comps = (0, 1, 2, 3) if end == 0 else (1, 2, 3)
        for c in comps:
            dof_list.append(ends[:, end] * NODE_DOFS + c)
            sup_list.append(end_support[:, end])
            comp_list.append(np.full(n_spans, c))
    return np.concatenate(dof_list), np.concatenate(sup_list), np.concatenate(comp_list)


def _bearing_links(br: BearingParameters, ends: np.ndarray, end_support: np.ndarray,
                   pier_top: np.ndarray, moving: np.ndarray) -> tuple[np.ndarray, ...]:
    """
    Return the elastic bearings as links between girder ends and pier tops (or ground).

    ``moving`` marks the supports (partitioned piled piers) whose pier top is not
    a node of the structure: their links are assembled as on ground, but the
    kinematics keep the pier-top arm for the substructure's motion.

    Returns
    -------
    (kinematics (n, 3, 12), full DOFs (n, 12) with -1 for ground, stiffness (n, 3),
    damping (n, 3), support (n,), side (n,)), one link per girder end and side.

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
    cdir = np.tile([br.lateral_damping, br.lateral_damping, br.vertical_damping],
                   (side.size, 1))
    node_b = np.where(top >= 0, top, 0)
    full_b = node_b[:, None] * NODE_DOFS + np.arange(NODE_DOFS)
    ground = np.repeat(top < 0, NODE_DOFS).reshape(-1, NODE_DOFS)
    link_full = np.concatenate([girder_end[:, None] * NODE_DOFS + np.arange(NODE_DOFS),
                                np.where(ground, -1, full_b)], axis=1)
    return kin, link_full, kdir, cdir, support, side


def _foundation_springs(fd: FoundationParameters, bases: np.ndarray,
                        n_full: int) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """Return (K, C) of the foundation springs under the pier bases."""
    bdofs = (bases[:, None] * NODE_DOFS + np.arange(NODE_DOFS)).ravel()
    kf = np.tile([fd.lateral_stiffness, fd.lateral_stiffness, fd.vertical_stiffness,
                  fd.rotational_stiffness, fd.rotational_stiffness,
                  fd.rotational_stiffness], bases.size)
    cf = np.tile([fd.damping, fd.damping, fd.damping, 0.0, 0.0, 0.0], bases.size)
    return (sp.csr_matrix((kf, (bdofs, bdofs)), shape=(n_full, n_full)),
            sp.csr_matrix((cf, (bdofs, bdofs)), shape=(n_full, n_full)))


def assemble_structure(b: BridgeParameters, br: BearingParameters, pr: PierParameters,
                       fd: FoundationParameters, track_parameters: TrackParameters | None,
                       train_length: float,
                       foundations: Mapping[int, FoundationOperator] | None = None,
                       monolithic: bool = False) -> Structure:
    """
    Assemble girders, bearings, piers, foundations and the slab track (once).

    The substructures are built as blocks of the global numbering (girders, then
    piers, then track) and meet at the named interfaces of the :class:`DofMap`:
    ``bearings`` (girder ends and pier tops) and ``foundations`` (pier bases).

    Parameters
    ----------
    b, br, pr, fd
        Girder, bearing, pier and foundation records.
    track_parameters
        The slab track, or None when loads act on the girder axis.
    train_length
        Head to last axle or car end (m): the automatic approach length.
    foundations
        ``foundation.model: piled``: the substructure of each piled pier by
        0-based support index.
    monolithic
        Make the substructures' coordinates DOFs of the structure ([P] Eq. 11)
        instead of leaving them to a partitioned driver (Eq. 12).

    Returns
    -------
    Structure

    """
    n_spans, ne, span = b.n_spans, b.elements_per_span, b.span_length
    n_supports = n_spans + 1
    girders, girder_nodes = girder_block(b)
    blocks = [girders]
    n_girder_nodes = girder_nodes.size
    pier_top = np.full(n_supports, -1)
    pier_base = np.full(n_supports, -1)
    piled = tuple(sorted((foundations or {}).keys()))
    if fd.model in ('springs', 'piled'):
        piers, pier_top, pier_base = pier_block(pr, n_spans, span, n_girder_nodes, piled)
        if piers.elements.size:
            blocks.append(piers)
    n_bridge_nodes = n_girder_nodes + sum(blk.coords.shape[0] for blk in blocks[1:])
    n_bridge_el = sum(blk.elements.shape[0] for blk in blocks)
    girder_el_dofs = (girders.elements[:, :, None] * NODE_DOFS
                      + np.arange(NODE_DOFS)).reshape(-1, 12)
    girder_beam = BeamLine(start=girders.coords[girders.elements[:, 0], 0],
                           length=np.full(len(girders.elements), span / ne),
                           dofs=girder_el_dofs, z=0.0)
    track = None
    sections = [blk.section for blk in blocks]
    coords = [blk.coords for blk in blocks]
    conn = [blk.elements for blk in blocks]
    if track_parameters is not None:
        track = build_track(track_parameters, span * n_spans, train_length, n_bridge_nodes,
                            girder_beam)
        coords.append(track.coords)
        conn.append(track.elements)
        sections.append(track.sections)
    xyz = np.concatenate(coords)
    n_nodes = n_beam_nodes = xyz.shape[0]
    # monolithic substructures: their coordinates as pseudo-nodes after the beams, the
    # pier top first (q[:6] is one node), the padding of the last node constrained
    blocks_q: dict[int, np.ndarray] = {}
    padding: list[np.ndarray] = []
    if monolithic:
        for support in piled:
            size = foundations[support].size  # type: ignore[index]
            count = -(-size // NODE_DOFS)
            pier_top[support] = n_nodes
            blocks_q[support] = n_nodes * NODE_DOFS + np.arange(size)
            padding.append(n_nodes * NODE_DOFS + np.arange(size, count * NODE_DOFS))
            n_nodes += count
    elements = np.concatenate(conn)
    section = BeamSection(*(np.concatenate([getattr(s, f) for s in sections])
                            for f in ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x')))
    n_full = n_nodes * NODE_DOFS
    edofs = (elements[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    ke, me, _ = global_matrices(xyz[elements[:, 0]], xyz[elements[:, 1]], section)
    k_beam = assemble(n_full, edofs, ke)
    m_full = assemble(n_full, edofs, me)
    for support, full in blocks_q.items():
        op = foundations[support]  # type: ignore[index]
        k_beam = k_beam + _dense_block(n_full, full, op.stiffness)
        m_full = m_full + _dense_block(n_full, full, op.mass)

    # Rayleigh damping for the girders and piers only; the track is damped by its
    # fasteners and layers.
    f1 = span_frequency(span, b.bending_stiffness, b.mass_per_length)
    a0, a1 = rayleigh_coefficients(b.damping_ratio, f1, 4 * f1)
    nb = slice(0, n_bridge_el)
    c_full = (a0 * assemble(n_full, edofs[nb], me[nb])
              + a1 * assemble(n_full, edofs[nb], ke[nb])).tocsr()
    for support, full in blocks_q.items():
        c_full = c_full + _dense_block(n_full, full, foundations[support].damping)  # type: ignore
    k_full = k_beam.copy()
    if track is not None:
        for links in track.links:
            k_full = k_full + assemble_links(n_full, links.dofs, links.kinematics,
                                             links.stiffness)
            c_full = c_full + assemble_links(n_full, links.dofs, links.kinematics,
                                             links.damping)

    # Interfaces: bearings between girder ends and supports, foundations under piers.
    constrained = np.zeros(n_full, dtype=bool)
    if padding:
        constrained[np.concatenate(padding)] = True
    ends = np.stack([girder_nodes[:, 0], girder_nodes[:, -1]], axis=1)  # (n_spans, 2)
    end_support = np.stack([np.arange(n_spans), np.arange(1, n_spans + 1)], axis=1)
    bearing_links = None
    if br.model == 'rigid':
        cdofs, c_support, c_component = _rigid_end_dofs(ends, end_support)
        constrained[cdofs] = True
    else:
        moving = np.zeros(n_supports, dtype=bool)
        moving[list(piled)] = not monolithic
        bearing_links = _bearing_links(br, ends, end_support, pier_top, moving)
        kin, link_full, kdir, cdir = bearing_links[:4]
        k_full = k_full + assemble_links(n_full, link_full, kin, kdir)
        c_full = c_full + assemble_links(n_full, link_full, kin, cdir)
    bases = pier_base[pier_base >= 0]
    if bases.size:
        k_found, c_found = _foundation_springs(fd, bases, n_full)
        k_full = k_full + k_found
        c_full = c_full + c_found

    dof_map = DofMap.compose(
        n_nodes, NODE_DOFS, constrained,
        {'girders': np.arange(n_girder_nodes),
         'piers': np.arange(n_girder_nodes, n_bridge_nodes),
         'track': np.arange(n_bridge_nodes, n_beam_nodes),
         'substructures': np.arange(n_beam_nodes, n_nodes)},
        {'bearings': np.concatenate([ends.ravel(), pier_top[pier_top >= 0]]),
         'foundations': bases})
    free, full_to_free = dof_map.free, dof_map.full_to_free
    n_free = dof_map.n_free

    def reduce(a: sp.csr_matrix) -> sp.csr_matrix:
        return a[free][:, free].tocsr()

    rigid = None
    if br.model == 'rigid':
        def rows(a: sp.csr_matrix) -> sp.csr_matrix:
            r = a[cdofs][:, free].tocsc()
            return sp.hstack([r, sp.csc_matrix((cdofs.size, 1))]).tocsr()

        rigid = RigidSupports(rows_k=rows(k_full), rows_c=rows(c_full), rows_m=rows(m_full),
                              full_dofs=cdofs, support=c_support, component=c_component)
    bearings = None
    if bearing_links is not None:
        kin, link_full, kdir, cdir, link_support, side = bearing_links
        ext = np.where(link_full >= 0, full_to_free[np.maximum(link_full, 0)], n_free)
        bearings = Bearings(kinematics=kin, dofs=ext, stiffness=kdir, damping=cdir,
                            support=link_support, side=side)

    el_nodes = girders.elements
    wfull = el_nodes[:, [0, 0, 1, 1]] * NODE_DOFS + W_DOFS % NODE_DOFS
    girder = GirderLine(span_length=span, n_spans=n_spans, elements_per_span=ne,
                        w_dofs=full_to_free[wfull], w_dofs_full=wfull)
    mid = girder_nodes[:, ne // 2]
    midspan = full_to_free[mid[:, None] * NODE_DOFS + np.arange(3)]
    piled_piers = tuple(
        PiledPier(support=s, operator=foundations[s],  # type: ignore[index]
                  links=np.flatnonzero(bearings.support == s) if bearings else np.zeros(0, int),
                  block=full_to_free[blocks_q[s]] if s in blocks_q else None)
        for s in piled)
    return Structure(mass=reduce(m_full), damping=reduce(c_full), stiffness=reduce(k_full),
                     dofs=dof_map, girder=girder,
                     midspan_dofs=midspan, bearings=bearings, rigid=rigid,
                     n_supports=n_supports, bearing_spacing=br.spacing,
                     fundamental_frequency=f1, rayleigh=(a0, a1),
                     girder_beam=girder_beam, track=track, piled=piled_piers)


def _dense_block(n_full: int, full: np.ndarray, block: np.ndarray) -> sp.csr_matrix:
    """Return a dense block on the full DOFs ``full`` as an n_full x n_full sparse matrix."""
    rows = np.repeat(full, full.size)
    cols = np.tile(full, full.size)
    return sp.csr_matrix((block.ravel(), (rows, cols)), shape=(n_full, n_full))


def _uniform_section(n: int, ea: float, gj: float, ei_y: float, ei_z: float, mass: float,
                     inertia_x: float) -> BeamSection:
    return BeamSection(*(np.full(n, v, dtype=float)
                         for v in (ea, gj, ei_y, ei_z, mass, inertia_x)))


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
