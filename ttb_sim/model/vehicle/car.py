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
The car record: one car of [P] Table 1 (plus documented assumptions), and its layout.

:class:`CarParameters` is the scenario's ``car`` section: every field is declared
once with its unit, range and description.  Defaults are [P] Table 1; where [P]
is silent (damper counts, anti-yaw dampers, heights and spacings) the choices
are stated on the field and in ``docs/model.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.declarations import check_declared, param
from ttb_sim.errors import ModelError
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.vehicle.dofs import N_BODIES


@dataclass(frozen=True)
class CarParameters:
    """
    One car ([P] Table 1 plus documented assumptions); the scenario's ``car`` section.

    Units are SI: masses kg, inertias kg m^2, stiffness per spring N/m (8 axle
    boxes and 4 air springs per car), damping per damper N s/m (the ``*_dampers``
    counts say how many act per car, smeared evenly over the spring positions),
    lengths m.  Every field is declared with :func:`~ttb_sim.declarations.param`,
    so it is settable from a scenario file as ``car.<field>``.
    """

    car_body_mass: float = param(48000.0, 'kg', 'Car body mass M_c.', low=1.0, high=1e6)
    bogie_mass: float = param(3200.0, 'kg', 'Bogie frame mass M_t.', low=1.0, high=1e5)
    wheelset_mass: float = param(2400.0, 'kg', 'Wheelset mass M_w.', low=1.0, high=1e5)
    car_body_pitch_inertia: float = param(2.3e6, 'kg*m^2', 'Car body pitch inertia I_cy.',
                                          low=1.0, high=1e9)
    car_body_roll_inertia: float = param(1.15e5, 'kg*m^2', 'Car body roll inertia I_cx.',
                                         low=1.0, high=1e9)
    car_body_yaw_inertia: float = param(2.3e6, 'kg*m^2', 'Car body yaw inertia I_cz.',
                                        low=1.0, high=1e9)
    bogie_pitch_inertia: float = param(7200.0, 'kg*m^2', 'Bogie pitch inertia I_ty.', low=1.0,
                                       high=1e7)
    bogie_roll_inertia: float = param(3200.0, 'kg*m^2', 'Bogie roll inertia I_tx.', low=1.0,
                                      high=1e7)
    bogie_yaw_inertia: float = param(6800.0, 'kg*m^2', 'Bogie yaw inertia I_tz.', low=1.0,
                                     high=1e7)
    wheelset_roll_inertia: float = param(1200.0, 'kg*m^2', 'Wheelset roll inertia I_wx.',
                                         low=1.0, high=1e6)
    wheelset_spin_inertia: float = param(200.0, 'kg*m^2', 'Wheelset inertia about its axle '
                                         'I_wy (spin perturbation and gyroscopic terms).',
                                         low=1.0, high=1e6)
    wheelset_yaw_inertia: float = param(1200.0, 'kg*m^2', 'Wheelset yaw inertia I_wz.',
                                        low=1.0, high=1e6)
    primary_stiffness_x: float = param(9.0e6, 'N/m', 'Primary longitudinal stiffness per '
                                       'axle box.', low=1.0, high=1e13)
    primary_stiffness_y: float = param(3.0e6, 'N/m', 'Primary lateral stiffness per axle box.',
                                       low=1.0, high=1e13)
    primary_stiffness_z: float = param(1.04e6, 'N/m', 'Primary vertical stiffness per axle '
                                       'box.', low=1.0, high=1e13)
    secondary_stiffness_x: float = param(0.24e6, 'N/m', 'Secondary longitudinal stiffness per '
                                         'air spring.', low=1.0, high=1e13)
    secondary_stiffness_y: float = param(0.24e6, 'N/m', 'Secondary lateral stiffness per air '
                                         'spring.', low=1.0, high=1e13)
    secondary_stiffness_z: float = param(0.4e6, 'N/m', 'Secondary vertical stiffness per air '
                                         'spring.', low=1.0, high=1e13)
    primary_damping_z: float = param(45.0e3, 'N*s/m', 'Primary vertical damping per damper.',
                                     low=0.0, high=1e9)
    secondary_damping_y: float = param(3.0e3, 'N*s/m', 'Secondary lateral damping per damper.',
                                       low=0.0, high=1e9)
    secondary_damping_z: float = param(98.0e3, 'N*s/m', 'Secondary vertical damping per '
                                       'damper.', low=0.0, high=1e9)
    primary_vertical_dampers: int = param(4, '-', 'Primary vertical dampers per car (one per '
                                          'wheelset: Zhai-type bogies carry one damper per '
                                          'side of each bogie; docs/model.md).', low=0, high=64)
    secondary_vertical_dampers: int = param(2, '-', 'Secondary vertical dampers per car (one '
                                            'per bogie).', low=0, high=64)
    secondary_lateral_dampers: int = param(2, '-', 'Secondary lateral dampers per car (one '
                                           'per bogie).', low=0, high=64)
    yaw_damping: float = param(250.0e3, 'N*s/m', 'Anti-yaw (longitudinal) damper between '
                               'bogie and car body, per damper; assumed, not in [P] Table 1 '
                               '(see docs/model.md).', low=0.0, high=1e9)
    yaw_dampers: int = param(4, '-', 'Anti-yaw dampers per car (one on each side of each bogie; '
                             '0 = the literal Table 1 car).', low=0, high=64)
    yaw_damper_semi_spacing: float = param(1.35, 'm', 'Lateral semi-spacing of the anti-yaw '
                                           'dampers (assumed).', low=0.1, high=2.0)
    bogie_semi_spacing: float = param(7.85, 'm', 'Half the distance between bogie centres '
                                      '(l_c, [P] Table 1); also sets the axle layout of '
                                      'moving forces and quarter cars.', low=0.1, high=30.0)
    wheelbase_semi: float = param(1.25, 'm', 'Half the bogie wheelbase (l_t, [P] Table 1).',
                                  low=0.1, high=5.0)
    wheel_radius: float = param(0.46, 'm', 'Nominal rolling radius r0.', low=0.1, high=2.0)
    contact_semi_distance: float = param(0.7465, 'm', 'Half the lateral distance between '
                                         'the contact points b.', low=0.3, high=1.5)
    primary_semi_spacing: float = param(1.0, 'm', 'Lateral semi-spacing of the axle-box '
                                        'springs (assumed).', low=0.1, high=3.0)
    secondary_semi_spacing: float = param(1.0, 'm', 'Lateral semi-spacing of the air springs '
                                          '(assumed).', low=0.1, high=3.0)
    car_body_cg_height: float = param(1.70, 'm', 'Car body centre of gravity above the rail '
                                      'top (assumed).', low=0.1, high=5.0)
    secondary_height: float = param(0.90, 'm', 'Height of the air springs above the rail top '
                                    '(assumed).', low=0.1, high=5.0)
    bogie_cg_height: float = param(0.46, 'm', 'Bogie centre of gravity above the rail top '
                                   '(assumed).', low=0.1, high=5.0)
    longitudinal_pitch_coupling: bool = param(False, '-', 'False: longitudinal suspension '
                                              'forces have no pitch moment arm (Zhai-type '
                                              'model); true: they act at the physical '
                                              'heights.')

    def __post_init__(self) -> None:
        """Check every field against its declaration, then the geometric rules."""
        check_declared(self, 'car parameter')
        if self.wheelbase_semi >= self.bogie_semi_spacing:
            msg = (f'car parameter wheelbase_semi = {self.wheelbase_semi!r} is invalid; '
                   f'allowed: < bogie_semi_spacing ({self.bogie_semi_spacing})')
            raise ModelError(msg)
        if self.wheel_radius >= self.wheelbase_semi:
            msg = (f'car parameter wheel_radius = {self.wheel_radius!r} is invalid; '
                   f'allowed: < wheelbase_semi ({self.wheelbase_semi})')
            raise ModelError(msg)

    @property
    def static_wheel_load(self) -> float:
        """Static wheel load P0 = (Mc/8 + Mt/4 + Mw/2) g (N)."""
        return static_wheel_load(self)

    @property
    def total_mass(self) -> float:
        """Total mass of the car, Mc + 2 Mt + 4 Mw (kg)."""
        return self.car_body_mass + 2.0 * self.bogie_mass + 4.0 * self.wheelset_mass


def static_wheel_load(params: CarParameters | None = None) -> float:
    """
    Return the static wheel load P0 = (Mc/8 + Mt/4 + Mw/2) g.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    float
        P0 in N (78.48 kN for Table 1).

    """
    p = params or CarParameters()
    return (p.car_body_mass / 8.0 + p.bogie_mass / 4.0 + p.wheelset_mass / 2.0) * GRAVITY


def body_positions(params: CarParameters | None = None) -> np.ndarray:
    """
    Return the centre of gravity of each body in the car frame.

    Parameters
    ----------
    params : CarParameters, optional
        Car parameters; Table 1 defaults if omitted.

    Returns
    -------
    numpy.ndarray
        Shape (7, 3): x (m, forward from the car centre), y (0) and z (m, height
        above the rail top) of each body, in DOF order.

    """
    p = params or CarParameters()
    lc, lt = p.bogie_semi_spacing, p.wheelbase_semi
    x = np.array([0.0, lc, -lc, lc + lt, lc - lt, -lc + lt, -lc - lt])
    z = np.array([p.car_body_cg_height, p.bogie_cg_height, p.bogie_cg_height]
                 + [p.wheel_radius] * 4)
    return np.column_stack([x, np.zeros(N_BODIES), z])
