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
The bridge's beams: multi-span simply supported girders and the pier columns.

Geometry (REP 103 track frame: x along the track, y left, z up): girder k
(0-based) spans x in [k L, (k + 1) L] at z = 0 and rests on supports k and k + 1.
Supports 0 and n_spans are abutments (always rigid ground); the intermediate ones
are piers. With spring or piled foundations each pier is a column of 3-D beam
elements from z = 0 down to z = -height (:func:`pier_block`). The bearings, the
foundations and the assembled structure are in :mod:`.bearings`,
:mod:`.foundation.pier_foundations` and :mod:`.structure`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
import math

import numpy as np

from ttb_sim.declarations import check_declared, param
from ttb_sim.fe.beam import BeamSection, NODE_DOFS, vertical_row, W_DOFS


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
class GirderLine:
    """
    Lookup from a position along the track to the girder element under it.

    DOF indices are *extended free* indices: constrained DOFs map to ``n_free``,
    a slot that always holds zero (see :class:`~ttb_sim.model.structure.Structure`).
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


def girder_line(b: BridgeParameters, elements: np.ndarray,
                full_to_free: np.ndarray) -> GirderLine:
    """Return the lookup of the girder elements ``elements`` (n_el, 2) under the track."""
    wfull = elements[:, [0, 0, 1, 1]] * NODE_DOFS + W_DOFS % NODE_DOFS
    return GirderLine(span_length=b.span_length, n_spans=b.n_spans,
                      elements_per_span=b.elements_per_span, w_dofs=full_to_free[wfull],
                      w_dofs_full=wfull)


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


def girder_block(b: BridgeParameters, bending_factors: np.ndarray | None = None
                 ) -> tuple[BeamBlock, np.ndarray]:
    """
    Return the girders (nodes 0.., ``elements_per_span`` elements per span) and their nodes.

    ``bending_factors`` (n_spans * elements_per_span,), if given, multiply the vertical
    bending stiffness of each element (damage,
    :func:`ttb_sim.model.damage.girder_bending_factors`).

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
    if bending_factors is not None:
        section = replace(section, ei_y=section.ei_y * bending_factors)
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


def _uniform_section(n: int, ea: float, gj: float, ei_y: float, ei_z: float, mass: float,
                     inertia_x: float) -> BeamSection:
    return BeamSection(*(np.full(n, v, dtype=float)
                         for v in (ea, gj, ei_y, ei_z, mass, inertia_x)))
