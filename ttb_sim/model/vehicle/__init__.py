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
Vehicles: the car record, its DOFs and matrices, modal tools, and the train models.

``car`` holds the car record (:class:`CarParameters`, the scenario's ``car``
section), ``dofs`` the body/component indexing of the 42-DOF car, ``suspension``
its suspension elements, stiffness and damping, ``matrices`` its mass and
gyroscopic matrices, contact maps and the matrices of a car and of a train of cars,
``modal`` the eigen-analysis used by V4, ``train`` the vehicle models a scenario
runs (moving forces, quarter cars, multibody cars).  The linear hunting
analysis is :mod:`ttb_sim.model.vehicle.stability` (imported on its own).
"""

from ttb_sim.model.vehicle.car import body_positions, CarParameters, static_wheel_load
from ttb_sim.model.vehicle.dofs import (BODY_NAMES, BOGIES, CAR_BODY, COMPONENTS, dof,
                                        DOF_PER_BODY, dofs, N_BODIES, N_DOF, SIDES, wheelset_dofs,
                                        WHEELSETS)
from ttb_sim.model.vehicle.matrices import (car_matrices, CarMatrices, contact_map,
                                            contact_spring_stiffness, ContactMap, gravity_vector,
                                            gyroscopic_matrix, mass_matrix, train_matrices,
                                            TrainMatrices)
from ttb_sim.model.vehicle.modal import eigenfrequencies, modal_damping_ratios
from ttb_sim.model.vehicle.suspension import (damping_matrix, point_motion_matrix,
                                              stiffness_matrix, suspension_elements,
                                              SuspensionElements)
from ttb_sim.model.vehicle.train import Axles, MovingForces, MultibodyCars, QuarterCars, Vehicle

__all__ = ['Axles', 'BODY_NAMES', 'body_positions', 'BOGIES', 'CAR_BODY', 'car_matrices',
           'CarMatrices', 'CarParameters', 'COMPONENTS', 'contact_map', 'contact_spring_stiffness',
           'ContactMap', 'damping_matrix', 'dof', 'DOF_PER_BODY', 'dofs', 'eigenfrequencies',
           'gravity_vector', 'gyroscopic_matrix', 'mass_matrix', 'modal_damping_ratios',
           'MovingForces', 'MultibodyCars', 'N_BODIES', 'N_DOF', 'point_motion_matrix',
           'QuarterCars', 'SIDES', 'static_wheel_load', 'stiffness_matrix', 'suspension_elements',
           'SuspensionElements', 'train_matrices', 'TrainMatrices', 'Vehicle', 'wheelset_dofs',
           'WHEELSETS']
