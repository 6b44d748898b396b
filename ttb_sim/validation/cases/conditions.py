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
V25 (scour) and V26 (temperature): the scenario's conditions against closed forms.

V25. The V14 single pile (d = 1.0 m, L = 12 m in [P] Table 5's soil, piles bonded)
with the soil above a scour depth removed, as a bridge run removes it around a
piled pier (:func:`~ttb_sim.model.damage.damaged_substructure`: the layers split at
the scour line, the soil above it left with 1e-6 of its modulus and density), its
static vertical head stiffness through the model's mesh, assembly and static solve,
against the independent FE of :mod:`~ttb_sim.validation.references.independent_fe`
(scikit-fem) on the same mesh, given the *sound* layers and the scour depth: it
removes the soil by geometry (every soil cell and outer face above the depth), not by
layers. Tolerance 1e-6 (one discretisation solved by two codes: measured 4e-12); a
scour that did not reach the model's soil would be 11 to 50 % off. Reported beside
it (not judged): the shipped Desai interface's scoured stiffness, and Randolph-Wroth
below a free length (:func:`~ttb_sim.validation.references.pile_soil.scoured_pile_stiffness`),
whose own accuracy falls as the embedded length shortens (-5.6 % sound, -12 % at 6 m).

V26. The first bending frequency of the ``moving_force_beam`` span (rigid
bearings) at a temperature, through the assembled structure and its modes as
``ttb-sim modes`` finds them, against the exact simply supported frequency of the
span at E(T) = E_ref (1 + alpha_E (T - T_ref)): f(T) = f_ref sqrt(1 + alpha_E
(T - T_ref)). Tolerance 0.1 %, as V23 (the 16-element mesh is within 1.1e-6 of the
continuum); without the modulus change the rows would be 1.5 to 5.8 % off.
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.config import load_scenario
from ttb_sim.model.damage import damaged_substructure, DamageParameters, Scour, SCOUR_RESIDUAL
from ttb_sim.model.foundation.records import Substructure
from ttb_sim.model.foundation.substructure import build
from ttb_sim.validation.cases.damage import first_bending_frequency, V23_TOLERANCE
from ttb_sim.validation.cases.pile_soil import head_stiffness, single_pile
from ttb_sim.validation.references.independent_fe import IndependentBlock
from ttb_sim.validation.references.pile_soil import scoured_pile_stiffness
from ttb_sim.validation.references.stepped_beam import SteppedBeam
from ttb_sim.validation.rows import Case, relative_row, report_row, Row

V25_DEPTHS = (2.0, 4.0, 6.0)
"""Scour depths (m): on the first layer boundary, inside the second layer, half the pile."""
V25_TOLERANCE = 1e-6
"""On the scoured head stiffness against the independent FE (see the module docstring)."""
V25_PIER = 2
"""The support number the scour entry names (any piled pier: the block is the pier's)."""

V26_CASES: tuple[tuple[float, float], ...] = ((-20.0, -0.003), (0.0, -0.003), (40.0, -0.003),
                                              (-10.0, -0.001))
"""(temperature (degC), girder modulus coefficient alpha_E (1/degC)) of each V26 row."""


def scoured(spec: Substructure, depth: float) -> Substructure:
    """Return the substructure as a bridge run builds it with ``damage.scour`` at ``depth``."""
    damage = DamageParameters(scour=(Scour(pier=V25_PIER, depth=depth),))
    return damaged_substructure(spec, V25_PIER, damage)


def scoured_reference(spec: Substructure, depth: float) -> float:
    """Return the closed-form head stiffness (N/m) of the spec's pile scoured to ``depth``."""
    piles = spec.piles
    assert piles is not None
    layers = spec.soil.layers
    return scoured_pile_stiffness([la.thickness for la in layers], [la.G for la in layers],
                                  layers[-1].nu, piles.length, piles.diameter, piles.E,
                                  piles.width**2, depth)


def independent_head_stiffness(spec: Substructure, depth: float) -> float:
    """Return the independent FE's static head stiffness (N/m) of the mesh ``spec`` builds."""
    model = build(scoured(spec, depth))
    block = IndependentBlock(spec, model.mesh.nodes, model.mesh.cells, removed_above=depth,
                             residual=SCOUR_RESIDUAL)
    head = block.head_weights(1, 2)
    return 1.0 / block.response(0.0, head, head, np.zeros((0, 3))).head.real


def v25_rows(depths: tuple[float, ...] = V25_DEPTHS, h: float = 0.443) -> list[Row]:
    """Return the rows of V25 on the single pile meshed with bricks of ``h`` at the pile."""
    bonded = single_pile(h=h, interface='bonded')
    shipped = single_pile(h=h)
    rows = []
    for depth in depths:
        computed = head_stiffness(scoured(bonded, depth))
        rows += [relative_row('V25', f'head stiffness, scour {depth:g} m', computed,
                              independent_head_stiffness(bonded, depth), V25_TOLERANCE, 'N/m'),
                 report_row('V25', f'Desai interface, scour {depth:g} m',
                            head_stiffness(scoured(shipped, depth)), 'N/m', computed),
                 report_row('V25', f'Randolph-Wroth below {depth:g} m free length',
                            scoured_reference(bonded, depth), 'N/m', computed)]
    return rows


def v26_rows() -> list[Row]:
    """Return the rows of V26 (see the module docstring)."""
    bridge = load_scenario('moving_force_beam').bridge
    reference_frequency = float(SteppedBeam.with_zones(
        bridge.span_length, bridge.bending_stiffness, bridge.mass_per_length, ()
    ).frequencies(1)[0])
    rows = []
    for temperature, alpha in V26_CASES:
        env = load_scenario('moving_force_beam').environment
        factor = 1.0 + alpha * (temperature - env.reference_temperature)
        computed = first_bending_frequency([f'environment.temperature={temperature!r}',
                                            f'environment.girder_modulus_coefficient={alpha!r}'])
        rows.append(relative_row('V26', f'f1 at {temperature:g} degC, alpha_E {alpha:g}/degC',
                                 computed, reference_frequency * math.sqrt(factor),
                                 V23_TOLERANCE, 'Hz'))
    return rows


CONDITION_CASES: tuple[Case, ...] = (
    Case('V25', 'scour: single-pile head stiffness with the top soil removed against '
                'the independent FE on the same mesh (about 3 min)', v25_rows),
    Case('V26', 'temperature: first bending frequency against sqrt(E(T) / E_ref)', v26_rows),
)
