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
The state of a pile-soil block, what is observed of it, and its interface response.

:class:`State` is the full state the integrators advance (displacements,
velocities and accelerations of every DOF, and the Desai plastic slip of the
interface); :func:`initial_state` is the geostatic state at rest.
:func:`observe` turns a state into a :class:`PileSoilFrame`, the pile-head and
soil-point response the runs record. :func:`interface_response` evaluates the
pile-soil interface at a displacement: its internal force, tangent and trial
slip, which the time stepping and the static solve both iterate on.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ttb_sim.model.foundation.substructure import PileSoilModel


@dataclass(frozen=True)
class PileSoilFrame:
    """
    Observed response at one instant (SI units, global axes, z up).

    Attributes
    ----------
    time : float
        s.
    pile_displacement, pile_acceleration : arrays, shape (n_piles, 3)
        Pile-head area-weighted mean displacement (m) and acceleration (m/s^2).
    pile_rotation, pile_rotation_rate : arrays, shape (n_piles, 3)
        Pile-head rigid rotation (rad) and rotation rate (rad/s).
    soil_displacement, soil_acceleration, soil_velocity : arrays, shape (n_points, 3)
        At the model's soil points (m, m/s^2, m/s).

    """

    time: float
    pile_displacement: np.ndarray
    pile_acceleration: np.ndarray
    pile_rotation: np.ndarray
    pile_rotation_rate: np.ndarray
    soil_displacement: np.ndarray
    soil_acceleration: np.ndarray
    soil_velocity: np.ndarray


@dataclass(frozen=True)
class State:
    """Full state: time (s), u (m), v (m/s), a (m/s^2), interface slip (k, 4, 2)."""

    time: float
    u: np.ndarray
    v: np.ndarray
    a: np.ndarray
    slip: Optional[np.ndarray]


def observe(model: PileSoilModel, state: State) -> PileSoilFrame:
    """Return the observed frame of a state."""
    n_p = model.n_piles
    hd, hr, sp_op = model.head_displacement, model.head_rotation, model.soil_points.operator
    n_s = len(model.soil_points.names)
    return PileSoilFrame(state.time, (hd @ state.u).reshape(n_p, 3),
                         (hd @ state.a).reshape(n_p, 3), (hr @ state.u).reshape(n_p, 3),
                         (hr @ state.v).reshape(n_p, 3), (sp_op @ state.u).reshape(n_s, 3),
                         (sp_op @ state.a).reshape(n_s, 3), (sp_op @ state.v).reshape(n_s, 3))


def interface_response(model: PileSoilModel, u: np.ndarray, slip: Optional[np.ndarray]
                       ) -> tuple[np.ndarray, Optional[np.ndarray], Optional[np.ndarray]]:
    """Return (internal force, tangent (k,4,3), trial slip) of the interface at u."""
    if model.interface is None or model.law is None or slip is None:
        return np.zeros_like(u), None, None
    stress, tangent, new_slip = model.law.evaluate(model.interface.strain(u), slip)
    return model.interface.force(stress), tangent, new_slip


def initial_state(model: PileSoilModel) -> State:
    """Return the geostatic state at rest (zero displacement from it, no slip)."""
    n = model.n_dofs
    slip = None if model.interface is None else np.zeros((model.interface.n_elements, 4, 2))
    return State(0.0, np.zeros(n), np.zeros(n), np.zeros(n), slip)
