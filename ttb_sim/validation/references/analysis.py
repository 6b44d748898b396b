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
References of the post-processing cases V21 and V22 (VALIDATION.md), from their definitions.

- ISO 2631-1 Table 3 values of the vertical weighting |Wk| (PHYSICS.md section 8);
- the mean power of a harmonic force against a harmonic velocity of the
  same frequency, ``F0 V0 cos(phi) / 2``, and the time mean of F v of two
  sampled records (Eq. 17), computed directly in the time domain.
"""

from __future__ import annotations

import math

import numpy as np

WK_TABLE: dict[float, float] = {1.0: 0.482, 6.3: 1.054, 80.0: 0.132}
"""|Wk| at 1, 6.3 and 80 Hz (ISO 2631-1 Table 3, as quoted in PHYSICS.md section 8)."""


def harmonic_power(force_amplitude: float, velocity_amplitude: float, phase: float) -> float:
    """Return the mean power F0 V0 cos(phase) / 2 of two sines of one frequency (W)."""
    return 0.5 * force_amplitude * velocity_amplitude * math.cos(phase)


def time_mean_power(force: np.ndarray, velocity: np.ndarray) -> float:
    """Return the time mean of F(t) v(t) of two sampled records (Eq. 17)."""
    return float(np.mean(np.asarray(force, dtype=float) * np.asarray(velocity, dtype=float)))
