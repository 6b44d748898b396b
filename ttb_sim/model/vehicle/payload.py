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
Passenger load (``train.passenger_load``): a mass per car carried by the car body.

The load is spread like the car body's own mass, so it adds to the body mass and
scales the body's roll, pitch and yaw inertias by (M_c + m) / M_c (the radii of
gyration are kept). The bogies and wheelsets are unchanged. The simpler vehicle
models carry it through their axles: a moving force gains m g / n, a quarter car's
sprung mass m / n, with n the axles per car.
"""

from __future__ import annotations

from dataclasses import replace

from ttb_sim.model.vehicle.car import CarParameters

__all__ = ['loaded_car', 'mass_per_axle']


def loaded_car(car: CarParameters, passenger_load: float) -> CarParameters:
    """Return the car with ``passenger_load`` (kg) carried by its body."""
    if passenger_load == 0.0:
        return car
    ratio = (car.car_body_mass + passenger_load) / car.car_body_mass
    return replace(car, car_body_mass=car.car_body_mass + passenger_load,
                   car_body_roll_inertia=car.car_body_roll_inertia * ratio,
                   car_body_pitch_inertia=car.car_body_pitch_inertia * ratio,
                   car_body_yaw_inertia=car.car_body_yaw_inertia * ratio)


def mass_per_axle(passenger_load: float, axles_per_car: int) -> float:
    """Return the share of one car's passenger load (kg) that each of its axles carries."""
    return passenger_load / axles_per_car
