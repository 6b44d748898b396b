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

"""V17, V18 and V20 through the functions of ``ttb-sim validate``, on a cheaper configuration."""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from ttb_sim.config import load_scenario
from ttb_sim.validation.cases.coupled import (_v17, _v18, _v20, axle_group_band, axle_loads,
                                              central_pile, dominant_row, FAST,
                                              harmonic_window, PileRecord,
                                              quasi_static_pier_load, rise_row)
from ttb_sim.validation.cases.pile_spectrum import (coupled_bridge, moving_load_spectrum,
                                                    pile_functional, pile_response)
from ttb_sim.validation.references.moving_load import (passage_times, pier_load_history,
                                                       pier_load_spectrum, triangle_spectrum)


def test_v17_multi_time_step_matches_single_step():
    rows = _v17(FAST)
    assert len(rows) == 2 and all(r.passed for r in rows), rows
    # the bearings carry the train: the comparison is not of zeros
    assert all(np.isfinite(r.computed) for r in rows)


def test_v18_partitioned_matches_monolithic():
    rows = _v18(FAST)
    assert len(rows) == 2 and all(r.passed for r in rows), rows


def test_eq19_band_lies_between_the_first_two_car_lines():
    scenario = load_scenario('paper_ttbcpsi', FAST)
    lo, hi = axle_group_band(scenario)
    assert (lo, hi) == pytest.approx((83.333 / 18.2, 83.333 / 15.7), rel=1e-4)
    window = harmonic_window(scenario, 4.0)
    assert window[0] < lo < hi < window[1]


def test_pier_load_spectrum_matches_the_fft_of_the_sampled_reaction():
    """
    The closed form R(f) against the FFT of the sampled quasi-static reaction.

    Sampling the piecewise-linear reaction at 2 kHz aliases it by about (f / fs)^2: below
    20 Hz the two agree to 1e-3 of the largest |R|.
    """
    scenario = load_scenario('paper_ttbcpsi', FAST)
    speed, span = scenario.train.speed, scenario.bridge.span_length
    loads = axle_loads(scenario)
    times = passage_times(scenario.axle_positions(), 0.0, 2 * span, speed)
    rate, n = 2000.0, 2 ** 15
    t = np.arange(n) / rate
    r = pier_load_history(t, loads, times, span, speed)
    assert r[0] == 0.0 and r[-1] == 0.0 and r.max() > 4 * loads[0]
    f = np.fft.rfftfreq(n, 1.0 / rate)
    numeric = np.fft.rfft(r) / rate
    closed = pier_load_spectrum(f, loads, times, span, speed)
    low = f < 20.0
    assert np.abs(numeric[low] - closed[low]).max() < 1e-3 * np.abs(closed).max()
    # the influence line's zeros at n V / L, its area at 0 Hz
    assert triangle_spectrum([0.0], span, speed)[0] == pytest.approx(span / speed)
    assert np.abs(triangle_spectrum(np.arange(1, 5) * speed / span, span, speed)).max() < 1e-15


@pytest.fixture(scope='module')
def fast_bridge():
    """Build the FAST configuration's coupled bridge (piled pier monolithic)."""
    return load_scenario('paper_ttbcpsi', FAST), coupled_bridge('paper_ttbcpsi', FAST)


def test_pier_frf_tends_to_the_static_flexibility(fast_bridge):
    """
    H(f) / -(2 pi f)^2 at 0.1 mHz is the pile head's static flexibility to a pier-top force.

    Not at 0.05 Hz: the viscous-spring boundary's dashpots (c / k = 2 R / V_s, about 0.5 s
    on this soft soil) still put a 14 % imaginary part there, 3e-4 at 0.1 mHz.
    """
    scenario, structure = fast_bridge
    pile = central_pile(scenario)
    f = 1e-4
    response = pile_response(structure, np.array([f]), pile)
    pier = structure.piled[0]
    force = np.zeros(structure.n_free)
    force[structure.pier_top_dofs[structure.pier_supports.index(pier.support), 2]] = 1.0
    static = pile_functional(structure, pile) @ spla.spsolve(structure.stiffness.tocsc(), force)
    assert static > 0
    assert response.pier_top[0] / -(2 * np.pi * f) ** 2 == pytest.approx(static, rel=1e-3)


def test_moving_load_route_tends_to_h_times_the_closed_form_load(fast_bridge):
    """
    Below the girders' first mode (5.6 Hz) the girders pass their load on quasi-statically.

    The moving-load route (unit forces along the girders, same solve) then equals the coupled
    pier FRF times the closed-form R(f), amplitude and phase: 1 % up to 0.5 Hz.
    """
    scenario, structure = fast_bridge
    f = np.array([0.05, 0.2, 0.5])
    response = pile_response(structure, f, central_pile(scenario))
    product = response.pier_top * quasi_static_pier_load(scenario, f)
    route = moving_load_spectrum(response, scenario.train.speed, axle_loads(scenario),
                                 scenario.train.start_position,
                                 np.asarray(scenario.axle_positions()))
    assert np.abs(route / product - 1.0).max() < 0.01


def test_rise_row_passes_only_a_strict_rise():
    assert rise_row('rises', [1.0, 2.0, 2.5, 4.0]).passed
    dip = rise_row('rises', [1.0, 2.0, 1.5, 4.0])
    assert not dip.passed and dip.computed == pytest.approx(0.75)
    assert not rise_row('rises', [1.0, 1.0, 2.0, 3.0]).passed


@pytest.mark.parametrize('frequency, passed', [(6.3, True), (4.0, True), (2.0, False),
                                               (12.5, False)])
def test_dominant_row_reads_the_loudest_low_frequency_band(frequency, passed):
    """A sine (plus a weaker 31.5 Hz one, outside 'low frequency') gives its own band."""
    rate = 1000.0
    t = np.arange(8000) / rate
    signal = np.sin(2 * np.pi * frequency * t) + 3.0 * np.sin(2 * np.pi * 31.5 * t)
    record = PileRecord(load_scenario('paper_ttbcpsi', FAST), signal, rate)
    row = dominant_row(record)
    assert row.computed == pytest.approx(frequency, rel=0.03)
    assert row.passed is passed


@pytest.fixture(scope='module')
def fast_rows():
    """V20's rows on FAST at the four speeds of the case."""
    return _v20(FAST)


def test_v20_rows_run_end_to_end_on_fast(fast_rows):
    """
    Every row is there and finite; the moving-load route explains the run.

    With moving forces and no track the route through the girders is the model's own linear
    response: it meets the run's energy between the car lines within 2 dB (the record stops
    one fundamental period after the last axle leaves, so the run misses the rest of the
    ring-down: -0.5 to -1.5 dB). The quasi-static product H R does not (8-17 dB under: the
    static reaction leaves out the girders' mode at 5.6 Hz): an information row.
    """
    kinds = [r.error_kind for r in fast_rows]
    assert len(fast_rows) == 26 and kinds.count('report') == 16
    assert all(np.isfinite(r.computed) for r in fast_rows if r.error_kind != 'smallest ratio')
    route = [r for r in fast_rows if 'vs moving load' in r.quantity]
    assert len(route) == 4 and all(r.passed and r.error < 2.0 for r in route), route
    quasi = [r for r in fast_rows if 'quasi-static H R' in r.quantity]
    assert len(quasi) == 4 and all(r.error_kind == 'report' and r.computed > 3.0
                                   for r in quasi), quasi
    judged = [r for r in fast_rows if r.error_kind != 'report']
    assert {r.quantity.split(',')[0] for r in judged} >= {
        'dominant 1/3-oct. band', 'car-line window energy vs moving load'}
