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
Full-system validation (VALIDATION.md V19): the paper's TTBI passage.

V19 runs the built-in ``paper_ttbi`` scenario (eight cars, ten spans, the whole
passage; about 20 minutes on one core) on VALIDATION.md's "Chinese HSR + Sato"
irregularity and reads two frequencies off the spectra of what it publishes:
where the vertical wheel-rail force PSD changes level (the Chinese-to-Sato
junction at lambda = 1 m, V / lambda = 83.3 Hz at 300 km/h) and where the
car-body vertical acceleration PSD peaks (the car-body bounce, 0.84 Hz). The
evaluation is a separate function so that a bag or any run's frames can be
checked the same way.

The irregularity is the ``chinese_sato`` preset (Chinese 1-200 m + Sato), not
[P]'s ``paper`` preset (Chinese 1-50 m): 50 m is 1.67 Hz at 300 km/h, so with
[P]'s band nothing drives the 0.84 Hz bounce and the car-body PSD peaks at the
band edge (measured 1.87 Hz; the force PSD step at 83.0 Hz is the same).
"""

from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np

from ttb_sim.analysis.psd import level_change_frequency, peak_frequency, welch_psd
from ttb_sim.config import load_scenario
from ttb_sim.sim import Frame, Simulation
from ttb_sim.validation.rows import Case, relative_row, Row

JUNCTION_WAVELENGTH = 1.0
"""Wavelength (m) where the paper's irregularity passes from the Chinese to the Sato PSD."""
BOUNCE_FREQUENCY = 0.84
"""Car-body bounce frequency of [P] Table 1 (Hz), PHYSICS.md 3.1."""


def v19_rows(frames: Iterable[Frame], speed: float) -> list[Row]:
    """
    Evaluate V19 on the frames of a TTBI run with the paper's irregularity.

    Parameters
    ----------
    frames : iterable of Frame
        Frames at a constant rate (multibody cars).
    speed : float
        Train speed (m/s).

    Returns
    -------
    list of Row
        Level-change frequency of the wheel-rail force PSD (all wheels of the
        first car averaged) and the car-body acceleration PSD peak (all cars).

    """
    frames = list(frames)
    times = np.array([f.time for f in frames])
    rate = 1.0 / float(np.median(np.diff(times)))
    force = np.array([f.wheel_rail[0, :, :, 2].ravel() for f in frames])
    acc = np.array([f.body_acceleration[:, 2] for f in frames])
    junction = speed / JUNCTION_WAVELENGTH
    spectra = [welch_psd(force[:, k], rate, segment_seconds=0.5) for k in range(force.shape[1])]
    f_force = spectra[0][0]
    p_force = np.mean([p for _, p in spectra], axis=0)
    step = level_change_frequency(f_force, p_force, band=(0.5 * junction, 2.0 * junction))
    body = [welch_psd(acc[:, k], rate, segment_seconds=min(10.0, times[-1] / 2))
            for k in range(acc.shape[1])]
    f_body = body[0][0]
    p_body = np.mean([p for _, p in body], axis=0)
    peak = peak_frequency(f_body, p_body, band=(0.3, 3.0))
    return [relative_row('V19', 'wheel-rail PSD level change', step, junction, 0.05, 'Hz'),
            relative_row('V19', 'car-body PSD peak', peak, BOUNCE_FREQUENCY, 0.05, 'Hz')]


#: Irregularity of V19 (see the module docstring).
V19_IRREGULARITY = 'chinese_sato'


def _v19(overrides: Sequence[str] = ()) -> list[Row]:
    scenario = load_scenario('paper_ttbi', overrides,
                             [('irregularity.spectrum', V19_IRREGULARITY)])
    sim = Simulation(scenario)
    return v19_rows(sim.frames(), scenario.train.speed)


SYSTEM_CASES = (
    Case('V19', 'TTBI at 300 km/h, Chinese HSR 1-200 m + Sato (paper_ttbi, about 20 min)',
         _v19),
)
