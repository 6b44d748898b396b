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
Multibody cars running on the slab track through wheel-rail contact.

``multibody`` holds the coupling (state, speed-dependent train matrices, the
step's acceptance and outputs), ``rail_compliance`` the local blocks and columns
of the inverse effective track matrix under the wheels, ``equilibrium`` the
static start, ``contact_step`` the compiled step that owns its work arrays,
``rail_kernels`` and ``contact_kernels`` its compiled loops, and
``reduced_track`` the variant that keeps the track in detail only in a window
around the train.
"""

from ttb_sim.sim.coupling.train_track.multibody import TrainTrackCoupling
from ttb_sim.sim.coupling.train_track.reduced_track import ReducedTrainTrackCoupling

__all__ = ['ReducedTrainTrackCoupling', 'TrainTrackCoupling']
