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
Coupled-model validation (VALIDATION.md V17, V18, V20): piled piers under the train.

V17 runs ``paper_ttbcpsi`` with the substructures at 3 dt and at dt and compares
the bearing forces of the piled piers and the pile-head displacements (RMS
difference over the run, relative to the RMS of the n = 1 run; 1 %). V18 does
the same for the partitioned against the monolithic solution ([P] Eq. 12
against Eq. 11) on a reduced configuration: two spans, one piled pier, a
coarser soil mesh, two cars. V20 runs the coupled model at 250, 300, 350 and
400 km/h and reads where the vertical acceleration of the central pile of
pier 7 peaks between the first two car-passage lines (V / car length and
twice that, which dominate the spectrum of a train of equal cars): [P]
Eq. 19 puts the axle groups' peak in the band V / (2 L_w + 2 L_b) to
V / (2 L_b).

The full cases run the whole passage of the paper scenario (V17 twice, V20
four times); :data:`FAST` names the overrides of the reduced configuration
that the test suite runs through the same functions.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ttb_sim.analysis.psd import padded_periodogram
from ttb_sim.config import load_scenario, Scenario
from ttb_sim.sim import Simulation
from ttb_sim.validation.rows import Case, Row

COUPLING_TOLERANCE = 0.01
"""V17, V18: largest RMS difference, relative to the reference run's RMS."""
V20_SPEEDS = (250.0, 300.0, 350.0, 400.0)
"""Train speeds of V20 (km/h)."""
REDUCED = ('bridge.n_spans=2', 'foundation.piled_piers=[2]', 'train.n_cars=2',
           'soil.mesh.h=1.0', 'soil.mesh.h_max=4.0', 'soil.mesh.h_shaft=2.0',
           "output.observers=['girder_1=girder@32.0']")
"""V18's reduced configuration of ``paper_ttbcpsi``."""
FAST = ('train.vehicle=moving_force', 'track.model=none', 'bridge.n_spans=4',
        'foundation.piled_piers=[3]', 'soil.mesh.h=1.5', 'soil.mesh.h_max=5.0',
        'soil.mesh.h_shaft=3.0', 'soil.block.lx=30.0', 'soil.block.ly=24.0',
        "output.observers=['girder_1=girder@80.0']", 'solver.dt=2e-4')
"""The test suite's configuration: eight moving-force cars over four spans, pier 3 piled on
a coarse soil mesh (18 000 DOFs reduced to 126 coordinates), dt = 2e-4 s."""


def coupled_histories(scenario: Scenario) -> dict[str, np.ndarray]:
    """
    Run a coupled scenario; return the piled piers' histories.

    Returns
    -------
    dict
        'bearings' (frames, piled piers, 2, 3) N, 'piles' (frames, piles, 3) m
        pile-head displacement, 'pile_acceleration' (frames, piles, 3) m/s^2,
        'time' (frames,) s.

    """
    sim = Simulation(scenario)
    piled = [p.support for p in sim.structure.piled]
    rows: dict[str, list[np.ndarray]] = {'bearings': [], 'piles': [],
                                         'pile_acceleration': [], 'time': []}
    for frame in sim.frames():
        rows['bearings'].append(frame.bearings[piled])
        rows['piles'].append(frame.pile_displacement)
        rows['pile_acceleration'].append(frame.pile_acceleration)
        rows['time'].append(np.array(frame.time))
    return {k: np.array(v) for k, v in rows.items()}


def rms_difference(x: np.ndarray, reference: np.ndarray) -> float:
    """Return RMS(x - reference) / RMS(reference) over all entries."""
    scale = float(np.sqrt(np.mean(reference ** 2)))
    return float(np.sqrt(np.mean((x - reference) ** 2))) / scale if scale > 0 else np.inf


def comparison_rows(case: str, what: str, run: dict[str, np.ndarray],
                    reference: dict[str, np.ndarray]) -> list[Row]:
    """Rows of the relative RMS differences of bearing forces and pile-head displacement."""
    rows = []
    for key, label in (('bearings', 'bearing forces of piled piers'),
                       ('piles', 'pile-head displacement')):
        error = rms_difference(run[key], reference[key])
        rows.append(Row(case, f'{label}, {what}', error, 0.0, error, COUPLING_TOLERANCE,
                        error <= COUPLING_TOLERANCE, error_kind='relative RMS'))
    return rows


def _v17(overrides: Sequence[str] = ()) -> list[Row]:
    runs = {n: coupled_histories(load_scenario('paper_ttbcpsi', [
        *overrides, f'solver.substructure_steps={n}'])) for n in (3, 1)}
    return comparison_rows('V17', 'n = 3 vs n = 1', runs[3], runs[1])


def _v18(overrides: Sequence[str] = REDUCED) -> list[Row]:
    partitioned = coupled_histories(load_scenario('paper_ttbcpsi', overrides))
    monolithic = coupled_histories(load_scenario('paper_ttbcpsi', [
        *overrides, 'solver.coupling=monolithic', 'solver.substructure_steps=1']))
    return comparison_rows('V18', 'partitioned vs monolithic', partitioned, monolithic)


def axle_group_band(scenario: Scenario) -> tuple[float, float]:
    """Return [P] Eq. 19's band V / (2 L_w + 2 L_b) .. V / (2 L_b) (Hz)."""
    car, speed = scenario.car, scenario.train.speed
    return (speed / (2 * car.wheelbase_semi + 2 * car.bogie_semi_spacing),
            speed / (2 * car.bogie_semi_spacing))


def harmonic_window(scenario: Scenario, record_seconds: float) -> tuple[float, float]:
    """
    Return the frequencies between the first two car-passage harmonics, their lines excluded.

    A train of equal cars loads a pier periodically: the pile response is
    lines at multiples of V / car length, and [P] Eq. 19's band always lies
    between the first two (2 L_w + 2 L_b < car length < 2 (2 L_b)). The
    window leaves out each line's Hann main lobe, 2 / T either side.
    """
    line = scenario.train.speed / scenario.train.car_length
    lobe = 2.0 / record_seconds
    return line + lobe, 2.0 * line - lobe


def pile_peak(acceleration: np.ndarray, rate: float, window: tuple[float, float]) -> float:
    """
    Return the frequency of the largest PSD value of ``acceleration`` inside ``window`` (Hz).

    The PSD is the zero-padded Hann periodogram of the whole record (a
    passage is a few seconds: Welch segments would not resolve the car lines).
    """
    f, p = padded_periodogram(acceleration, rate)
    band = np.flatnonzero((f > window[0]) & (f < window[1]))
    return float(f[band[np.argmax(p[band])]])


def v20_row(scenario: Scenario) -> Row:
    """
    Evaluate V20 at one speed: whether the pile acceleration peaks in Eq. 19's band.

    The peak searched is the largest PSD value of the central pile's vertical
    acceleration (first piled pier) between the car-passage lines
    (:func:`harmonic_window`): the axle groups' own contribution.
    """
    run = coupled_histories(scenario)
    time = run['time']
    rate = 1.0 / float(time[1] - time[0])
    central = scenario.piles.count // 2
    peak = pile_peak(run['pile_acceleration'][:, central, 2], rate,
                     harmonic_window(scenario, float(time[-1] - time[0])))
    lo, hi = axle_group_band(scenario)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    error = abs(peak - centre)
    return Row('V20', f'pile acc. PSD peak, {scenario.train.speed_kmh:g} km/h '
               f'(band {lo:.2f}-{hi:.2f} Hz)', peak, centre, error, half, error <= half, 'Hz',
               error_kind='absolute')


def _v20(overrides: Sequence[str] = (), speeds: Sequence[float] = V20_SPEEDS) -> list[Row]:
    return [v20_row(load_scenario('paper_ttbcpsi', [*overrides, f'train.speed_kmh={v}']))
            for v in speeds]


COUPLED_CASES = (
    Case('V17', 'TTBCPSI substructures at 3 dt vs dt (paper_ttbcpsi, two passages)', _v17),
    Case('V18', 'partitioned vs monolithic TTBCPSI (two spans, one piled pier)', _v18),
    Case('V20', 'pile acceleration PSD peak in the Eq. 19 band, 250-400 km/h (four passages)',
         _v20),
)
