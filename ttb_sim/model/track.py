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
Slab track on the girders and on the approaches ([P] Tables 2 and 4).

Two rails (3-D Euler beams, ``rail_elements_per_bay`` elements per fastener
bay) sit on discrete fasteners (spring-dashpots in x, y, z plus the pad's
resistance to rail roll). The fasteners hold the rails on unit track slabs;
each slab unit carries ``fasteners_per_slab`` fasteners and rests on a base
plate unit of the same length through a continuous spring-dashpot layer (the
filling layer). The base plates rest on the girder top through a second
continuous layer, and on rigid ground on the approaches before and after the
bridge. Slabs and base plates are 3-D beams whose nodes are the slab ends and
the fastener positions: PHYSICS.md accepts beams for slab and base below about
100 Hz; [P] uses Mindlin plates.

Heights (z up from the girder axis): girder top ``girder_top_height``, then the
base plate, the filling layer, the slab and the rail, stacked; the rails' axes
are at +/- ``rail_semi_spacing``. On the approaches the ground surface is at the
girder-top height. Track displacements, like the bridge's, are increments over
the dead-load state.

:func:`build_track` places the stations (fasteners, rail, slab and base nodes),
builds the beams and their :class:`~.beam_line.BeamLine` lookups, and the links
of :mod:`.track_links` (fasteners, the slab-base and base-girder layers).
"""

from __future__ import annotations

from dataclasses import dataclass
import math

import numpy as np

from ttb_sim.declarations import check_declared, param
from ttb_sim.fe.beam import BeamSection, NODE_DOFS
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.track_links import layer, LinkSet, node_dof_rows, node_link


@dataclass(frozen=True)
class TrackParameters:
    """
    Track on the girders and on the approaches ([P] Tables 2 and 4).

    ``slab``: two rails (3-D Euler beams) on discrete fasteners, a unit track
    slab and base plate (3-D beams) on continuous spring-dashpot layers. The
    dimensions of [P] Table 2 are those of CRTS III unit slabs.
    """

    model: str = param('none', '-', "'none': loads act on the girder axis; 'slab': rails on "
                       'fasteners on unit slabs on base plates, continued onto approaches.',
                       choices=('none', 'slab'))
    approach_length: float = param(0.0, 'm', 'Track on rigid ground before and after the '
                                   'bridge; 0 = train length + 20 m, so the whole train '
                                   'starts and ends off the bridge.', low=0.0, high=5000.0)
    rail_young_modulus: float = param(2.059e11, 'Pa', 'Rail elastic modulus ([P] Table 2).',
                                      low=1e9, high=1e13)
    rail_inertia_y: float = param(3.217e-5, 'm^4', 'Rail second moment about y (vertical '
                                  'bending).', low=1e-8, high=1e-2)
    rail_inertia_z: float = param(5.24e-6, 'm^4', 'Rail second moment about z (lateral '
                                  'bending).', low=1e-8, high=1e-2)
    rail_torsional_stiffness: float = param(1.958e5, 'N*m^2', 'Rail torsional stiffness GJ.',
                                            low=1.0, high=1e9)
    rail_polar_inertia: float = param(3.741e-5, 'm^4', 'Rail polar second moment (for the '
                                      'rotary inertia).', low=1e-8, high=1e-2)
    rail_mass: float = param(60.64, 'kg/m', 'Rail mass per metre.', low=1.0, high=1000.0)
    rail_semi_spacing: float = param(0.7465, 'm', 'Lateral distance of each rail axis from the '
                                     'track centre (at the wheel contact points).', low=0.3,
                                     high=1.5)
    rail_height: float = param(0.176, 'm', 'Rail height; the contact is at the top, the '
                               'fastener at the foot, the axis at mid-height.', low=0.05,
                               high=0.5)
    fastener_spacing: float = param(0.63, 'm', 'Fastener spacing ([P] Table 2).', low=0.2,
                                    high=2.0)
    rail_elements_per_bay: int = param(2, '-', 'Rail beam elements between fasteners.',
                                       low=1, high=16)
    fastener_vertical_stiffness: float = param(5e7, 'N/m', 'Fastener vertical stiffness.',
                                               low=1.0, high=1e12)
    fastener_lateral_stiffness: float = param(3e7, 'N/m', 'Fastener lateral stiffness.',
                                              low=1.0, high=1e12)
    fastener_longitudinal_stiffness: float = param(2e7, 'N/m', 'Fastener longitudinal '
                                                   'stiffness (assumed; not in [P]).', low=1.0,
                                                   high=1e12)
    fastener_vertical_damping: float = param(3.6e4, 'N*s/m', 'Fastener vertical damping.',
                                             low=0.0, high=1e9)
    fastener_lateral_damping: float = param(3e4, 'N*s/m', 'Fastener lateral (and '
                                            'longitudinal) damping.', low=0.0, high=1e9)
    rail_foot_width: float = param(0.15, 'm', 'Rail foot width: the pad resists rail roll '
                                   'with k_v w^2 / 12.', low=0.01, high=0.5)
    fasteners_per_slab: int = param(9, '-', 'Fasteners per slab unit (9 x 0.63 m = 5.67 m '
                                    'pitch: 5.6 m slab + gap).', low=1, high=100)
    slab_gap: float = param(0.07, 'm', 'Gap between slab units.', low=0.0, high=1.0)
    slab_width: float = param(2.5, 'm', 'Track slab width.', low=0.5, high=10.0)
    slab_thickness: float = param(0.21, 'm', 'Track slab thickness.', low=0.05, high=2.0)
    slab_young_modulus: float = param(3.6e10, 'Pa', 'Slab concrete modulus (C60).', low=1e8,
                                      high=1e12)
    base_width: float = param(3.1, 'm', 'Base plate width.', low=0.5, high=10.0)
    base_thickness: float = param(0.3, 'm', 'Base plate thickness.', low=0.05, high=2.0)
    base_young_modulus: float = param(3.25e10, 'Pa', 'Base plate concrete modulus (C40).',
                                      low=1e8, high=1e12)
    concrete_density: float = param(2500.0, 'kg/m^3', 'Density of slab and base plate '
                                    'concrete.', low=100.0, high=1e4)
    filling_thickness: float = param(0.09, 'm', 'Self-compacting filling layer between slab '
                                     'and base (its mass is shared between them).', low=0.0,
                                     high=1.0)
    layer_stiffness: float = param(1.5e9, 'N/m^2', 'Continuous layer stiffness per metre of '
                                   'track, vertical and lateral ([P] Table 4); used between '
                                   'slab and base, base and girder, base and ground.', low=1.0,
                                   high=1e13)
    layer_damping: float = param(8.3e4, 'N*s/m^2', 'Continuous layer damping per metre of '
                                 'track ([P] Table 4).', low=0.0, high=1e10)
    girder_top_height: float = param(1.1, 'm', 'Height of the girder top surface above the '
                                     'girder axis.', low=0.0, high=10.0)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'track parameter')


POISSON_CONCRETE = 0.2
STEEL_DENSITY = 7850.0


@dataclass(frozen=True)
class TrackMesh:
    """
    The track's share of the structure, before assembly.

    Node and DOF numbers are global (offset by the nodes that precede the
    track in the structure).
    """

    coords: np.ndarray
    """(n_nodes, 3) node coordinates."""
    elements: np.ndarray
    """(n_el, 2) global node numbers of each beam element."""
    sections: BeamSection
    rails: tuple[BeamLine, BeamLine]
    """Left (+y) and right (-y) rail."""
    slab: BeamLine
    base: BeamLine
    links: tuple[LinkSet, ...]
    """Fasteners, the slab-base layer and the base-girder/ground layer."""
    x_start: float
    x_end: float
    rail_head: float
    """Height of the rail top above the rail axis (m)."""
    n_fasteners: int


def _rect_section(n: int, young: float, width: float, thickness: float, density: float,
                  extra_mass: float = 0.0) -> BeamSection:
    """Return the 3-D beam section of a solid rectangle (width along y, thickness along z)."""
    area = width * thickness
    iy = width * thickness**3 / 12.0
    iz = thickness * width**3 / 12.0
    a, b = max(width, thickness), min(width, thickness)
    torsion = a * b**3 * (1.0 / 3.0 - 0.21 * b / a * (1.0 - b**4 / (12.0 * a**4)))
    shear = young / (2.0 * (1.0 + POISSON_CONCRETE))
    mass = density * area + extra_mass
    values = (young * area, shear * torsion, young * iy, young * iz, mass,
              mass / area * (iy + iz))
    return BeamSection(*(np.full(n, v) for v in values))


def approach_length(track: TrackParameters, train_length: float) -> float:
    """Return the approach length: as set, or the train length + 20 m (m)."""
    return track.approach_length or (train_length + 20.0)


@dataclass(frozen=True)
class TrackExtent:
    """Where the modelled track runs, known before it is built (m along the track)."""

    rail_start: float
    """First fastener: where the rails start."""
    rail_end: float
    """Last fastener: where the rails end."""
    unit_start: float
    """Start of the first slab / base unit."""
    unit_end: float
    """End of the last slab / base unit."""
    n_units: int
    """Number of slab / base units."""


def track_extent(track: TrackParameters, bridge_length: float,
                 train_length: float) -> TrackExtent:
    """
    Return the extent of the track :func:`build_track` would build, without building it.

    Parameters
    ----------
    track : TrackParameters
        Track keys of the scenario.
    bridge_length : float
        Total length of the girders (m).
    train_length : float
        Length of the train, for the automatic approach length (m).

    """
    approach = approach_length(track, train_length)
    s, n_f = track.fastener_spacing, track.fasteners_per_slab
    pitch = n_f * s
    margin = 0.5 * (s - track.slab_gap)
    x0 = -approach
    n_units = int(math.ceil((bridge_length + 2.0 * approach) / pitch))
    first = x0 + margin
    last = x0 + (n_units - 1) * pitch + margin + (n_f - 1) * s
    return TrackExtent(rail_start=first, rail_end=last, unit_start=x0,
                       unit_end=x0 + (n_units - 1) * pitch + pitch - track.slab_gap,
                       n_units=n_units)


@dataclass(frozen=True)
class _Stations:
    """Where the track's nodes are along x, and the heights of its beams (m)."""

    x_fast: np.ndarray
    """(n_fasteners,) fastener positions (rails run from the first to the last)."""
    x_rail: np.ndarray
    """Rail node positions, ``rail_elements_per_bay`` elements per fastener bay."""
    x_slab: np.ndarray
    """Slab / base nodes: per unit its start, the fasteners, its end."""
    per_unit: int
    """Slab / base nodes per unit."""
    z_rail: float
    z_slab: float
    z_base: float


def _stations(track: TrackParameters, extent: TrackExtent) -> _Stations:
    """Return the node positions of rails, slabs and base plates and the beams' heights."""
    s, n_f = track.fastener_spacing, track.fasteners_per_slab
    pitch = n_f * s
    margin = 0.5 * (s - track.slab_gap)
    x0, n_units = extent.unit_start, extent.n_units

    # Heights of the layer stack.
    h_g = track.girder_top_height
    z_base = h_g + 0.5 * track.base_thickness
    z_slab = h_g + track.base_thickness + track.filling_thickness + 0.5 * track.slab_thickness
    z_rail = z_slab + 0.5 * track.slab_thickness + 0.5 * track.rail_height

    # Fasteners and rail nodes (rails run from the first to the last fastener).
    unit0 = x0 + np.arange(n_units) * pitch
    x_fast = (unit0[:, None] + margin + np.arange(n_f)[None, :] * s).ravel()
    n_e = track.rail_elements_per_bay
    h = s / n_e
    n_rail_nodes = (x_fast.size - 1) * n_e + 1
    x_rail = x_fast[0] + np.arange(n_rail_nodes) * h

    # Slab / base nodes per unit: unit start, the fasteners, unit end.
    unit_len = pitch - track.slab_gap
    x_unit = np.concatenate([np.zeros((n_units, 1)),
                             margin + np.arange(n_f)[None, :] * s * np.ones((n_units, 1)),
                             np.full((n_units, 1), unit_len)], axis=1) + unit0[:, None]
    return _Stations(x_fast, x_rail, x_unit.ravel(), n_f + 2, z_rail, z_slab, z_base)


@dataclass(frozen=True)
class _Beams:
    """The track's beam elements: left rail, right rail, slab, base (global numbering)."""

    coords: np.ndarray
    elements: np.ndarray
    section: BeamSection
    ids: tuple[np.ndarray, ...]
    """Node numbers of each beam."""
    pairs: tuple[np.ndarray, ...]
    """(n_el, 2) node numbers of each beam's elements."""
    sections: tuple[BeamSection, ...]
    """Section of each beam."""


def _track_beams(track: TrackParameters, st: _Stations, first_node: int) -> _Beams:
    """Return the rails, the slabs and the base plates as beams from node ``first_node`` on."""
    coords, conn, sections = [], [], []
    node = first_node

    def add_line(x: np.ndarray, y: float, z: float, breaks: int | None) -> np.ndarray:
        nonlocal node
        ids = node + np.arange(x.size)
        coords.append(np.column_stack([x, np.full(x.size, y), np.full(x.size, z)]))
        pairs = np.column_stack([ids[:-1], ids[1:]])
        if breaks:
            keep = (np.arange(x.size - 1) % breaks) != breaks - 1
            pairs = pairs[keep]
        conn.append(pairs)
        node += x.size
        return ids

    e_r = track.rail_young_modulus
    rail_ids = []
    for side in (1.0, -1.0):
        ids = add_line(st.x_rail, side * track.rail_semi_spacing, st.z_rail, None)
        n = ids.size - 1
        sections.append(BeamSection(
            np.full(n, e_r * track.rail_mass / STEEL_DENSITY),
            np.full(n, track.rail_torsional_stiffness),
            np.full(n, e_r * track.rail_inertia_y), np.full(n, e_r * track.rail_inertia_z),
            np.full(n, track.rail_mass),
            np.full(n, STEEL_DENSITY * track.rail_polar_inertia)))
        rail_ids.append(ids)
    fill_mass = 0.5 * track.concrete_density * track.slab_width * track.filling_thickness
    slab_ids = add_line(st.x_slab, 0.0, st.z_slab, st.per_unit)
    sections.append(_rect_section(conn[-1].shape[0], track.slab_young_modulus,
                                  track.slab_width, track.slab_thickness,
                                  track.concrete_density, fill_mass))
    base_ids = add_line(st.x_slab, 0.0, st.z_base, st.per_unit)
    sections.append(_rect_section(conn[-1].shape[0], track.base_young_modulus,
                                  track.base_width, track.base_thickness,
                                  track.concrete_density, fill_mass))
    section = BeamSection(*(np.concatenate([getattr(sec, f) for sec in sections])
                            for f in ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x')))
    return _Beams(np.concatenate(coords), np.concatenate(conn), section,
                  (rail_ids[0], rail_ids[1], slab_ids, base_ids), tuple(conn), tuple(sections))


def _line(beams: _Beams, first_node: int, pairs: np.ndarray, y: float, z: float,
          sec: BeamSection | None = None) -> BeamLine:
    """Return the beam line of the elements ``pairs`` (global node numbers)."""
    start = beams.coords[pairs[:, 0] - first_node, 0]
    length = beams.coords[pairs[:, 1] - first_node, 0] - start
    dofs = (pairs[:, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    return BeamLine(start, length, dofs, z, y, sec)


def _fasteners(track: TrackParameters, st: _Stations, beams: _Beams,
               n_units: int) -> LinkSet:
    """Return the fasteners: rail foot on the slab top, one per rail and fastener position."""
    n_f, n_e = track.fasteners_per_slab, track.rail_elements_per_bay
    fast_rail_node = np.arange(st.x_fast.size) * n_e
    fast_slab_node = (np.arange(n_units)[:, None] * st.per_unit + 1 + np.arange(n_f)).ravel()
    dofs_f, kin_f = [], []
    for r, side in enumerate((1.0, -1.0)):
        a = beams.ids[r][fast_rail_node]
        b = beams.ids[2][fast_slab_node]
        arm_a = np.array([0.0, 0.0, -0.5 * track.rail_height])
        arm_b = np.array([0.0, side * track.rail_semi_spacing, 0.5 * track.slab_thickness])
        dofs_f.append(np.concatenate([node_dof_rows(a), node_dof_rows(b)], axis=1))
        kin_f.append(np.broadcast_to(node_link(arm_a, arm_b), (a.size, 4, 12)))
    n_fast = 2 * st.x_fast.size
    kf = np.tile([track.fastener_longitudinal_stiffness, track.fastener_lateral_stiffness,
                  track.fastener_vertical_stiffness,
                  track.fastener_vertical_stiffness * track.rail_foot_width**2 / 12.0],
                 (n_fast, 1))
    cf = np.tile([track.fastener_lateral_damping, track.fastener_lateral_damping,
                  track.fastener_vertical_damping, 0.0], (n_fast, 1))
    return LinkSet(np.concatenate(dofs_f), np.concatenate(kin_f), kf, cf)


def build_track(track: TrackParameters, bridge_length: float, train_length: float,
                first_node: int, girder: BeamLine) -> TrackMesh:
    """
    Build the track from x = -approach to bridge_length + approach.

    Parameters
    ----------
    track : TrackParameters
        Track keys of the scenario.
    bridge_length : float
        Total length of the girders (m); the bridge spans 0 .. bridge_length.
    train_length : float
        Length of the train, for the automatic approach length (m).
    first_node : int
        Global number of the first track node.
    girder : BeamLine
        The girders' axis (full DOFs); the base plates rest on its top surface.

    Returns
    -------
    TrackMesh

    """
    extent = track_extent(track, bridge_length, train_length)
    x0, n_units = extent.unit_start, extent.n_units
    x1 = x0 + n_units * (track.fasteners_per_slab * track.fastener_spacing)
    st = _stations(track, extent)
    beams = _track_beams(track, st, first_node)
    rails = (_line(beams, first_node, beams.pairs[0], track.rail_semi_spacing, st.z_rail,
                   beams.sections[0]),
             _line(beams, first_node, beams.pairs[1], -track.rail_semi_spacing, st.z_rail,
                   beams.sections[1]))
    slab = _line(beams, first_node, beams.pairs[2], 0.0, st.z_slab)
    base = _line(beams, first_node, beams.pairs[3], 0.0, st.z_base)
    # Continuous layers, integrated by Gauss quadrature over the upper beam's elements.
    k_l, c_l = track.layer_stiffness, track.layer_damping
    slab_base = layer(slab, np.array([0.0, 0.0, -0.5 * track.slab_thickness]),
                      base, np.array([0.0, 0.0, 0.5 * track.base_thickness]),
                      k_l, c_l, track.slab_width)
    base_girder = layer(base, np.array([0.0, 0.0, -0.5 * track.base_thickness]),
                        girder, np.array([0.0, 0.0, track.girder_top_height]), k_l, c_l,
                        track.base_width)
    fasteners = _fasteners(track, st, beams, n_units)
    return TrackMesh(coords=beams.coords, elements=beams.elements, sections=beams.section,
                     rails=rails, slab=slab, base=base,
                     links=(fasteners, slab_base, base_girder), x_start=x0, x_end=x1,
                     rail_head=0.5 * track.rail_height, n_fasteners=int(st.x_fast.size))
