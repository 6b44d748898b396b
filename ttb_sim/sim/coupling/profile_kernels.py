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
The irregularity profile's interpolation as a kernel helper (numba source).

The kernels that sample the track irregularity under the wheels (the quarter
cars' centreline profile, the rails under the multibody cars) call
:func:`quintic`, the arithmetic of
:meth:`ttb_sim.model.irregularity.profile.TrackIrregularity.sample`.
"""

from __future__ import annotations


def quintic(p0: float, p1: float, m0: float, m1: float, c0: float,
            c1: float) -> tuple[float, float, float, float]:
    """
    Return (a2, a3, a4, a5) of the quintic Hermite on [0, 1] through value p, slope m, curvature c.

    p(t) = p0 + m0 t + a2 t^2 + ... + a5 t^5, the arithmetic of
    :meth:`ttb_sim.model.irregularity.profile.TrackIrregularity.sample`.
    """
    a2 = 0.5 * c0
    d0 = p1 - (p0 + m0 + a2)
    d1 = m1 - (m0 + c0)
    d2 = c1 - c0
    return (a2, 10.0 * d0 - 4.0 * d1 + 0.5 * d2, -15.0 * d0 + 7.0 * d1 - d2,
            6.0 * d0 - 3.0 * d1 + 0.5 * d2)
