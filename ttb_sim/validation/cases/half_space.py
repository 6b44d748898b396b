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
V30: the frequency-domain reference on a homogeneous half-space, against Lamb's problem.

A pile of the soil's own material, bonded, is the ground itself: its head is a
square of the ground surface (side b = 0.886 m, the pile of 1 m diameter),
and the pipeline's harmonic head load (a uniform pressure on it, ``ttb-sim
frf``'s path: :func:`~ttb_sim.model.foundation.frequency_response.substructure_response`)
is a flexible square footing. Its head receptance, the tributary mean of the
vertical displacement over the square, is then the closed form
:func:`~ttb_sim.validation.references.half_space.square_patch_compliance` of a
homogeneous half-space with the same Rayleigh damping.

The block (8 x 8 m, 6 m deep; [P] Table 5's middle layer, E = 5 MPa,
nu = 0.25, Vs = 31.7 m/s) is wrapped in a 4 m perfectly matched layer, and
meshed three times, h = b / 2, b / 4, b / 8 at the load, growing by 1.3 to
0.5 m (10 to 63 elements per shear wavelength at 10 to 1 Hz). The receptance
converges at an observed order of about 1.1 (the load's edge, where the
traction jumps, governs it); Richardson's extrapolation of the three removes
the mesh's share.

Rows, at 1, 5 and 10 Hz: the extrapolated receptance against the closed form
(2 %: the matched layer's own error, about 1 % of |C| measured on this
block, and the extrapolation's, about 1 %); the radiation part (the imaginary
part) on the finest mesh against the closed form's (3 %); the ground point
2 m from the centre on the finest mesh (3 %: its cells are 0.4-0.5 m on every
mesh, 6.4 per shear wavelength at 10 Hz, so it is not extrapolated); the
finest mesh's whole error and the observed order, reported.
"""

from __future__ import annotations

from dataclasses import replace
import logging
import math
from typing import Any, Sequence

import numpy as np

from ttb_sim.model.foundation.frequency_response import MatchedLayer, substructure_response
from ttb_sim.model.foundation.records import (BlockSize, EQUAL_AREA_SIDE, Interface, MeshSize,
                                              Observation, PAPER_LAYERS, PileGroup, PileLoad,
                                              SoilLayer, SoilParameters, Substructure)
from ttb_sim.model.foundation.substructure import materials
from ttb_sim.validation.references.half_space import HalfSpace, square_patch_compliance
from ttb_sim.validation.rows import Case, relative_row, report_row, Row

LOG = logging.getLogger(__name__)

SIDE = EQUAL_AREA_SIDE * 1.0
"""Side b of the loaded square (m): the square pile of 1 m diameter."""
GROUND_POINT = 2.0
"""Distance (m) of the observed ground point from the square's centre, along x."""
V30_FREQUENCIES = (1.0, 5.0, 10.0)
V30_REFINEMENTS = (2, 4, 8)
"""The element size at the load is b over each of these."""


def soil_footing(h: float, block: float = 8.0, depth: float = 6.0, h_max: float = 0.5,
                 layer: SoilLayer = PAPER_LAYERS[1], boundary: str = 'viscoelastic'
                 ) -> Substructure:
    """Return a homogeneous block whose 'pile' is the soil itself: a square of the surface."""
    soil = SoilParameters((replace(layer, thickness=depth),), BlockSize(block, block),
                          MeshSize(h=h, growth=1.3, h_max=h_max, h_shaft=h_max),
                          boundary=boundary)
    ground = PileGroup(rows=1, cols=1, side=SIDE, length=min(2.0, 0.5 * depth), E=layer.E,
                       nu=layer.nu, rho=layer.rho, damping_ratio=layer.damping_ratio)
    return Substructure(soil=soil, piles=ground, interface=Interface(model='bonded'),
                        observation=Observation(line_points=0, val_points=False,
                                                points=((GROUND_POINT, 0.0, 0.0),)))


def half_space_of(spec: Substructure) -> HalfSpace:
    """Return the closed form's ground: the block's layer with its Rayleigh coefficients."""
    mats = materials(spec)
    layer = spec.soil.layers[0]
    return HalfSpace(layer.E, layer.nu, layer.rho, float(mats.alpha[0]), float(mats.beta[0]))


def footing_receptances(h: float, frequencies: Sequence[float], pml: float = 4.0,
                        **block: Any) -> np.ndarray:
    """
    Return the receptances (m/N, complex) of the square and of the ground point.

    Shape (n_f, 2): the square's mean vertical displacement, then the vertical
    displacement at (GROUND_POINT, 0, 0), per newton; mesh size h at the load.
    """
    spec = soil_footing(h, **block)
    load = PileLoad('harmonic', 1.0, frequencies[0], pile=1, direction='z', target='pile')
    got = substructure_response(spec, load, frequencies, layer=MatchedLayer(pml))
    LOG.info('V30: h = %.4g m, %d unknowns, %.0f s', h, got.unknowns, sum(got.seconds))
    return np.stack([got.heads[:, 0, 2], got.points[:, 0, 2]], axis=1)


def richardson(values: Sequence[complex], ratio: float = 2.0) -> tuple[complex, float]:
    """
    Return the extrapolation to h = 0 of values on three meshes, and the observed order.

    The meshes' sizes fall by ``ratio`` from one to the next; the order is
    log(|c1 - c2| / |c2 - c3|) / log(ratio) (NaN, and no extrapolation, when
    the differences do not shrink).
    """
    c1, c2, c3 = (complex(v) for v in values)
    shrink = abs(c1 - c2) / abs(c2 - c3) if c2 != c3 else math.inf
    if not 1.0 < shrink < math.inf:
        return c3, math.nan
    order = math.log(shrink) / math.log(ratio)
    return c3 + (c3 - c2) / (ratio**order - 1.0), order


def v30() -> list[Row]:
    """Return the rows of V30 (see the module docstring)."""
    sizes = [SIDE / n for n in V30_REFINEMENTS]
    fe = np.array([footing_receptances(h, V30_FREQUENCIES) for h in sizes])
    ground = half_space_of(soil_footing(sizes[0]))
    rows: list[Row] = []
    for i, f in enumerate(V30_FREQUENCIES):
        exact = square_patch_compliance(ground, f, SIDE)
        extrapolated, order = richardson(list(fe[:, i, 0]))
        rows.append(complex_row('V30', f'C extrapolated, {f:g} Hz', extrapolated, exact, 0.02,
                                'm/N'))
        rows.append(relative_row('V30', f'Im C (radiation), b/8, {f:g} Hz', fe[-1, i, 0].imag,
                                 exact.imag, 0.03, 'm/N'))
        point = square_patch_compliance(ground, f, SIDE, at=GROUND_POINT)
        rows.append(complex_row('V30', f'ground point {GROUND_POINT:g} m, b/8, {f:g} Hz',
                                fe[-1, i, 1], point, 0.03, 'm/N'))
        rows.append(report_row('V30', f'|C| on b/8 alone, {f:g} Hz', abs(fe[-1, i, 0]), 'm/N',
                               abs(exact)))
        rows.append(report_row('V30', f'observed order, {f:g} Hz', order))
    return rows


def complex_row(case: str, quantity: str, computed: complex, exact: complex, tolerance: float,
                unit: str = '') -> Row:
    """Build a row of amplitudes judged by |computed / exact - 1| (amplitude and phase)."""
    error = abs(computed / exact - 1)
    return Row(case, quantity, abs(computed), abs(exact), error, tolerance, error <= tolerance,
               unit)


HALF_SPACE_CASES = (
    Case('V30', 'homogeneous half-space: a flexible square footing through frf with a matched '
         "layer, three meshes, against Lamb's closed form (about 3 min)", v30),
)
"""The half-space case, registered with the validation suite."""
