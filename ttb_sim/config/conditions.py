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
The checks of the ``damage`` and ``environment`` sections against the rest of a scenario.

:func:`check_conditions` refuses a damaged span that does not exist, a zone off its
span, bearing damage on rigid bearings, pile damage or scour on a pier that is not
piled, a scour deep enough to free the piles, a soil scale list of the wrong length:
a :class:`~ttb_sim.errors.ScenarioError` naming the key, the value and what is
allowed, before anything is built. The loader calls it on every scenario it reads,
the build step again on every scenario it builds (both cheap: no soil mesh). The
other functions give the records and factors the build step hands the model: the one
definition of each condition's effect on the scenario's parameters.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

from ttb_sim.errors import ModelError, ScenarioError
from ttb_sim.model.bearings import BearingParameters
from ttb_sim.model.bridge import BridgeParameters
from ttb_sim.model.damage import (bearing_stiffness_factors, damaged_substructure,
                                  girder_bending_factors)
from ttb_sim.model.environment import (bearing_stiffness_factor, girder_modulus_factor,
                                       scaled_soil)
from ttb_sim.model.foundation.records import Substructure

if TYPE_CHECKING:
    from ttb_sim.config.records import Scenario

__all__ = ['bearing_factors', 'check_conditions', 'conditioned_bearings', 'conditioned_bridge',
           'girder_bending', 'pier_substructure']


def check_conditions(s: Scenario) -> None:
    """
    Refuse damage or environment entries that do not fit the scenario.

    Raises
    ------
    ScenarioError
        Naming the key, the value and what is allowed.

    """
    damage, env = s.damage, s.environment
    if s.substructure_only:
        if damage.given or env.changes_soil:
            raise ScenarioError(f'load.type = {s.load.type!r} runs the pile-soil substructure '
                                'alone; damage entries and environment.soil_modulus_scale '
                                "apply to a bridge run (load.type = 'none', foundation.model "
                                "= 'piled')")
        return
    b = s.bridge
    try:
        girder_bending_factors(damage.girders, b.n_spans, b.elements_per_span, b.span_length)
        bearing_stiffness_factors(damage.bearings, b.n_spans + 1,
                                  s.bearings.model == 'elastic')
        _check_piers(s)
    except ModelError as exc:
        raise ScenarioError(str(exc)) from None


def _check_piers(s: Scenario) -> None:
    damage, env = s.damage, s.environment
    piled = s.foundation.piled_piers if s.foundation.model == 'piled' else ()
    named = (('damage.piles', [p.pier for p in damage.piles]),
             ('damage.scour', [c.pier for c in damage.scour]))
    for key, piers in named:
        for i, pier in enumerate(piers):
            if pier not in piled:
                raise ScenarioError(
                    f'{key}[{i}].pier = {pier} is not a piled pier; allowed: '
                    f'{list(piled) if piled else "none"} (foundation.piled_piers with '
                    "foundation.model = 'piled')")
    if env.changes_soil and not piled:
        raise ScenarioError(f'environment.soil_modulus_scale = {list(env.soil_modulus_scale)!r}'
                            " scales the soil of piled piers: needs foundation.model = 'piled'"
                            ' (foundation springs are set by the foundation keys)')
    if not piled:
        return
    for pier in piled:
        pier_substructure(s, pier)


def pier_substructure(s: Scenario, pier: int) -> Substructure:
    """
    Return the pile-soil substructure of piled pier ``pier`` (its support number).

    The soil, piles, cap and interface keys, with the soil scaled by
    ``environment.soil_modulus_scale`` and then the pier's pile damage and scour.
    """
    spec = s.substructure()
    spec = replace(spec, soil=scaled_soil(spec.soil, s.environment))
    return damaged_substructure(spec, pier, s.damage)


def conditioned_bridge(s: Scenario) -> BridgeParameters:
    """Return the girders at ``environment.temperature`` (EA, GJ and both EI times E(T)/E_ref)."""
    b, factor = s.bridge, girder_modulus_factor(s.environment)
    if factor == 1.0:
        return b
    return replace(b, bending_stiffness=b.bending_stiffness * factor,
                   lateral_bending_stiffness=b.lateral_bending_stiffness * factor,
                   torsional_stiffness=b.torsional_stiffness * factor,
                   axial_stiffness=b.axial_stiffness * factor)


def conditioned_bearings(s: Scenario) -> BearingParameters:
    """Return the bearings at ``environment.temperature`` (their three stiffnesses)."""
    br, factor = s.bearings, bearing_stiffness_factor(s.environment)
    if factor == 1.0:
        return br
    return replace(br, vertical_stiffness=br.vertical_stiffness * factor,
                   lateral_stiffness=br.lateral_stiffness * factor,
                   longitudinal_stiffness=br.longitudinal_stiffness * factor)


def girder_bending(s: Scenario) -> np.ndarray | None:
    """Return the factor on each girder element's vertical EI, or None without girder damage."""
    if not s.damage.girders:
        return None
    b = s.bridge
    return girder_bending_factors(s.damage.girders, b.n_spans, b.elements_per_span,
                                  b.span_length)


def bearing_factors(s: Scenario) -> np.ndarray | None:
    """Return the (n_supports, 2) factor on the bearings' stiffness, or None without damage."""
    if not s.damage.bearings:
        return None
    return bearing_stiffness_factors(s.damage.bearings, s.bridge.n_spans + 1,
                                     s.bearings.model == 'elastic')
