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
The structure: girders, piers, bearings, foundations and track composed into one model.

:func:`assemble_structure` takes each part from its own builder (girders and
piers from :mod:`.bridge`, the slab track from :mod:`.track`, bearings from
:mod:`.bearings`, foundation springs and piled piers from
:mod:`.foundation.pier_foundations`), numbers their nodes as blocks of one
global numbering (girders, then piers, then track, then the pseudo-nodes of
monolithic substructures), assembles the matrices once and owns the DOF map
(:class:`~ttb_sim.fe.dofs.DofMap`) and the :class:`Structure` record the
solvers and sensors use.

All structural displacements are increments over the dead-load state of the
bridge, as a monitoring system zeroed before the passage would measure them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe.assembly import assemble, assemble_links
from ttb_sim.fe.beam import BeamSection, global_matrices, NODE_DOFS
from ttb_sim.fe.dofs import DofMap
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.bearings import (bearing_links, BearingLinks, BearingParameters, Bearings,
                                    rigid_ends, RigidEnds, RigidSupports)
from ttb_sim.model.bridge import (BeamBlock, BridgeParameters, girder_block, girder_line,
                                  GirderLine,
                                  pier_block, PierParameters, rayleigh_coefficients,
                                  span_frequency)
from ttb_sim.model.foundation.operator import FoundationOperator
from ttb_sim.model.foundation.pier_foundations import (add_piled_blocks, foundation_springs,
                                                       FoundationParameters, piled_blocks,
                                                       PiledBlocks)
from ttb_sim.model.track import build_track, TrackMesh, TrackParameters


@dataclass(frozen=True)
class PiledPier:
    """
    A pier standing on a cap-pile-soil substructure (``foundation.model: piled``).

    The bridge meets it only through the bearings of its support. Monolithic: its
    coordinates q are DOFs of the structure (``block``); partitioned: it is
    stepped beside the bridge (:mod:`ttb_sim.sim.substructure.piled_piers`) and the
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
    pier_supports: tuple[int, ...] = ()
    """Supports (0-based) that stand on a pier column, in order (abutments have none)."""
    pier_top_dofs: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.intp))
    """(len(pier_supports), 3) extended free indices of ux, uy, uz at each pier top; the
    zero slot where the top is not a structure DOF (partitioned piled piers)."""

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


@dataclass(frozen=True)
class _Beams:
    """The beam elements of the structure: girders, then piers, then track (full numbering)."""

    girders: BeamBlock
    girder_nodes: np.ndarray
    """(n_spans, elements_per_span + 1) node numbers of each span."""
    girder_beam: BeamLine
    pier_top: np.ndarray
    """Pier top node per support (-1: none)."""
    pier_base: np.ndarray
    """Pier base node per support (-1: none)."""
    track: TrackMesh | None
    xyz: np.ndarray
    """(n_nodes, 3) coordinates of every beam node."""
    elements: np.ndarray
    """(n_el, 2) node numbers of every beam element."""
    section: BeamSection
    n_girder_nodes: int
    n_bridge_nodes: int
    """Girder and pier nodes (the track's follow)."""
    n_bridge_el: int
    """Girder and pier elements (Rayleigh-damped; the track's follow)."""

    @property
    def n_nodes(self) -> int:
        """Number of beam nodes."""
        return int(self.xyz.shape[0])


def _beams(b: BridgeParameters, pr: PierParameters, fd: FoundationParameters,
           piled: tuple[int, ...], track_parameters: TrackParameters | None,
           train_length: float, girder_bending: np.ndarray | None = None) -> _Beams:
    """Return the girders, the piers (but the piled ones) and the track as one numbering."""
    n_spans, ne, span = b.n_spans, b.elements_per_span, b.span_length
    girders, girder_nodes = girder_block(b, girder_bending)
    blocks = [girders]
    n_girder_nodes = girder_nodes.size
    pier_top = np.full(n_spans + 1, -1)
    pier_base = np.full(n_spans + 1, -1)
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
    section = BeamSection(*(np.concatenate([getattr(s, f) for s in sections])
                            for f in ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x')))
    return _Beams(girders, girder_nodes, girder_beam, pier_top, pier_base, track,
                  np.concatenate(coords), np.concatenate(conn), section, n_girder_nodes,
                  n_bridge_nodes, n_bridge_el)


def _beam_matrices(beams: _Beams, n_full: int, b: BridgeParameters
                   ) -> tuple[sp.csr_matrix, sp.csr_matrix, sp.csr_matrix, float,
                              tuple[float, float]]:
    """
    Return (K, M, C) of the beams on the full DOFs, the span frequency and (a0, a1).

    Rayleigh damping for the girders and piers only; the track is damped by its
    fasteners and layers.
    """
    xyz, elements = beams.xyz, beams.elements
    edofs = (elements[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    ke, me, _ = global_matrices(xyz[elements[:, 0]], xyz[elements[:, 1]], beams.section)
    k_full = assemble(n_full, edofs, ke)
    m_full = assemble(n_full, edofs, me)
    f1 = span_frequency(b.span_length, b.bending_stiffness, b.mass_per_length)
    a0, a1 = rayleigh_coefficients(b.damping_ratio, f1, 4 * f1)
    nb = slice(0, beams.n_bridge_el)
    c_full = (a0 * assemble(n_full, edofs[nb], me[nb])
              + a1 * assemble(n_full, edofs[nb], ke[nb])).tocsr()
    return k_full, m_full, c_full, f1, (a0, a1)


def _girder_ends(beams: _Beams) -> tuple[np.ndarray, np.ndarray]:
    """Return the (n_spans, 2) end nodes of the girders and the supports under them."""
    nodes = beams.girder_nodes
    n_spans = nodes.shape[0]
    ends = np.stack([nodes[:, 0], nodes[:, -1]], axis=1)
    end_support = np.stack([np.arange(n_spans), np.arange(1, n_spans + 1)], axis=1)
    return ends, end_support


def _bearings(br: BearingParameters, beams: _Beams, blocks: PiledBlocks, moving: np.ndarray,
              factors: np.ndarray | None = None
              ) -> tuple[RigidEnds | None, BearingLinks | None]:
    """
    Return the rigid girder ends or the elastic bearings (the other None).

    ``moving`` marks the supports whose pier top is not a node of the structure
    (partitioned piled piers).
    """
    ends, end_support = _girder_ends(beams)
    if br.model == 'rigid':
        return rigid_ends(ends, end_support), None
    return None, bearing_links(br, ends, end_support, blocks.pier_top, moving, factors)


def _dof_map(beams: _Beams, blocks: PiledBlocks, constrained: np.ndarray) -> DofMap:
    """Return the numbering: blocks girders, piers, track, substructures; interfaces."""
    ends, _ = _girder_ends(beams)
    pier_top = blocks.pier_top
    return DofMap.compose(
        blocks.n_nodes, NODE_DOFS, constrained,
        {'girders': np.arange(beams.n_girder_nodes),
         'piers': np.arange(beams.n_girder_nodes, beams.n_bridge_nodes),
         'track': np.arange(beams.n_bridge_nodes, beams.n_nodes),
         'substructures': np.arange(beams.n_nodes, blocks.n_nodes)},
        {'bearings': np.concatenate([ends.ravel(), pier_top[pier_top >= 0]]),
         'foundations': beams.pier_base[beams.pier_base >= 0]})


def _piled_piers(foundations: Mapping[int, FoundationOperator] | None, piled: tuple[int, ...],
                 blocks: PiledBlocks, bearings: Bearings | None,
                 full_to_free: np.ndarray) -> tuple[PiledPier, ...]:
    """Return the records of the piled piers, by support."""
    return tuple(
        PiledPier(support=s, operator=foundations[s],  # type: ignore[index]
                  links=np.flatnonzero(bearings.support == s) if bearings else np.zeros(0, int),
                  block=(full_to_free[blocks.coordinates[s]] if s in blocks.coordinates
                         else None))
        for s in piled)


def assemble_structure(b: BridgeParameters, br: BearingParameters, pr: PierParameters,
                       fd: FoundationParameters, track_parameters: TrackParameters | None,
                       train_length: float,
                       foundations: Mapping[int, FoundationOperator] | None = None,
                       monolithic: bool = False, girder_bending: np.ndarray | None = None,
                       bearing_stiffness: np.ndarray | None = None) -> Structure:
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
    girder_bending
        Factor on the vertical bending stiffness of each girder element (damage);
        None: all 1.
    bearing_stiffness
        (n_spans + 1, 2) factor on the stiffness of the bearings of each support and
        side (damage); None: all 1.

    Returns
    -------
    Structure

    """
    piled = tuple(sorted((foundations or {}).keys()))
    beams = _beams(b, pr, fd, piled, track_parameters, train_length, girder_bending)
    # monolithic substructures: their coordinates as pseudo-nodes after the beams, the
    # pier top first (q[:6] is one node), the padding of the last node constrained
    blocks = piled_blocks(foundations or {}, piled if monolithic else (), beams.n_nodes,
                          beams.pier_top)
    n_full = blocks.n_nodes * NODE_DOFS
    k_full, m_full, c_full, f1, rayleigh = _beam_matrices(beams, n_full, b)
    k_full = add_piled_blocks(k_full, blocks, foundations or {}, 'stiffness')
    m_full = add_piled_blocks(m_full, blocks, foundations or {}, 'mass')
    c_full = add_piled_blocks(c_full, blocks, foundations or {}, 'damping')
    for links in beams.track.links if beams.track is not None else ():
        k_full = k_full + assemble_links(n_full, links.dofs, links.kinematics, links.stiffness)
        c_full = c_full + assemble_links(n_full, links.dofs, links.kinematics, links.damping)

    # Interfaces: bearings between girder ends and supports, foundations under piers.
    constrained = np.zeros(n_full, dtype=bool)
    constrained[blocks.padding] = True
    moving = np.zeros(b.n_spans + 1, dtype=bool)
    moving[list(piled)] = not monolithic
    ends_rigid, links_elastic = _bearings(br, beams, blocks, moving, bearing_stiffness)
    if ends_rigid is not None:
        constrained[ends_rigid.full_dofs] = True
    if links_elastic is not None:
        k_link, c_link = links_elastic.matrices(n_full)
        k_full, c_full = k_full + k_link, c_full + c_link
    bases = beams.pier_base[beams.pier_base >= 0]
    if bases.size:
        k_found, c_found = foundation_springs(fd, bases, n_full)
        k_full, c_full = k_full + k_found, c_full + c_found

    dof_map = _dof_map(beams, blocks, constrained)
    free, full_to_free = dof_map.free, dof_map.full_to_free
    rigid = (ends_rigid.supports(k_full, c_full, m_full, free) if ends_rigid is not None
             else None)
    bearings = (links_elastic.numbered(full_to_free, dof_map.n_free)
                if links_elastic is not None else None)
    mid = beams.girder_nodes[:, b.elements_per_span // 2]
    pier_supports = tuple(int(k) for k in np.flatnonzero((blocks.pier_top >= 0)
                                                         | np.isin(np.arange(b.n_spans + 1),
                                                                   piled)))
    tops = blocks.pier_top[list(pier_supports)]
    top_dofs = np.where(tops[:, None] >= 0,
                        full_to_free[np.maximum(tops, 0)[:, None] * NODE_DOFS + np.arange(3)],
                        dof_map.n_free)
    return Structure(mass=_reduce(m_full, free), damping=_reduce(c_full, free),
                     stiffness=_reduce(k_full, free), dofs=dof_map,
                     girder=girder_line(b, beams.girders.elements, full_to_free),
                     midspan_dofs=full_to_free[mid[:, None] * NODE_DOFS + np.arange(3)],
                     bearings=bearings, rigid=rigid, n_supports=b.n_spans + 1,
                     bearing_spacing=br.spacing, fundamental_frequency=f1, rayleigh=rayleigh,
                     girder_beam=beams.girder_beam, track=beams.track,
                     piled=_piled_piers(foundations, piled, blocks, bearings, full_to_free),
                     pier_supports=pier_supports, pier_top_dofs=top_dofs.reshape(-1, 3))


def _reduce(a: sp.csr_matrix, free: np.ndarray) -> sp.csr_matrix:
    """Return the free rows and columns of a full matrix."""
    return a[free][:, free].tocsr()
