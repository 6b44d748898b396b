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
The reduced pier-cap-pile-soil operator against the unreduced finite-element model.

One coarse piled pier (two piles, a cap, two soil layers, about 3 000 DOFs)
keeps every check to seconds. References: the unreduced linear model in the
same coordinates (complex sparse LU for the frequency response, sparse Newmark
in time), the cantilever formulas for the pier column, the Desai law for the
interface rows.
"""

import dataclasses
import logging
import math

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ttb_sim.fe.beam import BeamSection
from ttb_sim.model.foundation import reduction as red
from ttb_sim.model.foundation.krylov import reduction_basis
from ttb_sim.model.foundation.operator_cache import cache_key
from ttb_sim.model.foundation.records import (BlockSize, Cap, FoundationError, MeshSize,
                                              Observation, PileGroup, ReductionParameters,
                                              SoilLayer, SoilParameters, Substructure)
from ttb_sim.model.foundation.substructure import build
from ttb_sim.model.foundation.tied import tie_cap

LAYERS = (SoilLayer(2.0, 4e6, 0.35, 1835.0, 20e3, 5.0),
          SoilLayer(8.0, 6e6, 0.25, 1529.0, 10e3, 30.0))
HEIGHT, ELEMENTS = 8.0, 3
EA, GJ, EI, MU = 2.6e11, 2.2e11, 2.6e11, 2e4
SECTION = BeamSection(*(np.full(ELEMENTS, v) for v in (EA, GJ, EI, EI, MU, MU)))
RAYLEIGH = (0.1, 1e-3)
SMALL = ReductionParameters(shifts=(0.0, 10.0, 20.0, 30.0), levels=4)
LARGE = ReductionParameters(shifts=(0.0, 10.0, 20.0, 30.0), levels=8)


def _spec(**changes):
    spec = Substructure(
        soil=SoilParameters(LAYERS, BlockSize(10.0, 8.0), MeshSize(h=1.0, growth=1.5,
                                                                   h_max=3.0)),
        piles=PileGroup(rows=1, cols=2, spacing=3.0, side=0.8, length=4.0),
        cap=Cap(enabled=True, lx=5.0, ly=2.0, thickness=1.0),
        observation=Observation(line_points=3, val_points=False))
    return dataclasses.replace(spec, **changes)


def _operator(reduction=LARGE, spec=None, **kw):
    return red.pile_soil_operator(spec or _spec(), HEIGHT, ELEMENTS, SECTION, RAYLEIGH,
                                  reduction, **kw)


@pytest.fixture(scope='module')
def full():
    return red.unreduced_operator(_spec(), HEIGHT, ELEMENTS, SECTION, RAYLEIGH)


@pytest.fixture(scope='module')
def large():
    return _operator(LARGE, cache=False)


def test_refuses_no_cap_no_piles_and_a_floating_block():
    with pytest.raises(FoundationError, match='cap.enabled'):
        _operator(spec=_spec(cap=Cap(enabled=False)), cache=False)
    with pytest.raises(FoundationError, match='piles = none'):
        _operator(spec=_spec(piles=None), cache=False)
    soil = dataclasses.replace(_spec().soil, boundary='lysmer')
    with pytest.raises(FoundationError, match="soil.boundary = 'lysmer'"):
        _operator(spec=_spec(soil=soil), cache=False)
    with pytest.raises(FoundationError, match='soil.reduction.shifts'):
        ReductionParameters(shifts=(0.0, 0.0))
    with pytest.raises(FoundationError, match='soil.reduction.levels'):
        ReductionParameters(levels=0)


def test_reduced_matrices_symmetric_and_definite(large):
    """M, K symmetric positive definite, C symmetric positive semi-definite (to 1e-12)."""
    for a in (large.mass, large.damping, large.stiffness):
        assert np.array_equal(a, a.T)
    assert np.linalg.eigvalsh(large.mass).min() > 0
    assert np.linalg.eigvalsh(large.stiffness).min() > 0
    c = np.linalg.eigvalsh(large.damping)
    assert c.min() > -1e-12 * c.max()
    assert large.size == large.summary['dofs'] < large.summary['full_dofs'] / 10


def test_static_flexibility_and_pile_heads_equal_the_unreduced_model(full, large):
    """The static modes are in the basis: pier-top and pile-head statics to 1e-9."""
    rhs = np.zeros((full.mass.shape[0], 6))
    rhs[:6] = np.eye(6)
    u_full = spla.splu(sp.csc_matrix(full.stiffness)).solve(rhs)
    u_red = np.linalg.solve(large.stiffness, np.eye(large.size)[:, :6])
    flex_full, flex_red = u_full[:6], u_red[:6]
    scale = np.sqrt(np.outer(np.diag(flex_full), np.diag(flex_full)))
    assert np.abs(flex_red - flex_full).max() / scale.max() < 1e-9
    heads_full, heads_red = full.pile_heads @ u_full, large.pile_heads @ u_red
    assert np.abs(heads_red - heads_full).max() < 1e-9 * np.abs(heads_full).max()


def test_pile_strain_recovered_through_the_basis_equals_the_unreduced_model(full, large):
    """Interior pile DOFs through Psi and V: the layers' axial strain to 1e-9, compressed."""
    rhs = np.zeros(full.mass.shape[0])
    rhs[2] = -1e6                      # 1 MN down on the pier top
    u_full = spla.splu(sp.csc_matrix(full.stiffness)).solve(rhs)
    u_red = np.linalg.solve(large.stiffness, rhs[:large.size])
    strain_full, strain_red = full.pile_strain @ u_full, large.pile_strain @ u_red
    assert large.pile_strain.shape == (2 * (len(large.pile_layer_depths) - 1), large.size)
    assert large.pile_layer_depths[0] == 0.0 and large.pile_layer_depths[-1] == 4.0
    assert np.abs(strain_red - strain_full).max() < 1e-9 * np.abs(strain_full).max()
    assert np.all(strain_red < 0.0)


def test_pier_column_stands_on_the_cap_top(full):
    """Pier-top flexibility = cap-top flexibility carried up the lever + cantilever (1e-9)."""
    n = full.mass.shape[0]
    lead = 6 * ELEMENTS
    rhs = np.zeros((n, 6))
    rhs[:6] = np.eye(6)
    flex_top = spla.splu(sp.csc_matrix(full.stiffness)).solve(rhs)[:6]
    rhs = np.zeros((n, 6))
    rhs[lead:lead + 6] = np.eye(6)
    flex_cap = spla.splu(sp.csc_matrix(full.stiffness)).solve(rhs)[lead:lead + 6]
    # a load at the top is, at the cap top, the same force and the moment r x F, r = (0, 0, H)
    lever = np.eye(6)
    lever[3, 1], lever[4, 0] = -HEIGHT, HEIGHT
    cantilever = np.zeros((6, 6))
    cantilever[0, 0] = cantilever[1, 1] = HEIGHT**3 / (3 * EI)
    cantilever[2, 2], cantilever[5, 5] = HEIGHT / EA, HEIGHT / GJ
    cantilever[3, 3] = cantilever[4, 4] = HEIGHT / EI
    cantilever[0, 4] = cantilever[4, 0] = HEIGHT**2 / (2 * EI)
    cantilever[1, 3] = cantilever[3, 1] = -HEIGHT**2 / (2 * EI)
    expected = lever.T @ flex_cap @ lever + cantilever
    assert np.allclose(flex_top, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def _frf_error(op, reference, frequencies):
    h = red.dynamic_flexibility(op.mass, op.damping, op.stiffness, frequencies)
    static = red.dynamic_flexibility(op.mass, op.damping, op.stiffness, np.zeros(1))[0]
    s = 1 / np.sqrt(np.abs(np.diag(static.real)))
    return np.array([np.linalg.norm(s[:, None] * (a - b) * s)
                     / np.linalg.norm(s[:, None] * b * s) for a, b in zip(h, reference)])


def test_pier_top_dynamic_flexibility_converges_with_the_basis(full, large):
    """
    6 x 6 pier-top H(f) against the unreduced model (complex sparse LU), 0-30 Hz.

    Error: Frobenius norm of the difference over that of H, both scaled by the
    static diagonal (so translations and rotations weigh alike; 0 Hz is the
    static test above). Measured with levels 4 (114 coordinates) / 8 (178): 1.0e-4 /
    7e-9 at 2 Hz, 3.9e-2 / 2.6e-3 at 5 Hz, 0.19 / 0.056 at 10 Hz, 0.15 / 0.028 at
    30 Hz (this mesh resolves 1.4 Hz in its coarsest cells: a dense set of mesh
    resonances the real shifts approach slowly).
    """
    frequencies = np.array([2.0, 5.0, 10.0, 30.0])
    reference = red.dynamic_flexibility(full.mass, full.damping, full.stiffness, frequencies)
    small = _operator(SMALL, cache=False)
    err_small = _frf_error(small, reference, frequencies)
    err_large = _frf_error(large, reference, frequencies)
    assert small.size < large.size
    assert err_large[0] < 1e-6 and err_large[1] < 1e-2 and err_large[2:].max() < 0.1
    assert np.all(err_large < 0.5 * err_small)


def _newmark(mass, damping, stiffness, load, dt):
    """Average-acceleration Newmark from rest; dense or sparse matrices; returns u (n_t, n)."""
    b, g = 0.25, 0.5
    keff = stiffness + (g / (b * dt)) * damping + mass / (b * dt * dt)
    if sp.issparse(keff):
        solve = spla.splu(sp.csc_matrix(keff)).solve
    else:
        inv = np.linalg.inv(keff)

        def solve(r):
            return inv @ r
    n = mass.shape[0]
    u, v, a = np.zeros(n), np.zeros(n), np.zeros(n)
    out = []
    for f in load:
        rhs = (f + mass @ (u / (b * dt * dt) + v / (b * dt) + (0.5 / b - 1) * a)
               + damping @ (g / (b * dt) * u + (g / b - 1) * v + dt * (0.5 * g / b - 1) * a))
        un = solve(rhs)
        an = (un - u) / (b * dt * dt) - v / (b * dt) - (0.5 / b - 1) * a
        v = v + dt * ((1 - g) * a + g * an)
        u, a = un, an
        out.append(u)
    return np.array(out)


def test_pile_heads_under_a_pier_top_pulse_match_the_unreduced_newmark(full, large):
    """A 0.1 s half-sine (1 MN along x and z) at the pier top, 0.3 s: pile heads within 1 %."""
    dt, steps = 1e-3, 300
    t = dt * np.arange(1, steps + 1)
    pulse = np.where(t < 0.1, np.sin(math.pi * t / 0.1), 0.0) * 1e6
    direction = np.zeros(6)
    direction[[0, 2]] = 1.0

    def run(mass, damping, stiffness, heads):
        load = np.zeros((steps, mass.shape[0]))
        load[:, :6] = pulse[:, None] * direction
        return _newmark(mass, damping, stiffness, load, dt) @ heads.T

    ref = run(full.mass, full.damping, full.stiffness, full.pile_heads)
    got = run(large.mass, large.damping, large.stiffness, large.pile_heads)
    error = np.sqrt(((got - ref)**2).mean(axis=0)) / np.sqrt((ref**2).mean(axis=0)).max()
    assert error.max() < 1e-2


def test_interface_rows_follow_the_desai_law(large):
    """Rows = the Desai law's stress at small strain (1e-6); mobilisation scales with q."""
    tied = tie_cap(build(_spec()))
    psi, v = reduction_basis(tied, LARGE)
    phi = np.hstack([psi, np.vstack([np.zeros((6, v.shape[1])), v])])
    rng = np.random.default_rng(3)
    q = np.zeros(large.size)
    q[6 * ELEMENTS:] = rng.normal(size=phi.shape[1]) * 1e-9
    u = tied.transform @ (phi @ q[6 * ELEMENTS:])
    law, iface = tied.model.law, tied.model.interface
    stress, _, _ = law.evaluate(iface.strain(u), np.zeros((iface.n_elements, 4, 2)))
    rows = large.interface
    got_n = (rows.normal @ q).reshape(-1, 4)
    got_s = (rows.shear @ q).reshape(-1, 4, 2)
    scale = np.abs(stress).max()
    assert np.abs(got_n - stress[..., 0]).max() < 1e-6 * scale
    assert np.abs(got_s - stress[..., 1:]).max() < 1e-6 * scale
    small = red.interface_mobilisation(large, q)
    assert 0 < small < 1e-3
    assert red.interface_mobilisation(large, np.vstack([q, 10 * q])) == pytest.approx(
        10 * small, rel=1e-3)
    with pytest.raises(ValueError, match='coordinates'):
        red.interface_mobilisation(large, q[:-1])


def test_cache_gives_the_same_bits_and_survives_corruption(tmp_path, monkeypatch, caplog, large):
    monkeypatch.setenv('TTB_SIM_CACHE', str(tmp_path / 'cache'))
    caplog.set_level(logging.INFO, logger='ttb_sim.model.foundation')
    first = _operator()
    files = list((tmp_path / 'cache').glob('pile_soil_*.npz'))
    assert len(files) == 1 and 'cached in' in caplog.text
    caplog.clear()
    second = _operator()
    assert 'read from the cache' in caplog.text
    for op in (first, second):
        for name in ('mass', 'damping', 'stiffness', 'pile_heads', 'soil_points'):
            assert np.array_equal(getattr(op, name), getattr(large, name))
        assert np.array_equal(op.interface.shear, large.interface.shear)
        assert op.soil_point_names == large.soil_point_names and op.summary == large.summary
    assert cache_key(_spec(), HEIGHT, ELEMENTS, SECTION, RAYLEIGH, LARGE) != \
        cache_key(_spec(), HEIGHT, ELEMENTS, SECTION, (0.1, 2e-3), LARGE)
    files[0].write_bytes(b'not an npz file')
    caplog.clear()
    third = _operator()
    assert 'unreadable' in caplog.text and np.array_equal(third.stiffness, large.stiffness)
    blocked = tmp_path / 'a_file'
    blocked.write_text('x')
    monkeypatch.setenv('TTB_SIM_CACHE', str(blocked))
    caplog.clear()
    fourth = _operator()
    assert 'could not write' in caplog.text and np.array_equal(fourth.mass, large.mass)


def test_imaginary_shift_interpolates_the_response_there(full):
    """A shift at i 2 pi 10 Hz puts the exact 10 Hz response in the basis: H(10 Hz) to 1e-8."""
    reduction = ReductionParameters(shifts=(0.0, 10.0), levels=1, shift_axis='imaginary')
    op = _operator(reduction, cache=False)
    frequency = np.array([10.0])
    reference = red.dynamic_flexibility(full.mass, full.damping, full.stiffness, frequency)
    assert op.summary['basis'] <= 12
    assert _frf_error(op, reference, frequency)[0] < 1e-8


def test_a_build_reports_each_shift_with_its_percentage(caplog):
    """Three shifts: three lines at 33, 67 and 100 %, the first two with the time left."""
    caplog.set_level(logging.INFO, logger='ttb_sim.model.foundation.reduction')
    shifts = ReductionParameters(shifts=(0.0, 5.0, 10.0), levels=2)
    _operator(shifts, cache=False)
    lines = [r.getMessage() for r in caplog.records if 'shifts done' in r.getMessage()]
    assert [line.split(' shifts done ')[1].split(')')[0] for line in lines] == [
        '(33 %', '(67 %', '(100 %']
    assert all('left' in line for line in lines[:2]) and 'left' not in lines[2]


def test_progress_is_a_warning_only_for_a_long_build():
    """The terminal shows a build of minutes; a build of seconds stays at INFO."""
    assert red.BuildProgress(5, red.build_seconds(81_648, 5)).level == logging.WARNING
    assert red.BuildProgress(2, red.build_seconds(18_144, 2)).level == logging.INFO
    paper, live = red.build_seconds(81_648, 5), red.build_seconds(18_144, 2)
    assert 60 < paper < 300 and 1 < live < 6   # measured by symmetry classes: 133 s, 2.0-2.9 s
    assert red.build_seconds(81_648, 5, pardiso=True) == pytest.approx(paper / 3.4)
