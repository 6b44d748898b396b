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
Reduced vehicles (`model/vehicle/train.py`): axle layouts and quarter-car numbers.

References: the Yang & Yau (1997) quarter car of PHYSICS.md 9.3 (M_v = 5750 kg,
k_v = 1595 kN/m, f_v = 2.65 Hz) and the [P] Table 1 car geometry (bogie semi-spacing
l_c = 7.85 m, wheelbase semi l_t = 1.25 m, 25 m cars).
"""

import math

import numpy as np
import pytest
from ttb_sim.config import load_scenario
from ttb_sim.model.vehicle.train import Axles, MovingForces, MultibodyCars, QuarterCars
from ttb_sim.sim import build_vehicle


def _quarter_cars(sprung, unsprung, stiffness):
    n = len(sprung)
    return QuarterCars(axles=Axles(np.arange(n) * 2.5), sprung_mass=np.array(sprung),
                       unsprung_mass=np.array(unsprung), stiffness=np.array(stiffness),
                       damping=np.zeros(n))


def test_axles_count_and_train_length():
    axles = Axles(np.array([0.0, 2.5, 17.5, 20.0]))
    assert axles.count == 4
    assert axles.train_length == 20.0
    assert Axles(np.zeros(0)).count == 0
    assert Axles(np.zeros(0)).train_length == 0.0


def test_quarter_car_frequency_yang_yau():
    """f_v = sqrt(k / M) / (2 pi) = 2.65 Hz for the Yang & Yau vehicle (PHYSICS.md 9.3)."""
    cars = _quarter_cars([5750.0, 4 * 5750.0], [0.0, 0.0], [1.595e6, 1.595e6])
    f = cars.natural_frequency()
    assert f[0] == pytest.approx(2.65, abs=0.005)
    assert f[1] == pytest.approx(0.5 * f[0], rel=1e-12)  # four times the mass: half


def test_quarter_car_static_load():
    """The static wheel load is (M_s + M_u) g with g = 9.81 m/s^2."""
    cars = _quarter_cars([5750.0, 12000.0], [0.0, 1200.0], [1.595e6, 1.0e6])
    assert cars.static_load == pytest.approx([5750.0 * 9.81, 13200.0 * 9.81], rel=1e-12)


def test_sprung_mass_scenario_builds_one_quarter_car():
    """The contract scenario's train is the Yang & Yau quarter car, one axle at the head."""
    vehicle = build_vehicle(load_scenario('sprung_mass_beam'))
    assert isinstance(vehicle, QuarterCars)
    assert vehicle.axles.offsets.tolist() == [0.0]
    assert vehicle.static_load == pytest.approx([5750.0 * 9.81])
    assert vehicle.natural_frequency() == pytest.approx([2.65], abs=0.005)


def test_moving_force_scenario_loads():
    vehicle = build_vehicle(load_scenario('moving_force_beam', ['train.axle_load=1e5']))
    assert isinstance(vehicle, MovingForces)
    assert vehicle.loads.tolist() == [1e5]


def test_car_train_axle_layout():
    """
    Eight 25 m cars: per car, axles at the car centre -/+ l_c -/+ l_t.

    So the spacings inside a car are 2 l_t = 2.5 m, 2 l_c - 2 l_t = 13.2 m and
    2.5 m, the gap to the next car 25 - 18.2 = 6.8 m, and each car's axles are
    centred on it (12.5 m + 25 k behind the head).
    """
    vehicle = build_vehicle(load_scenario('paper_ttbi'))
    assert isinstance(vehicle, MultibodyCars)
    assert vehicle.n_cars == 8
    assert vehicle.length == 200.0
    offsets = vehicle.axles.offsets
    assert vehicle.axles.count == 32
    spacing = np.diff(offsets)
    assert spacing == pytest.approx(np.tile([2.5, 13.2, 2.5, 6.8], 8)[:-1])
    centres = offsets.reshape(8, 4).mean(axis=1)
    assert centres == pytest.approx(12.5 + 25.0 * np.arange(8))
    assert vehicle.axles.train_length == pytest.approx(7 * 25.0 + 12.5 + 7.85 + 1.25)
    assert math.isclose(offsets[0], 12.5 - 7.85 - 1.25)
