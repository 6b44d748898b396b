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
The compiled quarter-car step against its numpy path.

The kernels are :mod:`ttb_sim.sim.coupling.quarter_car.wheel_kernels`.

The node's default scenario ``live_train`` (16 quarter cars on irregular track,
ten spans on bearings) is stepped through the numpy path and the kernels from
the same start: every frame field agrees to 1e-9 of its largest value (the two
order the same sums differently; measured about 1e-12). The wheels start
behind the bridge, so wheels off and on the girder are both exercised.
"""

from dataclasses import replace
import itertools

import numpy as np
import pytest
from ttb_sim.config import load_scenario
from ttb_sim.sim import kernel_registry as kernels
from ttb_sim.sim.coupling.quarter_car import wheel_kernels
from ttb_sim.sim.coupling.quarter_car.wheels import QuarterCarTrain
from ttb_sim.sim.runner import make_runner

pytest.importorskip('numba')

STEPS = 250
"""0.5 s at dt = 2 ms: the head reaches 42 m, the last wheel is still behind the bridge."""
FIELDS = ('midspan', 'bearings', 'wheel_rail', 'body_acceleration')


def _frames(scenario, compiled):
    """Step ``scenario`` with the compiled kernels on or off; return frames and the coupling."""
    kernels.ENABLED = compiled
    try:
        sim = make_runner(scenario)
        frames = list(itertools.islice(sim.frames(), STEPS + 1))
    finally:
        kernels.ENABLED = True
    return frames, sim.coupling


def test_compiled_step_equals_numpy_path():
    """Every frame field of the kernels equals the numpy path's to 1e-9 of its largest value."""
    scenario = load_scenario('live_train')
    reference, numpy_coupling = _frames(scenario, False)
    compiled, kernel_coupling = _frames(scenario, True)
    assert isinstance(kernel_coupling, QuarterCarTrain)
    assert not numpy_coupling.kernel.compiled
    assert kernel_coupling.kernel.compiled
    for name in FIELDS:
        a = np.array([getattr(f, name) for f in reference])
        b = np.array([getattr(f, name) for f in compiled])
        scale = np.max(np.abs(a))
        assert scale > 0, name
        assert np.max(np.abs(a - b)) <= 1e-9 * scale, name
    # The contact forces are the static axle load plus the dynamic part: not trivial.
    wheel = np.array([f.wheel_rail[:, 0, :, 2].sum(axis=1) for f in compiled])
    assert np.ptp(wheel) > 1e3   # N


def test_reference_variant_keeps_the_numpy_path():
    """solver.variant = reference never takes the kernels (its bags stay bit-identical)."""
    scenario = load_scenario('live_train')
    scenario = replace(scenario, solver=replace(scenario.solver, variant='reference'))
    sim = make_runner(scenario)
    assert not sim.coupling.kernel.compiled


def test_centreline_profile_equals_sample():
    """The compiled irregularity equals TrackIrregularity.sample (rail mean), zero outside."""
    sim = make_runner(load_scenario('live_train'))
    irr = sim.coupling.irregularity
    assert irr is not None
    x = np.concatenate([np.linspace(irr.x_start - 3.0, irr.x_end + 3.0, 997),
                        [irr.x_start, irr.x_end]])
    kernel = wheel_kernels.KERNELS.compiled('centreline_profile')
    assert kernel is not None
    out = (np.zeros(x.size), np.zeros(x.size), np.zeros(x.size))
    kernel(x, irr.x_start, irr.dx, irr.values, irr.slopes, irr.curvatures, 1e-9, *out)
    s = irr.sample(x, outside='zero')
    for got, value in zip(out, (s.value, s.slope, s.curvature)):
        want = 0.5 * (value[0] + value[1])
        assert np.max(np.abs(want)) > 0
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))
    outside = (x < irr.x_start) | (x > irr.x_end)
    assert outside.any() and not np.any(out[0][outside])
