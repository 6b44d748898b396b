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
Unit slab and base plate: the pipeline's 3-D beams against Mindlin plates.

The track model (:mod:`ttb_sim.model.track`) represents each unit slab and
base plate by 3-D Euler beams along the track; [P] uses Mindlin plates. This
module compares the two for one unit:

- the beam is built by :func:`ttb_sim.model.track.build_track` itself (a track
  of exactly one unit, the girder replaced by rigid ground), so its nodes,
  sections (including the torsion constant and the filling-layer mass share)
  and continuous layers are those a simulation uses;
- the plate is a Mindlin plate (:mod:`ttb_sim.fe.mindlin`) of the same
  length, width, thickness, modulus and mass per area, on a Winkler
  foundation k = layer stiffness / width where the beam rests on its layer.

Modes are paired by the modal assurance criterion (MAC) on two fields sampled
at the beam's nodes: the mean deflection across the width and the twist
(least-squares slope across the width) times the width's radius of gyration
b / sqrt(12). Plate modes whose deflection is mostly outside that rigid
cross-section motion (transverse bending across the width) have no beam
counterpart; beam modes that move mostly in-plane (lateral bending, axial)
have no counterpart in a bending plate. Both kinds are listed apart.

For the slab on its layer the rail-seat receptance (vertical displacement over
force, 0-100 Hz) is compared as well; the plate is loaded by a uniform
pressure on a rail-seat patch (rail-foot width square) so that the Mindlin
plate's logarithmic point-load singularity does not enter.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import logging
import math

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from ttb_sim.fe.assembly import assemble, assemble_links
from ttb_sim.fe.beam import global_matrices, NODE_DOFS
from ttb_sim.fe.mindlin import MindlinPlate, plate_matrices, PlateMesh, rectangular_mesh
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.track import build_track, POISSON_CONCRETE, TrackMesh, TrackParameters
from ttb_sim.validation.rows import Case, relative_row, Row

LOG = logging.getLogger(__name__)

#: Plate element size (m); halving it changes the slab frequencies below
#: 150 Hz and the rail-seat receptances by at most 0.6 %.
ELEMENT_SIZE = 0.16

#: MAC above which a beam and a plate mode are called a pair.
MAC_PAIR = 0.8

#: Share of the plate's deflection energy outside rigid cross-section motion
#: above which a plate mode is called transverse bending.
TRANSVERSE_SHARE = 0.5

#: Ignore modes below this frequency (rigid-body modes of the free units) (Hz).
RIGID_LIMIT = 1.0


@dataclass(frozen=True)
class ModeSet:
    """
    Eigenfrequencies and sampled shapes of one model.

    Attributes
    ----------
    frequency : numpy.ndarray
        (n,) eigenfrequencies (Hz), ascending, rigid-body modes removed.
    shape : numpy.ndarray
        (n, 2 n_stations) mean deflection and b/sqrt(12) x twist at the stations.
    outside : numpy.ndarray
        (n,) share of the mode that neither model can pair: the plate's
        transverse bending, or the beam's in-plane motion.

    """

    frequency: np.ndarray
    shape: np.ndarray
    outside: np.ndarray


@dataclass(frozen=True)
class ModePair:
    """One beam mode and the plate mode that matches it best."""

    label: str
    beam: float
    plate: float
    mac: float

    @property
    def difference(self) -> float:
        """Return (beam - plate) / plate."""
        return (self.beam - self.plate) / self.plate


@dataclass(frozen=True)
class Comparison:
    """
    Beam against plate for one unit.

    Attributes
    ----------
    pairs : tuple of ModePair
        Beam modes of the vertical plane and torsion with their plate partner.
    plate_only : tuple of (str, float)
        Plate modes without a beam partner (transverse bending), with frequency (Hz).
    beam_only : tuple of (str, float)
        Beam modes without a plate partner (in-plane), with frequency (Hz).

    """

    pairs: tuple[ModePair, ...]
    plate_only: tuple[tuple[str, float], ...]
    beam_only: tuple[tuple[str, float], ...]


def unit_track(track: TrackParameters | None = None) -> TrackMesh:
    """
    Build a track of exactly one slab unit with the pipeline's own builder.

    The girder is replaced by rigid ground (DOFs -1), so the base plate's lower
    layer is grounded. Node numbers start at 0.
    """
    track = replace(track or TrackParameters(), model='slab')
    pitch = track.fasteners_per_slab * track.fastener_spacing
    track = replace(track, approach_length=0.2499 * pitch)
    ground = BeamLine(start=np.zeros(1), length=np.array([0.5 * pitch]),
                      dofs=-np.ones((1, 12), dtype=int), z=0.0)
    mesh = build_track(track, 0.5 * pitch, 0.0, 0, ground)
    if mesh.slab.start.size != track.fasteners_per_slab + 1:
        raise RuntimeError('the one-unit track does not hold exactly one slab unit')
    return mesh


def _component(track: TrackParameters, component: str) -> tuple[float, float, float, int]:
    """Return (width, thickness, modulus, link set index) of 'slab' or 'base'."""
    if component == 'slab':
        return track.slab_width, track.slab_thickness, track.slab_young_modulus, 1
    if component == 'base':
        return track.base_width, track.base_thickness, track.base_young_modulus, 2
    raise ValueError(f"component must be 'slab' or 'base', got {component!r}")


@dataclass(frozen=True)
class BeamUnit:
    """Stiffness, mass and DOF map of one unit's beam, as the pipeline builds it."""

    stiffness: np.ndarray
    mass: np.ndarray
    line: BeamLine
    dofs: np.ndarray
    """(n_local,) full DOF numbers of the local DOFs (the unit's nodes, 6 each)."""
    x: np.ndarray
    """(n_nodes,) node positions from the unit start (m)."""

    def local(self, full: np.ndarray) -> np.ndarray:
        """Return the local indices of full DOF numbers."""
        return np.searchsorted(self.dofs, full)


def beam_unit(component: str = 'slab', on_layer: bool = False,
              track: TrackParameters | None = None) -> BeamUnit:
    """
    Return the pipeline's beam of one slab (or base plate) unit.

    Parameters
    ----------
    component : str
        'slab' or 'base'.
    on_layer : bool
        Add the continuous layer under it (slab: on a rigid base plate; base
        plate: on rigid ground), as assembled by the pipeline.
    track : TrackParameters, optional
        Track keys; the defaults ([P] Tables 2 and 4) when omitted.

    """
    track = track or TrackParameters()
    mesh = unit_track(track)
    _, _, _, link_index = _component(track, component)
    line = mesh.slab if component == 'slab' else mesh.base
    first = mesh.elements[:, 0] * NODE_DOFS
    rows = np.flatnonzero(np.isin(first, line.dofs[:, 0]))
    n_full = mesh.coords.shape[0] * NODE_DOFS
    edofs = (mesh.elements[rows, :, None] * NODE_DOFS + np.arange(NODE_DOFS)).reshape(-1, 12)
    section = type(mesh.sections)(*(getattr(mesh.sections, f)[rows] for f in
                                    ('ea', 'gj', 'ei_y', 'ei_z', 'mass', 'inertia_x')))
    ke, me, _ = global_matrices(mesh.coords[mesh.elements[rows, 0]],
                                mesh.coords[mesh.elements[rows, 1]], section)
    k = assemble(n_full, edofs, ke)
    m = assemble(n_full, edofs, me)
    if on_layer:
        links = mesh.links[link_index]
        dofs = links.dofs.copy()
        dofs[:, 12:] = -1          # the layer's lower side is rigid
        k = k + assemble_links(n_full, dofs, links.kinematics, links.stiffness)
    local = np.unique(edofs)
    nodes = np.unique(mesh.elements[rows])
    x = mesh.coords[nodes, 0] - mesh.coords[nodes, 0].min()
    return BeamUnit(k[local][:, local].toarray(), m[local][:, local].toarray(), line, local, x)


def plate_of(component: str = 'slab', track: TrackParameters | None = None) -> MindlinPlate:
    """
    Return the Mindlin plate of a slab or base-plate unit.

    Modulus, thickness and Poisson's ratio are the track's; the density gives
    the beam section's mass per length (filling-layer share included) over the
    width.
    """
    track = track or TrackParameters()
    width, thickness, young, _ = _component(track, component)
    mesh = unit_track(track)
    line = mesh.slab if component == 'slab' else mesh.base
    first = mesh.elements[:, 0] * NODE_DOFS
    row = np.flatnonzero(first == line.dofs[0, 0])[0]
    mass = float(mesh.sections.mass[row])
    return MindlinPlate(young, POISSON_CONCRETE, thickness, mass / (width * thickness))


def _grid(breaks: np.ndarray, size: float) -> np.ndarray:
    """Return grid lines through the sorted breakpoints, spaced at most ``size``."""
    breaks = np.unique(np.round(breaks, 9))
    parts = [np.linspace(a, b, int(math.ceil((b - a) / size - 1e-9)) + 1)[:-1]
             for a, b in zip(breaks[:-1], breaks[1:])]
    return np.concatenate(parts + [breaks[-1:]])


def plate_mesh(component: str = 'slab', track: TrackParameters | None = None,
               element_size: float = ELEMENT_SIZE) -> tuple[PlateMesh, np.ndarray]:
    """
    Return the plate mesh of one unit and the beam node positions on it.

    Grid lines pass through the beam nodes (slab ends, fasteners), the rail
    axes and the edges of the rail-seat patches.
    """
    track = track or TrackParameters()
    width, _, _, _ = _component(track, component)
    x_nodes = beam_unit(component, False, track).x
    half = 0.5 * track.rail_foot_width
    seats = x_nodes[1:-1]
    x = _grid(np.concatenate([x_nodes, seats - half, seats + half]), element_size)
    r = track.rail_semi_spacing
    y = _grid(np.array([-0.5 * width, -r - half, -r, -r + half, 0.0, r - half, r, r + half,
                        0.5 * width]), element_size)
    return rectangular_mesh(x, y), x_nodes


def _eig(k: np.ndarray | sp.spmatrix, m: np.ndarray | sp.spmatrix,
         f_max: float, n_guess: int = 40) -> tuple[np.ndarray, np.ndarray]:
    """Return eigenfrequencies (Hz) up to f_max (rigid modes removed) and mode shapes."""
    if isinstance(k, np.ndarray) and isinstance(m, np.ndarray):
        w2, v = la.eigh(k, m)
    else:
        sigma = -(2 * math.pi * RIGID_LIMIT) ** 2
        # A fixed start vector: ARPACK's default one is random, and the modes must
        # come out the same, bit for bit, on every run.
        start = np.ones(k.shape[0])
        w2, v = sla.eigsh(sp.csc_matrix(k), min(n_guess, k.shape[0] - 2), sp.csc_matrix(m),
                          sigma=sigma, v0=start)
    order = np.argsort(w2)
    f = np.sqrt(np.abs(w2[order])) / (2 * math.pi)
    keep = (f > RIGID_LIMIT) & (f <= f_max)
    if sp.issparse(k) and f[-1] <= f_max:
        LOG.warning('plate eigen-solve may have missed modes below %.0f Hz', f_max)
    return f[keep], v[:, order][:, keep]


def beam_modes(component: str = 'slab', on_layer: bool = False,
               track: TrackParameters | None = None, f_max: float = 150.0) -> ModeSet:
    """Return the modes of the pipeline's beam of one unit up to f_max."""
    track = track or TrackParameters()
    width, _, _, _ = _component(track, component)
    unit = beam_unit(component, on_layer, track)
    f, v = _eig(unit.stiffness, unit.mass, f_max)
    n_nodes = unit.x.size
    comp = v.reshape(n_nodes, NODE_DOFS, -1)
    shape = np.concatenate([comp[:, 2], width / math.sqrt(12.0) * comp[:, 3]], axis=0).T
    # Kinetic energy share of the in-plane DOFs (ux, uy, rz).
    energy = v * (unit.mass @ v)
    e = energy.reshape(n_nodes, NODE_DOFS, -1)
    in_plane = e[:, [0, 1, 5]].sum(axis=(0, 1)) / energy.sum(axis=0)
    return ModeSet(f, shape, in_plane)


def _trapezoid(x: np.ndarray) -> np.ndarray:
    """Return trapezoidal-rule weights on the points x."""
    d = np.diff(x)
    w = np.zeros_like(x)
    w[:-1] += 0.5 * d
    w[1:] += 0.5 * d
    return w


def plate_modes(component: str = 'slab', on_layer: bool = False,
                track: TrackParameters | None = None, f_max: float = 150.0,
                element_size: float = ELEMENT_SIZE) -> ModeSet:
    """Return the modes of the Mindlin plate of one unit up to f_max."""
    track = track or TrackParameters()
    width, _, _, link_index = _component(track, component)
    plate = plate_of(component, track)
    mesh, x_nodes = plate_mesh(component, track, element_size)
    k_found = track.layer_stiffness / width if on_layer else 0.0
    k, m = plate_matrices(mesh, plate, k_found)
    f, v = _eig(k, m, f_max)
    w = v[0::3].reshape(mesh.y.size, mesh.x.size, -1)        # (ny, nx, n)
    ty, tx = _trapezoid(mesh.y), _trapezoid(mesh.x)
    y = mesh.y - 0.5 * (mesh.y[0] + mesh.y[-1])
    mean = np.einsum('j,jin->in', ty, w) / ty.sum()
    twist = np.einsum('j,j,jin->in', ty, y, w) / np.sum(ty * y**2)
    rest = w - mean[None] - y[:, None, None] * twist[None]
    share = (np.einsum('j,i,jin->n', ty, tx, rest**2)
             / np.einsum('j,i,jin->n', ty, tx, w**2))
    cols = np.abs(mesh.x[:, None] - x_nodes[None, :]).argmin(axis=0)
    shape = np.concatenate([mean[cols], width / math.sqrt(12.0) * twist[cols]], axis=0).T
    return ModeSet(f, shape, share)


def mac(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Return the MAC matrix of the rows of a against the rows of b."""
    num = (a @ b.T) ** 2
    return num / np.outer(np.sum(a * a, axis=1), np.sum(b * b, axis=1))


def _kind(shape: np.ndarray) -> str:
    """Name a paired mode after the larger of its two sampled fields."""
    n = shape.size // 2
    bend, twist = np.sum(shape[:n] ** 2), np.sum(shape[n:] ** 2)
    return 'vertical bending' if bend >= twist else 'torsion'


def compare(component: str = 'slab', on_layer: bool = False,
            track: TrackParameters | None = None, f_max: float = 150.0,
            element_size: float = ELEMENT_SIZE) -> Comparison:
    """
    Pair the beam's and the plate's modes of one unit up to f_max.

    Parameters
    ----------
    component : str
        'slab' or 'base'.
    on_layer : bool
        Free-free (False) or on the unit's continuous layer over rigid ground.
    track : TrackParameters, optional
        Track keys (defaults: [P] Tables 2 and 4).
    f_max : float
        Highest frequency considered (Hz). The plate is solved to 1.3 f_max so
        that partners just above f_max are found.
    element_size : float
        Plate element size (m).

    Returns
    -------
    Comparison

    """
    beam = beam_modes(component, on_layer, track, f_max)
    plate = plate_modes(component, on_layer, track, 1.3 * f_max, element_size)
    beamlike = plate.outside < TRANSVERSE_SHARE
    mat = mac(beam.shape, plate.shape) * beamlike[None, :]
    pairs, used, beam_only = [], set(), []
    counts: dict[str, int] = {}
    for i, f in enumerate(beam.frequency):
        if beam.outside[i] > 0.5:
            beam_only.append(('in-plane (lateral bending / axial)', float(f)))
            continue
        j = int(np.argmax(mat[i]))
        if mat[i, j] < MAC_PAIR:
            beam_only.append(('out-of-plane, no plate partner', float(f)))
            continue
        kind = _kind(beam.shape[i])
        counts[kind] = counts.get(kind, 0) + 1
        pairs.append(ModePair(f'{kind} {counts[kind]}', float(f), float(plate.frequency[j]),
                              float(mat[i, j])))
        used.add(j)
    plate_only = [(f'transverse bending ({100 * plate.outside[j]:.0f} % off-section)',
                   float(plate.frequency[j])) for j in range(plate.frequency.size)
                  if j not in used and plate.frequency[j] <= f_max and not beamlike[j]]
    plate_only += [('unpaired beam-like', float(plate.frequency[j]))
                   for j in range(plate.frequency.size)
                   if j not in used and plate.frequency[j] <= f_max and beamlike[j]]
    return Comparison(tuple(pairs), tuple(sorted(plate_only, key=lambda r: r[1])),
                      tuple(beam_only))


def rail_seat_receptance(frequencies: np.ndarray, fastener: int = 0, both_rails: bool = False,
                         track: TrackParameters | None = None,
                         element_size: float = ELEMENT_SIZE) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the vertical rail-seat receptance of the slab on its layer (m/N).

    A unit force acts at fastener ``fastener`` (0 = next to the slab end) under
    the +y rail (or under both rails), on the slab top; the response is the
    vertical displacement at the same place (plate: averaged over the
    rail-seat patch, the work-conjugate of the uniform patch pressure; both
    rails: the mean of the two seats). Undamped.

    Parameters
    ----------
    frequencies : array
        Frequencies (Hz); keep them below the first resonance on the layer.
    fastener : int
        Fastener index within the unit.
    both_rails : bool
        Load both rail seats of the fastener (as a wheelset does) instead of one.
    track : TrackParameters, optional
        Track keys.
    element_size : float
        Plate element size (m).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Beam and plate receptance at each frequency.

    """
    track = track or TrackParameters()
    unit = beam_unit('slab', True, track)
    x_seat = unit.x[1 + fastener]
    r = track.rail_semi_spacing
    sides = np.array([1.0, -1.0]) if both_rails else np.array([1.0])
    arm = np.column_stack([np.zeros(sides.size), sides * r,
                           np.full(sides.size, 0.5 * track.slab_thickness)])
    element, rows, _ = unit.line.rows(np.full(sides.size, x_seat + unit.line.start[0]), arm)
    load_b = np.zeros(unit.dofs.size)
    np.add.at(load_b, unit.local(unit.line.dofs[element]).ravel(), rows[:, 2].ravel())

    plate = plate_of('slab', track)
    mesh, _ = plate_mesh('slab', track, element_size)
    k, m = plate_matrices(mesh, plate, track.layer_stiffness / track.slab_width)
    half = 0.5 * track.rail_foot_width
    centre = mesh.nodes[mesh.elements].mean(axis=1)
    inside = ((np.abs(centre[:, 0] - x_seat) < half)
              & (np.abs(np.abs(centre[:, 1]) - r) < half)
              & (np.sign(centre[:, 1])[:, None] == sides[None, :]).any(axis=1))
    corner = mesh.nodes[mesh.elements[inside]]
    area = ((corner[:, 1, 0] - corner[:, 0, 0]) * (corner[:, 3, 1] - corner[:, 0, 1]))
    load_p = np.zeros(mesh.n_dofs)
    np.add.at(load_p, 3 * mesh.elements[inside].ravel(), np.repeat(area / 4.0, 4))
    load_p *= sides.size / area.sum()

    beam, slab = [], []
    for f in np.asarray(frequencies, dtype=float):
        w2 = (2 * math.pi * f) ** 2
        beam.append(load_b @ la.solve(unit.stiffness - w2 * unit.mass, load_b) / sides.size)
        slab.append(load_p @ sla.spsolve((k - w2 * m).tocsc(), load_p) / sides.size)
    return np.array(beam), np.array(slab)


def format_comparison(comparison: Comparison) -> str:
    """Format a comparison as text lines (pairs, then unpaired modes)."""
    lines = [f'{"mode":24s} {"beam Hz":>9s} {"plate Hz":>9s} {"diff":>8s} {"MAC":>6s}']
    for p in comparison.pairs:
        lines.append(f'{p.label:24s} {p.beam:9.2f} {p.plate:9.2f} '
                     f'{100 * p.difference:7.2f}% {p.mac:6.3f}')
    for label, f in comparison.plate_only:
        lines.append(f'plate only: {label} {f:.2f} Hz')
    for label, f in comparison.beam_only:
        lines.append(f'beam only: {label} {f:.2f} Hz')
    return '\n'.join(lines)


def support_differences(frequencies: np.ndarray, track: TrackParameters | None = None,
                        element_size: float = ELEMENT_SIZE) -> dict[str, np.ndarray]:
    """
    Return beam-over-plate differences of the rail-seat receptance, per fastener.

    The unit slab on its layer is loaded at each fastener position of one half
    of the (symmetric) unit, under one rail and under both rails.

    Returns
    -------
    dict
        ``'slab'``: (2, n_half, n_freq) relative difference H_beam / H_plate - 1
        of the slab alone; ``'support'``: the same for the rail-seat support
        seen by the rail, the fastener's vertical compliance in series
        (1 / k_f + H).

    """
    track = track or TrackParameters()
    n_half = (track.fasteners_per_slab + 1) // 2
    slab, support = np.zeros((2, 2, n_half, len(frequencies)))
    soft = 1.0 / track.fastener_vertical_stiffness
    for r, both in enumerate((False, True)):
        for i in range(n_half):
            hb, hp = rail_seat_receptance(frequencies, i, both, track, element_size)
            slab[r, i] = hb / hp - 1.0
            support[r, i] = (soft + hb) / (soft + hp) - 1.0
    return {'slab': slab, 'support': support}


def x1_rows() -> list[Row]:
    """
    Return the validation rows X1: the pipeline's beam slab against a Mindlin plate.

    Free-free unit slab: vertical bending 1 and 2 (1 %) and torsion 1 (3 %);
    the unit slab on its layer: the rail-seat support (fastener in series with
    the slab) over 0-100 Hz, worst fastener and load case (2 %).
    """
    free = compare('slab', False)
    pairs = {p.label: p for p in free.pairs}
    rows = [relative_row('X1', f'slab {label}, free-free', pairs[label].beam,
                         pairs[label].plate, tol, 'Hz')
            for label, tol in (('vertical bending 1', 0.01), ('vertical bending 2', 0.01),
                               ('torsion 1', 0.03))]
    diff = support_differences(np.linspace(0.0, 100.0, 11))['support']
    worst = float(np.abs(diff).max())
    rows.append(Row('X1', 'rail-seat support 0-100 Hz, beam/plate', 1.0 + worst, 1.0, worst,
                    0.02, worst <= 0.02, '-'))
    return rows


SLAB_PLATE_CASES: tuple[Case, ...] = (
    Case('X1', 'unit slab: pipeline 3-D beam against a Mindlin plate', x1_rows),
)
