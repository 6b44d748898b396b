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
Post-processing cases V21 (power flow, Parseval) and V22 (ISO 2631 Wk) of VALIDATION.md.

V21 runs ``sprung_mass_beam`` through the pipeline and takes the vertical
wheel-rail force of the quarter car against the girder's mid-span velocity
(central differences of the recorded displacement): the lines of
:func:`ttb_sim.analysis.power_flow.power_flow_spectrum` must sum to the time
mean of F v (tolerance 0.1 %).  A second row checks one line of a sampled
harmonic pair against F0 V0 cos(phi) / 2.  V22 compares |Wk| with the ISO
table at 1, 6.3 and 80 Hz (tolerance 1 %).
"""

from __future__ import annotations

import math

import numpy as np

from ttb_sim.analysis.power_flow import power_flow_spectrum, velocity_from_displacement
from ttb_sim.analysis.weighting import weighting_response
from ttb_sim.config import load_scenario
from ttb_sim.sim import Simulation
from ttb_sim.validation.references.analysis import harmonic_power, time_mean_power, WK_TABLE
from ttb_sim.validation.rows import Case, relative_row, Row

V21_TOLERANCE = 1e-3
V22_TOLERANCE = 0.01


def _v21() -> list[Row]:
    sim = Simulation(load_scenario('sprung_mass_beam'))
    frames = list(sim.frames())
    rate = 1.0 / (frames[1].time - frames[0].time)
    force = np.array([f.wheel_rail[0, 0, :, 2].sum() for f in frames])
    velocity = velocity_from_displacement(np.array([f.midspan[0, 2] for f in frames]), rate)
    _, p = power_flow_spectrum(-force, velocity, rate)   # force of the wheel on the girder
    rows = [relative_row('V21', 'sum P(f) = mean F v (pipeline)', float(p.sum()),
                         time_mean_power(-force, velocity), V21_TOLERANCE, 'W')]
    n, f0, phase, amp_f, amp_v = 4000, 12.5, 0.7, 2.0e3, 0.01
    t = np.arange(n) / 1000.0
    f, p = power_flow_spectrum(amp_f * np.sin(2 * math.pi * f0 * t),
                               amp_v * np.sin(2 * math.pi * f0 * t - phase), 1000.0)
    line = float(p[int(np.argmin(np.abs(f - f0)))])
    rows.append(relative_row('V21', 'P(12.5 Hz) of a harmonic pair', line,
                             harmonic_power(amp_f, amp_v, phase), V21_TOLERANCE, 'W'))
    return rows


def _v22() -> list[Row]:
    return [relative_row('V22', f'|Wk| at {f:g} Hz', float(abs(weighting_response(f, 'Wk'))),
                         value, V22_TOLERANCE, '-') for f, value in WK_TABLE.items()]


ANALYSIS_CASES = (
    Case('V21', 'power flow: the lines sum to the time mean of F v (Parseval)', _v21),
    Case('V22', 'ISO 2631 Wk weighting against the ISO table', _v22),
)
