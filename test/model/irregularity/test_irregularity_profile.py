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

"""Tests of the sampling of a rail irregularity profile (quintic Hermite, derivatives)."""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity import profile
from ttb_sim.model.irregularity.synthesis import synthesize


@pytest.fixture(scope='module')
def chinese_profile() -> profile.TrackIrregularity:
    """Chinese HSR 2-200 m, 400 m at 0.02 m (100 points per shortest wavelength)."""
    return synthesize('chinese_hsr', length=400.0, dx=0.02, seed=21, x_start=-50.0)


def test_sample_reproduces_grid_values(chinese_profile):
    """Sampling at grid points returns the stored values and derivatives (1e-12 rel)."""
    prof = chinese_profile
    got = prof.sample(prof.x[::97])
    for arr, ref in ((got.value, prof.values), (got.slope, prof.slopes),
                     (got.curvature, prof.curvatures)):
        np.testing.assert_allclose(arr, ref[:, ::97], rtol=1e-12,
                                   atol=1e-12 * np.max(np.abs(ref)))
    assert got.rail('y_right')[0] is not None
    np.testing.assert_array_equal(got.rail('z_right')[1], got.slope[1])


def test_spectral_derivatives_match_finite_differences_of_the_grid(chinese_profile):
    """
    Slopes and curvatures at the nodes are the derivatives of the node values.

    Reference: central differences of the grid values (and of the slopes).
    Tolerance: 0.2 % of the peak (central-difference error at the shortest
    wavelength, 2 m at dx = 0.02 m, is 0.066 %).
    """
    prof = chinese_profile
    fd1 = (prof.values[:, 2:] - prof.values[:, :-2]) / (2 * prof.dx)
    fd2 = (prof.slopes[:, 2:] - prof.slopes[:, :-2]) / (2 * prof.dx)
    for fd, ref in ((fd1, prof.slopes[:, 1:-1]), (fd2, prof.curvatures[:, 1:-1])):
        peak = np.max(np.abs(ref), axis=1, keepdims=True)
        assert np.all(np.abs(fd - ref) <= 2e-3 * peak)


def test_sampled_derivatives_are_derivatives_of_sampled_value(chinese_profile):
    """
    Derivatives returned by ``sample`` equal finite differences of ``sample``.

    Between grid points (random positions), central difference with h = 1e-4 m.
    Tolerance: 1e-5 of the peak value of each derivative.
    """
    prof = chinese_profile
    x = np.random.default_rng(0).uniform(prof.x_start + 1.0, prof.x_end - 1.0, size=(5, 40))
    h = 1e-4
    mid, plus, minus = prof.sample(x), prof.sample(x + h), prof.sample(x - h)
    assert mid.value.shape == (4, 5, 40)
    fd1 = (plus.value - minus.value) / (2 * h)
    fd2 = (plus.slope - minus.slope) / (2 * h)
    for fd, ref in ((fd1, mid.slope), (fd2, mid.curvature)):
        peak = np.max(np.abs(ref), axis=(1, 2), keepdims=True)
        assert np.all(np.abs(fd - ref) <= 1e-5 * peak)


def test_quintic_hermite_interpolation_is_accurate():
    """
    Sampling between nodes reproduces a known smooth profile and its derivatives.

    Profile: sum of sines of wavelength 2-200 m stored with exact derivatives
    at dx = 0.25 m (8 points per shortest wavelength); ``sample`` at random
    positions vs the analytic values.  Tolerance (of each peak): 1e-6 value,
    1e-4 slope, 1e-3 curvature; measured 6.5e-8, 4.5e-6, 8.8e-5.
    """
    waves = np.array([200.0, 37.0, 9.0, 3.3, 2.0])
    k = 2 * np.pi / waves
    amp = np.array([1.0, 0.5, 0.2, 0.05, 0.02])[:, np.newaxis] * 1e-3
    phase = np.arange(5)[:, np.newaxis] * 0.7

    def series(x):
        arg = k[:, np.newaxis] * x + phase
        return (np.sum(amp * np.sin(arg), axis=0),
                np.sum(amp * k[:, np.newaxis] * np.cos(arg), axis=0),
                np.sum(-amp * k[:, np.newaxis] ** 2 * np.sin(arg), axis=0))

    grid = 0.25 * np.arange(1601)
    node = [np.tile(arr, (4, 1)) * np.array([[1.0], [-1.0], [2.0], [0.5]])
            for arr in series(grid)]
    prof = profile.TrackIrregularity(0.0, 0.25, *node)
    x = np.random.default_rng(3).uniform(0.0, 400.0, 500)
    got = prof.sample(x)
    for arr, ref, tol in zip((got.value, got.slope, got.curvature), series(x),
                             (1e-6, 1e-4, 1e-3)):
        assert np.max(np.abs(arr[0] - ref)) <= tol * np.max(np.abs(ref))
        np.testing.assert_allclose(arr[1], -arr[0], rtol=1e-12)


def test_outside_range_raises_or_gives_zeros(chinese_profile):
    """Outside [x_start, x_end]: ModelError by default, zeros with outside='zero'."""
    prof = chinese_profile
    with pytest.raises(ModelError, match=r'covers x = -50 to 350 m; position x = 351'):
        prof.sample([0.0, 351.0])
    with pytest.raises(ModelError, match='outside'):
        prof.sample(-50.5)
    with pytest.raises(ModelError, match='outside'):
        prof.sample(np.nan)
    edge = prof.sample([prof.x_start, prof.x_end])
    np.testing.assert_allclose(edge.value, prof.values[:, [0, -1]], rtol=1e-12)
    got = prof.sample(np.array([-60.0, 10.0, 400.0]), outside='zero')
    ref = prof.sample(10.0)
    for arr, value in ((got.value, ref.value), (got.slope, ref.slope),
                       (got.curvature, ref.curvature)):
        np.testing.assert_array_equal(arr[:, [0, 2]], 0.0)
        np.testing.assert_allclose(arr[:, 1], value, rtol=1e-12)


def test_irregularity_is_immutable(chinese_profile):
    """Arrays of a TrackIrregularity are read-only."""
    with pytest.raises(ValueError):
        chinese_profile.values[0, 0] = 1.0
    with pytest.raises(AttributeError):
        chinese_profile.dx = 1.0
