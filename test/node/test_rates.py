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

"""Tests of the per-family publishing rates: families, periods, the schedule, the controller."""

from __future__ import annotations

import pytest
from ttb_sim.errors import ScenarioError
from ttb_sim.node.parameters import initial_values, parameter_table
from ttb_sim.node.passage import PassageController
from ttb_sim.node.rates import (check_rate, FAMILIES, family_of, family_periods, frame_stride,
                                RATE_PARAMETERS, Schedule)


def test_family_is_the_first_part_of_the_topic_name():
    assert family_of('piles/pier07/pile01/imu') == 'piles'
    assert family_of('train/car01/body/imu') == 'train'
    assert family_of('wheel_rail/car01/axle1/left') == 'wheel_rail'
    assert family_of('/clock') == ''
    assert set(RATE_PARAMETERS.values()) == set(FAMILIES)
    assert 'publish_rates.soil_hz' in RATE_PARAMETERS


def test_periods_default_to_publish_rate_and_round_overrides_to_whole_frames():
    values = {'publish_rate_hz': 50.0, 'publish_rates.piles_hz': 1000.0,
              'publish_rates.soil_hz': 3.0}
    periods = family_periods(values, 0.001, ('train', 'piles', 'soil'))
    assert periods['train'] == pytest.approx(0.02)          # publish_rate_hz
    assert periods['piles'] == pytest.approx(0.001)         # one frame
    assert periods['soil'] == pytest.approx(0.333)          # 333 frames, the nearest
    assert family_periods({'publish_rate_hz': 0.0}, 0.001, ('bridge',)) == {'bridge': 0.0}


def test_a_rate_above_the_output_rate_is_refused_with_the_limit():
    assert check_rate('publish_rates.piles_hz', 1000.0, 0.001) == (True, '')
    assert check_rate('publish_rates.piles_hz', 0.0, 0.001) == (True, '')
    ok, reason = check_rate('publish_rates.piles_hz', 2000.0, 0.001)
    assert not ok
    assert 'publish_rates.piles_hz = 2000 Hz' in reason and 'output rate' in reason
    assert '[0, 1000] Hz' in reason


def test_stride_is_the_common_divisor_of_the_periods_in_frames():
    assert frame_stride({'a': 0.02, 'b': 0.1}, 0.001) == 20
    assert frame_stride({'a': 0.02, 'b': 0.03}, 0.001) == 10
    assert frame_stride({'a': 0.0, 'b': 0.1}, 0.001) == 1      # every frame
    assert frame_stride({'a': 0.0105, 'b': 0.1}, 0.001) == 1   # not whole frames
    assert frame_stride({}, 0.001) == 1


def test_schedule_decimates_each_family_at_its_own_period():
    schedule = Schedule(('piles', 'soil'), start=0.0)
    periods = {'piles': 0.001, 'soil': 0.005}
    due = [schedule.due(k * 0.001, periods) for k in range(11)]
    assert all('piles' in d for d in due)
    assert [k for k, d in enumerate(due) if 'soil' in d] == [0, 5, 10]
    schedule.restart(0.011, 'soil')
    assert schedule.due(0.011, periods) == {'piles', 'soil'}


def test_schedule_catches_up_after_a_raised_rate_without_a_burst():
    schedule = Schedule(('bridge',), start=0.0)
    assert schedule.due(0.0, {'bridge': 1.0}) == {'bridge'}
    # next due at 1.0; a faster rate from t = 0.5 on does not owe the frames in between
    assert schedule.due(0.5, {'bridge': 0.1}) == frozenset()
    assert schedule.due(1.0, {'bridge': 0.1}) == {'bridge'}
    assert schedule.due(1.05, {'bridge': 0.1}) == frozenset()
    assert schedule.due(1.1, {'bridge': 0.1}) == {'bridge'}


def _controller(beam, **values) -> PassageController:
    given = {'real_time_factor': 0.0, 'loop': False}
    given.update(values)
    return PassageController(beam, initial_values(parameter_table(beam), given))


def test_controller_publishes_each_family_at_its_own_rate(beam):
    c = _controller(beam, publish_rate_hz=0.0)
    period = c.output_period
    assert set(c.families) == {'train', 'bridge', 'bearings'}
    c = _controller(beam, publish_rate_hz=1.0 / (10 * period),
                    **{'publish_rates.bridge_hz': 1.0 / (2 * period)})
    due: list[frozenset[str]] = []
    times = []
    for _ in range(3):
        tick = c.advance(budget=5.0, max_frames=40)
        due += tick.due
        times += [f.time for f in tick.frames]
        assert len(tick.due) == len(tick.frames)
    bridge = [t for t, d in zip(times, due) if 'bridge' in d]
    bearings = [t for t, d in zip(times, due) if 'bearings' in d]
    assert len(bridge) > len(bearings) >= 2
    assert [b - a for a, b in zip(bridge, bridge[1:])] == pytest.approx(
        [2 * period] * (len(bridge) - 1))
    assert [b - a for a, b in zip(bearings, bearings[1:])] == pytest.approx(
        [10 * period] * (len(bearings) - 1))
    # without a bag only every second output frame is computed (the common divisor)
    assert c.frame_period == pytest.approx(2 * period)


def test_controller_refuses_a_family_rate_above_the_output_rate(beam):
    rate = 1.0 / _controller(beam).output_period
    c = _controller(beam)
    ok, reason = c.check_rates({'publish_rates.bridge_hz': 2 * rate})
    assert not ok and 'output rate' in reason
    assert c.check_rates({'publish_rates.bridge_hz': rate}) == (True, '')
    with pytest.raises(ScenarioError, match='publish_rates.bearings_hz'):
        _controller(beam, **{'publish_rates.bearings_hz': 2 * rate})
