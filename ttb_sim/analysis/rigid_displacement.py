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
The rigid-displacement method of [P] Eq. 16: a girder's mid-span settles as a rigid body.

With the girder rigid, its mid-span moves by the mean of its two supports, and
each piled support by the mean of its piles: ``U_B(t) = sum_i U_p,i(t) / (2 N)``
over the N piles of each of the two foundations.  A support without piles
(rigid, or springs whose motion the bag does not record) counts as 0.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.errors import ScenarioError

__all__ = ['rigid_midspan_displacement']


def rigid_midspan_displacement(left_piles: ArrayLike | None, right_piles: ArrayLike | None
                               ) -> NDArray[np.float64]:
    """
    Return the rigid-body mid-span displacement of a span (Eq. 16).

    Parameters
    ----------
    left_piles, right_piles : array_like or None
        (samples, piles) vertical pile-head displacements of the span's two
        supports (m), or None for a support without piles. At least one given.

    """
    groups = [None if g is None else np.asarray(g, dtype=float) for g in (left_piles,
                                                                          right_piles)]
    given = [g for g in groups if g is not None]
    if not given:
        raise ScenarioError('rigid_midspan_displacement needs the piles of at least one support')
    n = given[0].shape[0]
    means = []
    for g in groups:
        if g is None:
            means.append(np.zeros(n))
            continue
        if g.ndim != 2 or g.shape[0] != n or g.shape[1] == 0:
            raise ScenarioError(f'pile displacements must be (samples, piles) with {n} samples, '
                                f'got shape {g.shape}')
        means.append(g.mean(axis=1))
    return np.asarray(0.5 * (means[0] + means[1]), dtype=float)
