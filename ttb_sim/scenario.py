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
Typed, validated scenario configuration.

A scenario is a tree of frozen dataclasses. Every leaf is declared once with
:func:`param`, which records its default, unit, allowed range or choices and a
description; the YAML loader, the ``--set`` overrides, ``ttb-sim scenarios`` and
the ROS parameter descriptors all read that one declaration.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import math
from pathlib import Path
import re
import sys
import sysconfig
from typing import Any, Iterator, Mapping, Sequence

from ttb_sim.errors import ScenarioError
import yaml

G = 9.81
"""Gravitational acceleration (m/s²)."""


@dataclass(frozen=True)
class Spec:
    """The declaration of one scenario key."""

    unit: str
    description: str
    low: float | None = None
    high: float | None = None
    low_inclusive: bool = True
    high_inclusive: bool = True
    choices: tuple[str, ...] | None = None
    dynamic: bool = False

    def allowed(self) -> str:
        """Describe the allowed values in words, for error messages and help."""
        if self.choices is not None:
            return 'one of ' + ', '.join(repr(c) for c in self.choices)
        if self.low is None and self.high is None:
            return 'any value'
        lo = '(-inf' if self.low is None else ('[' if self.low_inclusive else '(') + _num(self.low)
        hi = 'inf)' if self.high is None else (
            _num(self.high) + (']' if self.high_inclusive else ')'))
        unit = f' {self.unit}' if self.unit not in ('', '-') else ''
        return f'{lo}, {hi}{unit}'

    def contains(self, value: float) -> bool:
        """Tell whether a number lies inside the declared range."""
        if self.low is not None:
            if value < self.low or (value == self.low and not self.low_inclusive):
                return False
        if self.high is not None:
            if value > self.high or (value == self.high and not self.high_inclusive):
                return False
        return True


def _num(value: float) -> str:
    if float(value).is_integer() and abs(value) < 1e10:
        return str(int(value))
    return f'{value:g}'


def param(default: Any, unit: str, description: str, *, low: float | None = None,
          high: float | None = None, low_inclusive: bool = True, high_inclusive: bool = True,
          choices: Sequence[str] | None = None, dynamic: bool = False) -> Any:
    """
    Declare a scenario key with its default, unit, range and description.

    Parameters
    ----------
    default
        Value used when the scenario file does not set the key.
    unit
        SI unit of the value ('-' when dimensionless).
    description
        One sentence for users, shown by ``ttb-sim scenarios --keys`` and ROS.
    low, high, low_inclusive, high_inclusive
        Allowed numeric range (each bound optional).
    choices
        Allowed strings, for enumerations.
    dynamic
        True when the running ROS node may change the key.

    Returns
    -------
    dataclasses.Field
        The field, carrying its :class:`Spec` in ``metadata['spec']``.

    """
    spec = Spec(unit=unit, description=description, low=low, high=high,
                low_inclusive=low_inclusive, high_inclusive=high_inclusive,
                choices=tuple(choices) if choices is not None else None, dynamic=dynamic)
    return field(default=default, metadata={'spec': spec})


@dataclass(frozen=True)
class TrainConfig:
    """Train: vehicle model, axle layout and running speed."""

    vehicle: str = param('moving_force', '-', 'Vehicle model: constant moving forces, '
                         'quarter cars (a sprung mass on a spring-dashpot over each axle), or '
                         "42-DOF multibody cars ([P] Table 1, section 'car') on wheel-rail "
                         "contact (needs track.model = 'slab').",
                         choices=('moving_force', 'sprung_mass', 'car'))
    speed_kmh: float = param(300.0, 'km/h', 'Running speed of the train (the upper bound '
                             'is a numerical guard: validation runs use high speed '
                             'parameters).', low=0.0, high=10000.0, low_inclusive=False,
                             dynamic=True)
    start_position: float = param(0.0, 'm', 'Position of the train head along the track at '
                                  't = 0 (0 is the start of the first span).',
                                  low=-5000.0, high=5000.0)
    axle_offsets: tuple[float, ...] = param((), 'm', 'Distances of the axles behind the train '
                                            'head; empty = derived from the car geometry.',
                                            low=0.0, high=5000.0)
    n_cars: int = param(8, '-', 'Number of cars (when axle_offsets is empty).', low=1, high=32)
    car_length: float = param(25.0, 'm', 'Length of one car over couplers.', low=1.0,
                              high=60.0)
    bogie_semi_spacing: float = param(7.85, 'm', 'Half the distance between bogie centres '
                                      '(l_c, [P] Table 1).', low=0.1, high=30.0)
    wheelbase_semi: float = param(1.25, 'm', 'Half the bogie wheelbase (l_t, [P] Table 1).',
                                  low=0.1, high=5.0)
    axle_load: float = param(156960.0, 'N', 'Magnitude of each moving force (moving_force '
                             'vehicle); default = (Mc/4 + Mt/2 + Mw) g of [P] Table 1.',
                             low=0.0, high=1e7)
    sprung_mass: float = param(5750.0, 'kg', 'Sprung mass of each quarter car.', low=0.0,
                               high=1e6, low_inclusive=False)
    unsprung_mass: float = param(0.0, 'kg', 'Unsprung (wheel) mass of each quarter car, '
                                 'which follows the girder; 0 = massless wheel.', low=0.0,
                                 high=1e5)
    suspension_stiffness: float = param(1.595e6, 'N/m', 'Suspension stiffness of each '
                                        'quarter car.', low=0.0, high=1e12,
                                        low_inclusive=False)
    suspension_damping: float = param(0.0, 'N*s/m', 'Suspension damping of each quarter car.',
                                      low=0.0, high=1e9)

    @property
    def speed(self) -> float:
        """Return the running speed in m/s."""
        return self.speed_kmh / 3.6

    def axle_positions(self) -> tuple[float, ...]:
        """Distances of all axles behind the head (m), from the layout keys."""
        if self.axle_offsets:
            return tuple(float(a) for a in self.axle_offsets)
        lc, lt, length = self.bogie_semi_spacing, self.wheelbase_semi, self.car_length
        first = length / 2.0 - lc - lt
        local = (first, first + 2 * lt, first + 2 * lc, first + 2 * lc + 2 * lt)
        return tuple(k * length + a for k in range(self.n_cars) for a in local)


@dataclass(frozen=True)
class CarConfig:
    """
    Multibody car ([P] Table 1) used by ``train.vehicle = car``.

    Stiffness values are per spring (8 axle boxes and 4 air springs per car),
    damping values per damper; the damper counts say how many act per car.
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
                                       'axle box.', low=1.0, high=1e10)
    primary_stiffness_y: float = param(3.0e6, 'N/m', 'Primary lateral stiffness per axle box.',
                                       low=1.0, high=1e10)
    primary_stiffness_z: float = param(1.04e6, 'N/m', 'Primary vertical stiffness per axle '
                                       'box.', low=1.0, high=1e10)
    secondary_stiffness_x: float = param(0.24e6, 'N/m', 'Secondary longitudinal stiffness per '
                                         'air spring.', low=1.0, high=1e10)
    secondary_stiffness_y: float = param(0.24e6, 'N/m', 'Secondary lateral stiffness per air '
                                         'spring.', low=1.0, high=1e10)
    secondary_stiffness_z: float = param(0.4e6, 'N/m', 'Secondary vertical stiffness per air '
                                         'spring.', low=1.0, high=1e10)
    primary_damping_z: float = param(45.0e3, 'N*s/m', 'Primary vertical damping per damper.',
                                     low=0.0, high=1e9)
    secondary_damping_y: float = param(3.0e3, 'N*s/m', 'Secondary lateral damping per damper.',
                                       low=0.0, high=1e9)
    secondary_damping_z: float = param(98.0e3, 'N*s/m', 'Secondary vertical damping per '
                                       'damper.', low=0.0, high=1e9)
    primary_vertical_dampers: int = param(4, '-', 'Primary vertical dampers per car (one per '
                                          'wheelset: Zhai-type bogies carry one damper per '
                                          'side of each bogie; see README).', low=0, high=64)
    secondary_vertical_dampers: int = param(2, '-', 'Secondary vertical dampers per car (one '
                                            'per bogie).', low=0, high=64)
    secondary_lateral_dampers: int = param(2, '-', 'Secondary lateral dampers per car (one '
                                           'per bogie).', low=0, high=64)
    yaw_damping: float = param(250.0e3, 'N*s/m', 'Anti-yaw (longitudinal) damper between '
                               'bogie and car body, per damper; assumed, not in [P] Table 1 '
                               '(see README).', low=0.0, high=1e9)
    yaw_dampers: int = param(4, '-', 'Anti-yaw dampers per car (one on each side of each bogie; '
                             '0 = the literal Table 1 car).', low=0, high=64)
    yaw_damper_semi_spacing: float = param(1.35, 'm', 'Lateral semi-spacing of the anti-yaw '
                                           'dampers (assumed).', low=0.1, high=2.0)
    wheel_radius: float = param(0.46, 'm', 'Nominal rolling radius r0.', low=0.1, high=2.0)
    contact_semi_distance: float = param(0.7465, 'm', 'Half the lateral distance between '
                                         'the contact points b.', low=0.3, high=1.5)


@dataclass(frozen=True)
class BridgeConfig:
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


@dataclass(frozen=True)
class TrackConfig:
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


@dataclass(frozen=True)
class BearingsConfig:
    """Bearings between girder ends and supports ([P] Eq. 1 as point springs)."""

    model: str = param('rigid', '-', "'rigid': ideal pinned supports; 'elastic': "
                       'spring-dashpot bearings on the supports.', choices=('rigid', 'elastic'))
    spacing: float = param(4.4, 'm', 'Lateral distance between the left and right bearings '
                           '(assumed).', low=0.0, high=50.0, low_inclusive=False)
    vertical_stiffness: float = param(5e9, 'N/m', 'Vertical stiffness per bearing (assumed; '
                                      'typical 1e9-1e10).', low=0.0, high=1e14,
                                      low_inclusive=False)
    lateral_stiffness: float = param(5e8, 'N/m', 'Lateral stiffness per bearing (assumed).',
                                     low=0.0, high=1e14, low_inclusive=False)
    longitudinal_stiffness: float = param(5e7, 'N/m', 'Longitudinal stiffness per bearing '
                                          '(assumed).', low=0.0, high=1e14,
                                          low_inclusive=False)
    vertical_damping: float = param(0.0, 'N*s/m', 'Vertical damping per bearing.', low=0.0,
                                    high=1e12)
    lateral_damping: float = param(0.0, 'N*s/m', 'Lateral and longitudinal damping per '
                                   'bearing.', low=0.0, high=1e12)


@dataclass(frozen=True)
class PiersConfig:
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


@dataclass(frozen=True)
class FoundationConfig:
    """Foundations of the intermediate piers; abutments are always rigid."""

    model: str = param('rigid', '-', "'rigid': bearings sit on fixed supports; 'springs': "
                       'piers on foundation springs ([P] Table 4).',
                       choices=('rigid', 'springs'))
    vertical_stiffness: float = param(6e9, 'N/m', 'Vertical foundation spring ([P] Table 4).',
                                      low=0.0, high=1e15, low_inclusive=False)
    lateral_stiffness: float = param(6e8, 'N/m', 'Lateral and longitudinal foundation spring '
                                     '([P] Table 4).', low=0.0, high=1e15, low_inclusive=False)
    rotational_stiffness: float = param(1e11, 'N*m/rad', 'Rocking and twisting foundation '
                                        'spring (assumed; not in [P]).', low=0.0, high=1e18,
                                        low_inclusive=False)
    damping: float = param(0.0, 'N*s/m', 'Translational foundation damping ([P] Table 4: 0).',
                           low=0.0, high=1e12)


@dataclass(frozen=True)
class IrregularityConfig:
    """Track irregularity (applied under quarter cars; moving forces ignore it)."""

    spectrum: str = param('none', '-', "Irregularity spectrum ('paper' = Chinese HSR vertical "
                          "and alignment 1-50 m plus Sato 0.05-1 m; 'chinese_sato' the same with "
                          "1-200 m); 'none' is a smooth track.",
                          choices=('none', 'paper', 'chinese_sato', 'chinese_hsr', 'sato',
                                   'german_low',
                                   'german_high', 'fra1', 'fra2', 'fra3', 'fra4', 'fra5',
                                   'fra6'), dynamic=True)
    seed: int = param(1, '-', 'Seed of the random phases (same seed, same track).', low=0,
                      high=2**31 - 1, dynamic=True)
    scale: float = param(1.0, '-', 'Factor on the irregularity amplitude; 0 gives a smooth '
                         'track.', low=0.0, high=100.0, dynamic=True)
    file: str = param('', '-', 'CSV of a measured profile (x, z_left, z_right, y_left, '
                      'y_right in metres; smooth outside its range); empty = synthesise '
                      'from the spectrum.', dynamic=True)
    grid_spacing: float = param(0.01, 'm', 'Grid spacing of the synthesised profile (must be '
                                'under half the shortest wavelength).', low=0.001, high=1.0)


@dataclass(frozen=True)
class ContactConfig:
    """Wheel-rail contact of multibody cars (PHYSICS.md section 2)."""

    tread: str = param('lm', '-', "Zhai's Hertz constant: worn 'lm' or 'conical' tread.",
                       choices=('lm', 'conical'))
    friction: float = param(0.3, '-', 'Friction coefficient of the Shen-Hedrick-Elkins '
                            'saturation.', low=0.0, high=1.0, low_inclusive=False)
    geometry: str = param('profiles', '-', "'profiles': LMA wheel on CHN60 rail contact "
                          "table; 'conicity': equivalent cone.",
                          choices=('profiles', 'conicity'))
    conicity: float = param(0.05, '-', "Equivalent conicity for geometry = 'conicity'.",
                            low=0.0, high=1.0)
    tolerance: float = param(1e-9, 'm', 'Convergence tolerance of the contact iteration on '
                             'the compression of every wheel.', low=1e-15, high=1e-3,
                             low_inclusive=False)
    max_iterations: int = param(30, '-', 'Contact iterations per step before the run stops '
                                'as diverged.', low=1, high=1000)


@dataclass(frozen=True)
class SolverConfig:
    """Time integration (Newmark average acceleration)."""

    dt: float = param(0.0, 's', 'Time step; 0 picks it automatically (see README).', low=0.0,
                      high=0.1)
    duration: float = param(0.0, 's', 'Simulated time; 0 runs until the last axle has left '
                            'the bridge plus free_vibration_periods fundamental periods.',
                            low=0.0, high=1e5)
    free_vibration_periods: float = param(1.0, '-', 'Fundamental periods of free vibration '
                                          'appended to an automatic duration.', low=0.0,
                                          high=1000.0)
    divergence_limit: float = param(10.0, 'm', 'Any displacement larger than this (or not '
                                    'finite) stops the run as diverged.', low=0.0, high=1e6,
                                    low_inclusive=False)
    variant: str = param('qdldl', '-', "Solver variant: 'reference' is the validated path "
                         '(general SuperLU LU, step as written); the others factorise the '
                         'symmetric effective matrices with a fill-reducing order and take the '
                         "lean step: 'qdldl' (LDL^T, the fastest measured), 'cholmod' "
                         "(CHOLMOD Cholesky via cholespy), 'superlu_sym' (pure scipy). They "
                         "agree with 'reference' to round-off (README, Benchmark).",
                         choices=('qdldl', 'cholmod', 'superlu_sym', 'reference'))


@dataclass(frozen=True)
class OutputConfig:
    """What is written, and how often."""

    rate_hz: float = param(0.0, 'Hz', 'Frame (message) rate in simulation time; 0 = every '
                           'solver step. Rounded so that frames fall on solver steps.',
                           low=0.0, high=1e6)
    observers: tuple[str, ...] = param((), '-', 'Named displacement observers, each '
                                       "'name=component@x' with component rail_left, "
                                       'rail_right, slab, base or girder and x the position '
                                       'along the track (m); published on ~/observers/name.')


@dataclass(frozen=True)
class Scenario:
    """A complete simulation case."""

    name: str = param('custom', '-', 'Short name of the scenario.')
    description: str = param('', '-', 'One line describing the scenario.')
    train: TrainConfig = field(default_factory=TrainConfig)
    car: CarConfig = field(default_factory=CarConfig)
    track: TrackConfig = field(default_factory=TrackConfig)
    contact: ContactConfig = field(default_factory=ContactConfig)
    bridge: BridgeConfig = field(default_factory=BridgeConfig)
    bearings: BearingsConfig = field(default_factory=BearingsConfig)
    piers: PiersConfig = field(default_factory=PiersConfig)
    foundation: FoundationConfig = field(default_factory=FoundationConfig)
    irregularity: IrregularityConfig = field(default_factory=IrregularityConfig)
    solver: SolverConfig = field(default_factory=SolverConfig)
    output: OutputConfig = field(default_factory=OutputConfig)

    def __post_init__(self) -> None:
        """Check the rules that involve more than one key."""
        _check_consistency(self)

    def to_dict(self) -> dict[str, Any]:
        """Return the scenario as plain nested dicts (for echo in summaries)."""
        return _to_plain(dataclasses.asdict(self))


# --------------------------------------------------------------------------------------
# Key walking
# --------------------------------------------------------------------------------------

def iter_keys(cls: type = Scenario, prefix: str = '') -> Iterator[tuple[str, type, Any, Spec]]:
    """
    Yield every leaf key of the schema.

    Yields
    ------
    tuple
        (dotted key path, Python type, default, spec) for each leaf.

    """
    hints = _hints(cls)
    for f in dataclasses.fields(cls):
        path = f'{prefix}{f.name}'
        if 'spec' in f.metadata:
            yield path, hints[f.name], f.default, f.metadata['spec']
        else:
            yield from iter_keys(hints[f.name], prefix=f'{path}.')


def key_spec(path: str) -> tuple[type, Any, Spec]:
    """
    Return (type, default, spec) of one dotted key.

    Raises
    ------
    ScenarioError
        If the key does not exist.

    """
    for key, typ, default, spec in iter_keys():
        if key == path:
            return typ, default, spec
    raise ScenarioError(f'unknown key {path!r}; see `ttb-sim scenarios --keys` for the list')


def _hints(cls: type) -> dict[str, Any]:
    module = sys.modules[cls.__module__]
    out = {}
    for f in dataclasses.fields(cls):
        t = f.type
        out[f.name] = eval(t, vars(module)) if isinstance(t, str) else t  # noqa: S307
    return out


# --------------------------------------------------------------------------------------
# Building from plain data
# --------------------------------------------------------------------------------------

def from_mapping(data: Mapping[str, Any], cls: type = Scenario, prefix: str = '') -> Any:
    """
    Build a (nested) config dataclass from plain data, validating every key.

    Raises
    ------
    ScenarioError
        On an unknown key, a wrong type or a value out of range; the message
        names the key path, the value and what is allowed.

    """
    if not isinstance(data, Mapping):
        where = prefix[:-1] or 'the scenario'
        raise ScenarioError(f'{where} must be a mapping of keys, got {data!r}')
    hints = _hints(cls)
    names = {f.name: f for f in dataclasses.fields(cls)}
    kwargs: dict[str, Any] = {}
    for key, value in data.items():
        path = f'{prefix}{key}'
        if key not in names:
            allowed = ', '.join(sorted(names))
            raise ScenarioError(f'unknown key {path!r}; allowed here: {allowed}')
        f = names[key]
        if 'spec' in f.metadata:
            kwargs[key] = _coerce(path, value, hints[key], f.metadata['spec'])
        else:
            kwargs[key] = from_mapping(value, hints[key], prefix=f'{path}.')
    try:
        return cls(**kwargs)
    except ScenarioError:
        raise
    except (TypeError, ValueError) as exc:  # pragma: no cover - defensive
        raise ScenarioError(f'{prefix[:-1] or "scenario"}: {exc}') from None


def _coerce(path: str, value: Any, typ: Any, spec: Spec) -> Any:
    """Check one value against its declared type and range, and return it typed."""
    if typ in (tuple[float, ...],):
        if not isinstance(value, (list, tuple)):
            raise ScenarioError(f'{path} = {value!r}: expected a list of numbers ({spec.unit})')
        items = tuple(_coerce_number(f'{path}[{i}]', v, float, spec)
                      for i, v in enumerate(value))
        return items
    if typ in (tuple[str, ...],):
        if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
            raise ScenarioError(f'{path} = {value!r}: expected a list of strings')
        return tuple(value)
    if typ is str:
        if not isinstance(value, str):
            raise ScenarioError(f'{path} = {value!r}: expected a string, {spec.allowed()}')
        if spec.choices is not None and value not in spec.choices:
            raise ScenarioError(f'{path} = {value!r}: allowed values are {spec.allowed()}')
        return value
    if typ in (float, int):
        return _coerce_number(path, value, typ, spec)
    raise TypeError(f'unsupported schema type {typ!r} for {path}')  # pragma: no cover


def _coerce_number(path: str, value: Any, typ: type, spec: Spec) -> float | int:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        kind = 'an integer' if typ is int else 'a number'
        raise ScenarioError(f'{path} = {value!r}: expected {kind}, allowed {spec.allowed()}')
    if typ is int:
        if isinstance(value, float):
            if not value.is_integer():
                raise ScenarioError(f'{path} = {value!r}: expected an integer, allowed '
                                    f'{spec.allowed()}')
        value = int(value)
    else:
        value = float(value)
        if not math.isfinite(value):
            raise ScenarioError(f'{path} = {value!r}: expected a finite number, allowed '
                                f'{spec.allowed()}')
    if not spec.contains(value):
        raise ScenarioError(f'{path} = {value!r} is out of range: allowed {spec.allowed()}')
    return value


def _check_consistency(s: Scenario) -> None:
    if s.bridge.elements_per_span % 2:
        raise ScenarioError(f'bridge.elements_per_span = {s.bridge.elements_per_span}: must be '
                            'even, so that a node sits at mid-span')
    if s.foundation.model == 'springs' and s.bearings.model == 'rigid':
        raise ScenarioError("foundation.model = 'springs' needs bearings.model = 'elastic' "
                            '(rigid bearings model ideal fixed supports)')
    if s.train.vehicle == 'car' and s.track.model != 'slab':
        raise ScenarioError(f"train.vehicle = 'car' needs track.model = 'slab' (got "
                            f'{s.track.model!r}): wheels run on rails')
    if s.track.model == 'slab' and s.train.vehicle != 'car':
        raise ScenarioError(f"track.model = 'slab' needs train.vehicle = 'car' (got "
                            f'{s.train.vehicle!r})')
    parse_observers(s.output.observers)


OBSERVER_COMPONENTS = ('rail_left', 'rail_right', 'slab', 'base', 'girder')
_OBSERVER = re.compile(r'^([A-Za-z][A-Za-z0-9_]*)=([a-z_]+)@(.+)$')


@dataclass(frozen=True)
class Observer:
    """A named displacement observation point (``output.observers``)."""

    name: str
    component: str
    x: float


def parse_observers(entries: Sequence[str]) -> tuple[Observer, ...]:
    """
    Parse ``output.observers`` entries of the form ``name=component@x``.

    Raises
    ------
    ScenarioError
        Naming the entry and what is allowed, for a malformed entry, an unknown
        component, a non-finite position or a repeated name.

    """
    out: list[Observer] = []
    for i, entry in enumerate(entries):
        path = f'output.observers[{i}] = {entry!r}'
        match = _OBSERVER.match(entry.strip())
        if not match:
            raise ScenarioError(f"{path}: expected 'name=component@x' with a name of "
                                'letters, digits and _ (starting with a letter)')
        name, component, x_text = match.groups()
        if component not in OBSERVER_COMPONENTS:
            raise ScenarioError(f'{path}: component {component!r} is unknown; allowed: '
                                f'{", ".join(OBSERVER_COMPONENTS)}')
        try:
            x = float(x_text)
        except ValueError:
            x = math.nan
        if not math.isfinite(x):
            raise ScenarioError(f'{path}: position {x_text!r} is not a finite number (m)')
        if any(o.name == name for o in out):
            raise ScenarioError(f'{path}: observer name {name!r} is used twice')
        out.append(Observer(name, component, x))
    return tuple(out)


def _to_plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _to_plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_to_plain(v) for v in value]
    return value


# --------------------------------------------------------------------------------------
# Files, built-ins and overrides
# --------------------------------------------------------------------------------------

class YamlLoader(yaml.SafeLoader):
    """Safe YAML loader that also reads 1e6 and 1.5e-3 as floats (as YAML 1.2 does)."""


YamlLoader.yaml_implicit_resolvers = {
    key: [(tag, rx) for tag, rx in resolvers if tag != 'tag:yaml.org,2002:float']
    for key, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}
YamlLoader.add_implicit_resolver(
    'tag:yaml.org,2002:float',
    re.compile(r"""^(?:[-+]?(?:[0-9][0-9_]*)\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                |[-+]?(?:[0-9][0-9_]*)(?:[eE][-+]?[0-9]+)
                |\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                |[-+]?\.(?:inf|Inf|INF)
                |\.(?:nan|NaN|NAN))$""", re.X),
    list('-+0123456789.'))


def read_yaml(text: str) -> Any:
    """Parse YAML text with :class:`YamlLoader`."""
    return yaml.load(text, Loader=YamlLoader)  # noqa: S506 - a SafeLoader subclass


def config_dirs() -> list[Path]:
    """Return the folders searched for built-in scenarios, in order."""
    dirs = [Path(__file__).resolve().parent.parent / 'config']
    for scheme_key in ('data',):
        base = sysconfig.get_paths().get(scheme_key)
        if base:
            dirs.append(Path(base) / 'share' / 'ttb_sim' / 'config')
    dirs.append(Path(sys.prefix) / 'share' / 'ttb_sim' / 'config')
    try:  # a colcon / ament install
        from ament_index_python.packages import get_package_share_directory
        dirs.append(Path(get_package_share_directory('ttb_sim')) / 'config')
    except Exception:  # noqa: B902 - ament absent or package not in the index
        pass
    seen: list[Path] = []
    for d in dirs:
        if d not in seen:
            seen.append(d)
    return seen


def builtin_scenarios() -> dict[str, Path]:
    """Map built-in scenario names to their YAML files."""
    found: dict[str, Path] = {}
    for d in config_dirs():
        if d.is_dir():
            for p in sorted(d.glob('*.yaml')):
                if p.stem not in found and _is_scenario_file(p):
                    found[p.stem] = p
    return found


def _is_scenario_file(path: Path) -> bool:
    try:
        with path.open(encoding='utf-8') as fh:
            head = fh.read(4096)
    except OSError:
        return False
    return 'ros__parameters' not in head and 'Panels:' not in head


def resolve(source: str | Path) -> Path:
    """
    Find a scenario file from a path or a built-in name.

    Raises
    ------
    ScenarioError
        If neither a readable file nor a built-in of that name exists.

    """
    path = Path(source)
    if path.suffix in ('.yaml', '.yml') or path.exists():
        if not path.is_file():
            raise ScenarioError(f'scenario file {str(path)!r} does not exist')
        return path
    builtins = builtin_scenarios()
    if str(source) in builtins:
        return builtins[str(source)]
    names = ', '.join(sorted(builtins)) or '(none found)'
    raise ScenarioError(f'no scenario {str(source)!r}: give a YAML path or a built-in name '
                        f'({names})')


def parse_override(text: str) -> tuple[str, Any]:
    """
    Split a ``KEY=VALUE`` override; the value is read as a YAML scalar.

    Raises
    ------
    ScenarioError
        If the text has no '=' or the value is not valid YAML.

    """
    if '=' not in text:
        raise ScenarioError(f'--set {text!r}: expected KEY=VALUE, e.g. bridge.span_length=25')
    key, raw = text.split('=', 1)
    key = key.strip()
    try:
        value = read_yaml(raw) if raw.strip() else ''
    except yaml.YAMLError as exc:
        raise ScenarioError(f'--set {text!r}: value is not valid YAML ({exc})') from None
    return key, value


def apply_overrides(data: dict[str, Any], overrides: Sequence[tuple[str, Any]]) -> None:
    """
    Set dotted keys in nested plain data, in place.

    Raises
    ------
    ScenarioError
        If a key does not exist in the schema.

    """
    for key, value in overrides:
        key_spec(key)  # raises on unknown keys
        node = data
        parts = key.split('.')
        for part in parts[:-1]:
            child = node.get(part)
            if not isinstance(child, dict):
                child = {}
                node[part] = child
            node = child
        node[parts[-1]] = value


def load_scenario(source: str | Path, overrides: Sequence[str] = (),
                  values: Sequence[tuple[str, Any]] = ()) -> Scenario:
    """
    Load, override and validate a scenario.

    Parameters
    ----------
    source
        Path to a YAML file, or the name of a built-in scenario.
    overrides
        ``KEY=VALUE`` strings (values are YAML scalars), applied in order.
    values
        Already-typed ``(key, value)`` pairs, applied after ``overrides``.

    Returns
    -------
    Scenario
        The validated scenario.

    Raises
    ------
    ScenarioError
        If the file cannot be read or parsed, or any key is invalid.

    """
    path = resolve(source)
    try:
        text = path.read_text(encoding='utf-8')
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(f'cannot read scenario file {str(path)!r}: {exc}') from None
    try:
        data = read_yaml(text)
    except yaml.YAMLError as exc:
        raise ScenarioError(f'scenario file {str(path)!r} is not valid YAML: {exc}') from None
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise ScenarioError(f'scenario file {str(path)!r} must hold a mapping of keys')
    data.setdefault('name', path.stem)
    apply_overrides(data, [parse_override(o) for o in overrides] + list(values))
    return from_mapping(data)
