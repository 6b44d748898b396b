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
The degrees of freedom of the 42-DOF car: bodies, components and their indices.

Seven rigid bodies, six DOF each, body-major ordering ``index = 6 * body + component``:
body 0 ``car_body``, 1 ``bogie_1`` (front, +l_c), 2 ``bogie_2`` (rear, -l_c),
3..6 ``wheelset_1..4`` (+l_c + l_t, +l_c - l_t, -l_c + l_t, -l_c - l_t).  Components:
0 ``x`` (longitudinal), 1 ``y`` (lateral, to the left), 2 ``z`` (up), 3 ``roll``,
4 ``pitch``, 5 ``yaw`` (REP 103, right-handed).  The wheelset ``pitch`` DOF carries
the spin perturbation (see :mod:`ttb_sim.model.vehicle.matrices`).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ttb_sim.errors import ModelError

#: Names of the seven bodies, in DOF order.
BODY_NAMES = ('car_body', 'bogie_1', 'bogie_2',
              'wheelset_1', 'wheelset_2', 'wheelset_3', 'wheelset_4')

#: Names of the six components of each body, in DOF order.
COMPONENTS = ('x', 'y', 'z', 'roll', 'pitch', 'yaw')

N_BODIES = 7
DOF_PER_BODY = 6
N_DOF = N_BODIES * DOF_PER_BODY

CAR_BODY = 0
BOGIES = (1, 2)
WHEELSETS = (3, 4, 5, 6)

#: Sides of the wheels, in contact order: left (+1, y > 0) then right (-1).
SIDES = (1, -1)


def _index(names: Sequence[str], key: int | str, what: str) -> int:
    if isinstance(key, str):
        if key not in names:
            msg = f'{what} {key!r} is unknown; allowed: {", ".join(names)}'
            raise ModelError(msg)
        return names.index(key)
    value = int(key)
    if not 0 <= value < len(names):
        msg = f'{what} index {key} is out of range; allowed: 0..{len(names) - 1}'
        raise ModelError(msg)
    return value


def dof(body: int | str, component: int | str) -> int:
    """
    Return the index of one DOF in the 42-vector of a car.

    Parameters
    ----------
    body : int or str
        Body index 0..6 or name from :data:`BODY_NAMES`.
    component : int or str
        Component index 0..5 or name from :data:`COMPONENTS`.

    Returns
    -------
    int
        ``6 * body + component``.

    Raises
    ------
    ModelError
        If the body or component is unknown.

    """
    return (DOF_PER_BODY * _index(BODY_NAMES, body, 'body')
            + _index(COMPONENTS, component, 'component'))


def dofs(bodies: Sequence[int | str], components: Sequence[int | str]) -> np.ndarray:
    """
    Return the DOF indices of every (body, component) pair, body-major.

    Parameters
    ----------
    bodies : sequence of int or str
        Bodies (indices or names).
    components : sequence of int or str
        Components (indices or names).

    Returns
    -------
    numpy.ndarray
        Integer array of ``len(bodies) * len(components)`` indices.

    """
    return np.array([dof(b, c) for b in bodies for c in components], dtype=int)


def wheelset_dofs(j: int) -> np.ndarray:
    """
    Return the six DOF indices of wheelset ``j`` (0..3, front to rear).

    Parameters
    ----------
    j : int
        Wheelset number within the car, 0 = leading axle.

    Returns
    -------
    numpy.ndarray
        Indices of x, y, z, roll, pitch (spin perturbation), yaw.

    """
    if not 0 <= int(j) < 4:
        raise ModelError(f'wheelset number {j} is out of range; allowed: 0..3')
    return dofs([WHEELSETS[int(j)]], COMPONENTS)
