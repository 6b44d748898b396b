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
Environment: the scenario section ``environment`` and the stiffness changes it implies.

- Girder modulus: E(T) = E_ref (1 + alpha_E (T - T_ref)), on every stiffness of the
  girders (EA, GJ, both EI); the default alpha_E = -0.003 / degC follows the frequency
  slope of a monitored RC slab, -0.13 to -0.23 % / degC (Xia et al. 2006), doubled
  because f ~ sqrt(E).
- Bearing stiffness: k(T) = k_ref (1 + alpha_b (T - T_ref)) below T_ref, k_ref above
  (elastomers stiffen in the cold and hardly soften in the warm); the default
  alpha_b = -2 / 45 / degC is the largest low-temperature stiffening TRL RR299 recommends
  accepting for a bearing elastomer, a factor of 3 after 24 h at -25 degC, from 20 degC.
- Soil: a factor per soil layer on its Young's modulus (frozen or wet ground).

Sources and limits are in docs/damage.md.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.model.foundation.records import SoilParameters

__all__ = ['bearing_stiffness_factor', 'EnvironmentParameters', 'EnvironmentValueError',
           'girder_modulus_factor', 'scaled_soil']


class EnvironmentValueError(ModelError):
    """The environment section gives a state the stiffness laws cannot describe."""


@dataclass(frozen=True)
class EnvironmentParameters:
    """Temperature and ground state (``environment``)."""

    temperature: float = param(20.0, 'degC', 'Temperature of the bridge (girders and '
                               'bearings; uniform, no gradient).', low=-60.0, high=60.0,
                               dynamic=True)
    reference_temperature: float = param(20.0, 'degC', 'Temperature at which the girder and '
                                         'bearing keys hold.', low=-60.0, high=60.0)
    girder_modulus_coefficient: float = param(
        -0.003, '1/degC', "alpha_E of the girders' E(T) = E_ref (1 + alpha_E (T - T_ref)), on "
        'EA, GJ and both EI (default: the frequency slope -0.13 to -0.23 %/degC of Xia et al. '
        '2006 times two; docs/damage.md).', low=-0.1, high=0.1)
    bearing_stiffness_coefficient: float = param(
        -2.0 / 45.0, '1/degC', "alpha_b of the bearings' k(T) = k_ref (1 + alpha_b (T - "
        'T_ref)) below T_ref (no change above; default: the factor 3 at -25 degC that TRL '
        'RR299 accepts at most; docs/damage.md).', low=-1.0, high=0.0)
    soil_modulus_scale: tuple[float, ...] = param(
        (), '-', "Factor on the Young's modulus of each soil layer, top down (one per entry "
        'of soil.layers; frozen ground > 1, saturated < 1); empty = 1 everywhere.',
        low=0.0, high=1000.0, low_inclusive=False)

    def __post_init__(self) -> None:
        """Check every field against its declaration, and that the stiffnesses stay positive."""
        check_declared(self, 'environment.', EnvironmentValueError)
        for key, factor in (('girder_modulus_coefficient', girder_modulus_factor(self)),
                            ('bearing_stiffness_coefficient', bearing_stiffness_factor(self))):
            if not factor > 0.0:
                raise EnvironmentValueError(
                    f'environment.{key} = {getattr(self, key):g} 1/degC at '
                    f'environment.temperature = {self.temperature:g} degC (reference_temperature'
                    f' = {self.reference_temperature:g} degC) gives a stiffness factor of '
                    f'{factor:g}; allowed: factors > 0 (a smaller coefficient or a '
                    'temperature nearer the reference)')

    @property
    def changes_soil(self) -> bool:
        """True when some soil layer modulus is scaled."""
        return bool(self.soil_modulus_scale)


def girder_modulus_factor(env: EnvironmentParameters) -> float:
    """Return E(T) / E_ref = 1 + alpha_E (T - T_ref) of the girders."""
    return 1.0 + env.girder_modulus_coefficient * (env.temperature - env.reference_temperature)


def bearing_stiffness_factor(env: EnvironmentParameters) -> float:
    """Return k(T) / k_ref = 1 + alpha_b min(T - T_ref, 0) of the bearings."""
    return 1.0 + env.bearing_stiffness_coefficient * min(
        env.temperature - env.reference_temperature, 0.0)


def scaled_soil(soil: SoilParameters, env: EnvironmentParameters) -> SoilParameters:
    """
    Return the soil with each layer's modulus times ``environment.soil_modulus_scale``.

    Raises
    ------
    EnvironmentValueError
        When the list does not have one factor per layer.

    """
    scale = env.soil_modulus_scale
    if not scale:
        return soil
    if len(scale) != len(soil.layers):
        message = (f'environment.soil_modulus_scale = {list(scale)!r} has {len(scale)} factors '
                   f'for {len(soil.layers)} soil.layers; allowed: one factor per layer, top down')
        raise EnvironmentValueError(message)
    layers = tuple(replace(layer, E=layer.E * s) for layer, s in zip(soil.layers, scale))
    return replace(soil, layers=layers)
