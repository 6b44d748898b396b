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
Damage: the scenario section ``damage`` and the stiffness it takes from the model.

Four physical models (docs/damage.md gives their sources and limits):

- ``damage.girders``: a cracked zone of a girder, the vertical bending stiffness EI
  times (1 - loss) over a length at a position of a span. A girder element the zone
  covers in part gets the flexibility average of its cracked and sound parts
  (:func:`girder_bending_factors`), exact for a uniform bending moment over the element.
- ``damage.bearings``: a bearing's three spring stiffnesses times (1 - loss)
  (:func:`bearing_stiffness_factors`).
- ``damage.piles``: the Young's modulus of the piles of a piled pier times (1 - loss)
  (:func:`damaged_substructure`).
- ``damage.scour``: the soil above a depth around a piled pier removed: its layers
  split at the depth and the soil above it given :data:`SCOUR_RESIDUAL` of its modulus,
  density and cohesion (same wave speeds, so the mesh carries what it did; no stiffness
  and no overburden left), so that the piles stand free above the scour line.

The records check their own values (:class:`DamageError`); checks against the rest of
the scenario (a span that exists, a pier that is piled) are in
:mod:`ttb_sim.config.conditions`.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.model.foundation.records import SoilLayer, SoilParameters, Substructure

__all__ = ['bearing_stiffness_factors', 'BearingDamage', 'damaged_substructure',
           'DamageError', 'DamageParameters', 'girder_bending_factors', 'GirderDamage',
           'PileDamage', 'Scour', 'SCOUR_RESIDUAL', 'scoured_layers']

SCOUR_RESIDUAL = 1e-6
"""Fraction of modulus, density and cohesion left in scoured soil (removed, numerically)."""


class DamageError(ModelError):
    """A damage entry is described by invalid values."""


@dataclass(frozen=True)
class GirderDamage:
    """A zone of lost vertical bending stiffness on one span (an entry of ``damage.girders``)."""

    span: int = param(1, '-', 'Span, 1-based (1 = the first span).', low=1, high=50)
    start: float = param(15.0, 'm', "Start of the damaged zone, from the span's left "
                         'support.', low=0.0, high=500.0)
    length: float = param(2.0, 'm', 'Length of the damaged zone along the span.', low=0.0,
                          high=500.0, low_inclusive=False)
    loss: float = param(0.0, '-', 'Fraction of the vertical bending stiffness EI lost in the '
                        'zone (lateral bending, torsion and axial stiffness are kept).',
                        low=0.0, high=1.0, high_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'damage.girders.', DamageError)

    @property
    def end(self) -> float:
        """Return the distance (m) from the span's left support to the zone's far end."""
        return self.start + self.length


@dataclass(frozen=True)
class BearingDamage:
    """Lost stiffness of the bearings of a support (an entry of ``damage.bearings``)."""

    support: int = param(1, '-', 'Support, 1-based (1 = the first abutment, n_spans + 1 the '
                         'last); both girder ends on it are affected.', low=1, high=51)
    side: str = param('both', '-', "Bearing line: 'left' (+y), 'right' (-y) or 'both'.",
                      choices=('left', 'right', 'both'))
    stiffness_loss: float = param(0.0, '-', 'Fraction of the vertical, lateral and '
                                  'longitudinal stiffness of the bearings lost (their '
                                  'damping is kept).', low=0.0, high=1.0,
                                  high_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'damage.bearings.', DamageError)


@dataclass(frozen=True)
class PileDamage:
    """Lost stiffness of the piles of a piled pier (an entry of ``damage.piles``)."""

    pier: int = param(2, '-', 'Piled pier, by its support number (as in '
                      'foundation.piled_piers).', low=2, high=50)
    stiffness_loss: float = param(0.0, '-', "Fraction of the Young's modulus of all the "
                                  "piles of the pier's group lost.", low=0.0, high=1.0,
                                  high_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'damage.piles.', DamageError)


@dataclass(frozen=True)
class Scour:
    """Soil removed around a piled pier down to a depth (an entry of ``damage.scour``)."""

    pier: int = param(2, '-', 'Piled pier, by its support number (as in '
                      'foundation.piled_piers).', low=2, high=50)
    depth: float = param(1.0, 'm', 'Scour depth below the ground surface: the soil of the '
                         "pier's block above it is removed (less than the pile length).",
                         low=0.0, high=1000.0, low_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'damage.scour.', DamageError)


@dataclass(frozen=True)
class DamageParameters:
    """Damage of girders, bearings, piles and the ground around piled piers (``damage``)."""

    girders: tuple[GirderDamage, ...] = param(
        (), '-', 'Cracked girder zones, each {span, start, length, loss}: vertical bending EI '
        "times (1 - loss) from start (m from the span's left support) over length "
        '(docs/damage.md).')
    bearings: tuple[BearingDamage, ...] = param(
        (), '-', 'Degraded bearings, each {support, side, stiffness_loss} '
        "(needs bearings.model = 'elastic').")
    piles: tuple[PileDamage, ...] = param(
        (), '-', 'Degraded piles, each {pier, stiffness_loss}: the pile modulus of a piled '
        'pier times (1 - stiffness_loss).')
    scour: tuple[Scour, ...] = param(
        (), '-', 'Scour, each {pier, depth}: the soil of a piled pier above depth removed '
        '(docs/damage.md).')

    @property
    def given(self) -> bool:
        """Tell whether some damage entry is given, even one with a zero loss."""
        return bool(self.girders or self.bearings or self.piles or self.scour)


def girder_bending_factors(zones: Sequence[GirderDamage], n_spans: int,
                           elements_per_span: int, span_length: float) -> np.ndarray:
    """
    Return the factor on the vertical EI of every girder element (n_spans * ne,).

    An element a zone covers over a fraction f of its length gets the flexibility
    average of its parts, 1 / EI_e = ((1 - f) + f / (1 - loss)) / EI: its bending
    strain energy under a uniform moment is then that of the element with the zone.
    Under a varying moment it is an approximation (the zone's place inside the element
    is lost); a zone that covers whole elements is exact.

    Raises
    ------
    DamageError
        For a span beyond ``n_spans``, a zone off its span, or zones that overlap.

    """
    ne = elements_per_span
    h = span_length / ne
    edges = np.arange(ne + 1) * h
    flexibility = np.ones((n_spans, ne))
    for i, zone in enumerate(zones):
        _check_zone(i, zone, n_spans, span_length)
        covered = np.clip(np.minimum(zone.end, edges[1:]) - np.maximum(zone.start, edges[:-1]),
                          0.0, None) / h
        flexibility[zone.span - 1] += covered * (zone.loss / (1.0 - zone.loss))
    _check_overlaps(zones)
    return (1.0 / flexibility).ravel()


def _check_zone(i: int, zone: GirderDamage, n_spans: int, span_length: float) -> None:
    where = f'damage.girders[{i}]'
    if zone.span > n_spans:
        raise DamageError(f'{where}.span = {zone.span} is not a span; allowed: 1 to '
                          f'{n_spans} (bridge.n_spans)')
    if zone.start < 0.0 or zone.end > span_length:
        raise DamageError(f'{where}: the zone start = {zone.start:g} m + length = '
                          f'{zone.length:g} m runs from {zone.start:g} to {zone.end:g} m, '
                          f'off the span; allowed: inside 0 to {span_length:g} m '
                          '(bridge.span_length)')


def _check_overlaps(zones: Sequence[GirderDamage]) -> None:
    for i, a in enumerate(zones):
        for j, b in enumerate(zones[:i]):
            if a.span == b.span and a.start < b.end and b.start < a.end:
                raise DamageError(f'damage.girders[{i}] ({a.start:g} to {a.end:g} m) overlaps '
                                  f'damage.girders[{j}] ({b.start:g} to {b.end:g} m) on span '
                                  f'{a.span}; give one zone with the combined loss')


def bearing_stiffness_factors(entries: Sequence[BearingDamage], n_supports: int,
                              elastic: bool) -> np.ndarray:
    """
    Return the factor on the stiffness of the bearings per support and side (n_supports, 2).

    Side 0 is the left (+y) bearing line, side 1 the right (-y) one.

    Raises
    ------
    DamageError
        For a support that does not exist, rigid bearings, or a bearing named twice.

    """
    factors = np.ones((n_supports, 2))
    named = np.zeros((n_supports, 2), dtype=bool)
    for i, entry in enumerate(entries):
        where = f'damage.bearings[{i}]'
        if not elastic:
            raise DamageError(f"{where}: bearing damage needs bearings.model = 'elastic' (rigid "
                              'bearings are ideal pins without a stiffness)')
        if entry.support > n_supports:
            raise DamageError(f'{where}.support = {entry.support} is not a support; allowed: 1 '
                              f'to {n_supports} (bridge.n_spans + 1)')
        sides = {'left': [0], 'right': [1], 'both': [0, 1]}[entry.side]
        row = entry.support - 1
        if named[row, sides].any():
            raise DamageError(f'{where} names a bearing of support {entry.support} that an '
                              'earlier entry names; give each bearing once')
        named[row, sides] = True
        factors[row, sides] = 1.0 - entry.stiffness_loss
    return factors


def scoured_layers(layers: Sequence[SoilLayer], depth: float) -> tuple[SoilLayer, ...]:
    """
    Return the layers with the soil above ``depth`` removed (kept at :data:`SCOUR_RESIDUAL`).

    The layer the scour line cuts is split there; the layers above it keep their
    Poisson's ratio, friction angle and damping ratio, so the wave speeds are the
    same and the mesh resolves what it did.
    """
    out: list[SoilLayer] = []
    top = 0.0
    for layer in layers:
        bottom = top + layer.thickness
        if bottom <= depth:
            out.append(_removed(layer, layer.thickness))
        elif top < depth:
            out.append(_removed(layer, depth - top))
            out.append(replace(layer, thickness=bottom - depth))
        else:
            out.append(layer)
        top = bottom
    return tuple(out)


def _removed(layer: SoilLayer, thickness: float) -> SoilLayer:
    eps = SCOUR_RESIDUAL
    return replace(layer, thickness=thickness, E=layer.E * eps, rho=layer.rho * eps,
                   c=layer.c * eps)


def damaged_substructure(spec: Substructure, pier: int, damage: DamageParameters
                         ) -> Substructure:
    """
    Return the substructure of the piled pier ``pier`` (support number) with its damage.

    Raises
    ------
    DamageError
        For a scour depth at or below the pile tips or the block's base, or a pier
        named twice in one list.

    """
    piles = [p for p in damage.piles if p.pier == pier]
    scour = [s for s in damage.scour if s.pier == pier]
    for key, found in (('damage.piles', piles), ('damage.scour', scour)):
        if len(found) > 1:
            raise DamageError(f'{key} names pier {pier} {len(found)} times; give it once')
    out = spec
    if piles and out.piles is not None:
        group = out.piles
        out = replace(out, piles=replace(group, E=group.E * (1.0 - piles[0].stiffness_loss)))
    if scour:
        depth = scour[0].depth
        i = damage.scour.index(scour[0])
        soil: SoilParameters = out.soil
        if depth >= soil.depth:
            raise DamageError(f'damage.scour[{i}].depth = {depth:g} m is not above the base of '
                              f'the soil block ({soil.depth:g} m, the sum of soil.layers '
                              'thicknesses)')
        if out.piles is not None and depth >= out.piles.length:
            raise DamageError(f'damage.scour[{i}].depth = {depth:g} m reaches the pile tips '
                              f'(piles.length = {out.piles.length:g} m): the group would '
                              'stand on nothing; allowed: less than piles.length')
        out = replace(out, soil=replace(soil, layers=scoured_layers(soil.layers, depth)))
    return out
