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
Wheel-rail contact: the public face of the modules of this package.

- :mod:`.hertz`: Hertz normal contact (Zhai's law, the contact ellipse) and
  the elastic constants of wheel and rail steel.
- :mod:`.creep`: Kalker's linear creep coefficients and forces, their load
  scaling, Shen-Hedrick-Elkins saturation and its derivatives.
- :mod:`.geometry`: wheelset contact geometry (equivalent cone) and creepages.
- :mod:`.profiles`: parametric wheel and rail profiles.
- :mod:`.contact_table`: the contact-geometry table of a wheelset on them.
- :mod:`.contact_parameters`: the contact record of the scenario.
"""

from ttb_sim.model.wheel_rail.contact_table import contact_geometry_table, ContactGeometryTable
from ttb_sim.model.wheel_rail.creep import (creep_coefficients, CREEP_LOAD_EXPONENTS,
                                            FRICTION_COEFFICIENT, kalker_coefficients,
                                            KALKER_RATIO_RANGE, linear_creep_forces,
                                            scale_creep_coefficients, scaled_creep_coefficients,
                                            she_factor_derivative,
                                            she_factor_gradient, she_ratio, she_saturation)
from ttb_sim.model.wheel_rail.geometry import creepages, simplified_geometry, WheelsetGeometry
from ttb_sim.model.wheel_rail.hertz import (hertz_constant, hertz_ellipse, HertzEllipse,
                                            linearised_stiffness, normal_force,
                                            normal_force_derivative, POISSON_RATIO,
                                            static_compression, TREADS, YOUNG_MODULUS)
from ttb_sim.model.wheel_rail.profiles import (Profile, rail_profile, RailParameters,
                                               wheel_profile, WheelParameters)

__all__ = [
    'CREEP_LOAD_EXPONENTS',
    'ContactGeometryTable',
    'FRICTION_COEFFICIENT',
    'HertzEllipse',
    'KALKER_RATIO_RANGE',
    'POISSON_RATIO',
    'Profile',
    'RailParameters',
    'TREADS',
    'WheelParameters',
    'WheelsetGeometry',
    'YOUNG_MODULUS',
    'contact_geometry_table',
    'creep_coefficients',
    'creepages',
    'hertz_constant',
    'hertz_ellipse',
    'kalker_coefficients',
    'linear_creep_forces',
    'linearised_stiffness',
    'normal_force',
    'normal_force_derivative',
    'rail_profile',
    'scale_creep_coefficients',
    'scaled_creep_coefficients',
    'she_factor_derivative',
    'she_factor_gradient',
    'she_ratio',
    'she_saturation',
    'simplified_geometry',
    'static_compression',
    'wheel_profile',
]
