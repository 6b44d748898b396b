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
Vehicle-structure couplings behind one protocol (:class:`Coupling`).

Moving forces (no vehicle dynamics, ``moving_force``), quarter cars on the
girders (``quarter_car/``), and 42-DOF multibody cars on the slab track through
wheel-rail contact (``train_track/``); beside them the protocol (``base``), the
girder loads and rows of points on beams (``girder_load``) and the irregularity
profile's interpolation as a kernel helper (``profile_kernels``).
"""

from ttb_sim.sim.coupling.base import (Coupling, FusedCoupling, girder_wheel_load,
                                       VehicleOutputs)
from ttb_sim.sim.coupling.moving_force import MovingForceCoupling
from ttb_sim.sim.coupling.quarter_car import QuarterCarCoupling, QuarterCarTrain
from ttb_sim.sim.coupling.train_track import ReducedTrainTrackCoupling, TrainTrackCoupling

__all__ = ['Coupling', 'FusedCoupling', 'girder_wheel_load', 'MovingForceCoupling',
           'QuarterCarCoupling', 'QuarterCarTrain', 'ReducedTrainTrackCoupling',
           'TrainTrackCoupling', 'VehicleOutputs']
