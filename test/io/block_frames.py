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

"""Frames of every topic family for the bag tests: random values, a few special ones."""

from __future__ import annotations

import numpy as np
from ttb_sim.sim import Frame, Layout

LAYOUT = Layout(n_spans=2, n_supports=3, n_bodies=2, n_axles=4, observers=('left', 'mid'),
                piles=((2, 3), (3, 1)), soil_points=40)
SPECIAL = np.array([0.0, -0.0, np.nan, np.inf, -np.inf, 1e-310, -1e300, 5e-324])


def frames(n: int, layout: Layout = LAYOUT) -> list[Frame]:
    """Frames of random values (a few special ones), stamps from 0.95 s in steps of 0.7 ms."""
    rng = np.random.default_rng(7)
    out = []
    for k in range(n):
        row = rng.normal(size=layout.row_width) * 10.0 ** rng.integers(-6, 6, layout.row_width)
        special = rng.random(layout.row_width) < 0.02
        row[special] = rng.choice(SPECIAL, int(special.sum()))
        fields = {name: row[cols] for name, cols in layout.columns().items() if name != 'zero'}
        fields['head_position'], fields['speed'] = float(row[1]), float(row[2])
        out.append(Frame(step=k, time=0.95 + k * 7e-4, **fields))
    return out
