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

"""The reduced track-bridge (solver.variant reduced) against the full model it reduces."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse.linalg as sla

from ttb_sim.config import load_scenario
from ttb_sim.sim import build_structure, Simulation
from ttb_sim.sim.coupling.train_track import reduced_track
from ttb_sim.sim.coupling.train_track.equilibrium import rail_under_wheels
from ttb_sim.sim.coupling.train_track.reduced_track import (project, rail_cuts, rigid_track_basis,
                                                            slab_joints, static_track_basis,
                                                            track_free_dofs, track_window)

SMALL = [('train.vehicle', 'car'), ('track.model', 'slab'), ('train.n_cars', 1),
         ('bridge.n_spans', 3), ('bearings.model', 'elastic'), ('train.start_position', 40.0),
         ('train.speed_kmh', 300.0), ('solver.dt', 1e-4)]
"""One car on a three-span bridge on elastic bearings, head on the second span."""
SHORT_UNITS = [('track.fasteners_per_slab', 3)]
"""Slab units of 1.89 m: the window's ends move to slab joints, so with ADVANCE = 1 m
short units let it move every two metres or so."""


@pytest.fixture(scope='module')
def small():
    """Return the structure and a window over the second span."""
    structure = build_structure(load_scenario('moving_force_beam', values=SMALL))
    static = static_track_basis(structure, 'qdldl')
    window = track_window(structure, static, rigid_track_basis(structure), 30.0, 70.0)
    return structure, window


def test_basis_keeps_the_bridge_and_the_window_and_rests_the_rest_on_it(small):
    st, window = small
    t = window.basis.tocsr()
    assert 0 < window.size < st.n_free
    # The local basis moves every far track node with the girder below it: a rigid
    # vertical translation of the girders lifts the far track on the bridge alike
    # (the rail cuts over the slab joints are kept DOFs: they move as themselves).
    local = window.local_basis
    girder_z = st.full_to_free[st.girder_beam.dofs[:, [2, 8]]].ravel()
    lift = np.zeros(window.size)
    lift[np.searchsorted(window.kept, girder_z[girder_z < st.n_free])] = 1.0
    moved = local @ lift
    rail = st.track.rails[0]
    far_on_bridge = (((rail.start > 1.0) & (rail.start < window.start - 1.0))
                     | ((rail.start > window.end + 1.0) & (rail.start < st.girder_beam.end - 1.0)))
    assert np.count_nonzero(far_on_bridge) > 100
    rail_z = np.setdiff1d(st.full_to_free[rail.dofs[far_on_bridge, 2]],
                          rail_cuts(st, slab_joints(st)))
    np.testing.assert_allclose(moved[rail_z], 1.0, rtol=1e-12)
    # Kept DOFs are identity rows of T.
    kept_rows = t[window.kept]
    assert np.array_equal(kept_rows.indices, np.arange(window.size))
    np.testing.assert_array_equal(kept_rows.data, 1.0)
    # Every girder DOF is kept; the far track moves only with the bridge DOFs and the
    # rail cuts over the slab-unit joints, and each far node only with the girder
    # and cuts within a slab unit or so (the basis is local).
    girder = np.unique(st.full_to_free[st.girder_beam.dofs])
    assert np.all(window.full_to_reduced[st.girder_beam.dofs] < window.size)
    assert np.isin(girder[girder < st.n_free], window.kept).all()
    far = np.setdiff1d(np.arange(st.n_free), window.kept)
    track_free, x = track_free_dofs(st)
    in_window = track_free[(x >= window.start) & (x <= window.end)]
    cuts = rail_cuts(st, slab_joints(st))
    assert cuts.size > 0 and np.isin(cuts, window.kept).all()
    window_track = np.searchsorted(window.kept, np.setdiff1d(in_window[in_window < st.n_free],
                                                             cuts))
    assert far.size > 0
    assert not np.isin(t[far].indices, window_track).any()
    x_of = np.full(st.n_free, np.nan)
    x_of[track_free[track_free < st.n_free]] = np.repeat(x, 6)[(track_free < st.n_free).ravel()]
    pitch = st.track.slab.length.sum() / max(1, slab_joints(st).size)
    far_t = t[far].tocoo()
    master_x = x_of[window.kept[far_t.col]]
    on_track = ~np.isnan(master_x)
    reach = np.abs(master_x[on_track] - x_of[far[far_t.row[on_track]]])
    assert reach.max() <= 1.5 * pitch


def test_reduced_statics_equal_the_full_model(small):
    """Static girder loads: the far track is condensed statically, so deflections agree."""
    st, window = small
    t = window.basis
    mid = st.midspan_dofs[:, 2]
    force = np.zeros(st.n_free)
    force[mid] = [-1e5, -2e5, -3e5]
    full = sla.spsolve(st.stiffness.tocsc(), force)
    reduced = t @ sla.spsolve(project(st.stiffness, t).tocsc(), t.T @ force)
    np.testing.assert_allclose(reduced[mid], full[mid], rtol=1e-9)


def test_reduced_low_frequencies_equal_the_full_model(small):
    """
    Far track as static stiffness and rigidly carried mass: bridge modes within 0.5 %.

    Measured: at most 0.19 % over the lowest eight modes (3.6-7.5 Hz) here, where
    the far track is 60 % of the bridge's; 0.04 % over the lowest twelve of
    paper_ttbi. Riding rigidly in the stiffness too made a span 46 % stiffer
    (the track's plates locked the span joints).
    """
    st, window = small
    full = sla.eigsh(st.stiffness.tocsc(), k=8, M=st.mass.tocsc(), sigma=0.0,
                     return_eigenvectors=False)
    red = sla.eigsh(project(st.stiffness, window.basis).tocsc(), k=8,
                    M=project(st.mass, window.local_basis).tocsc(), sigma=0.0,
                    return_eigenvectors=False)
    f_full, f_red = (np.sort(np.sqrt(v)) / (2 * np.pi) for v in (full, red))
    assert f_full[0] > 1.0
    np.testing.assert_allclose(f_red, f_full, rtol=5e-3)


def test_reduced_run_with_moving_window_follows_the_full_model(monkeypatch):
    """
    A run whose window moves every two metres or so agrees with the full model.

    ADVANCE = 1 m and slab units of 1.89 m (the window's ends move out to slab
    joints) make the window move three times in 5 m of travel, so the state
    hand-over is exercised far more than in a real run (every 40-45 m).
    Measured over these 0.06 s (RMS of the difference over the reference's
    RMS): wheel-rail Fz 1.8e-5, Fy 8.1e-3 (1.2 kN RMS here; 8.1e-3 without
    moves), girder mid-span 2.9e-5. With 15 m margins instead of 30 (earlier
    basis, 0.06 s): Fz 6e-4, Fy 1.2e-2, mid-span 6e-4.
    """
    monkeypatch.setattr(reduced_track, 'ADVANCE', 1.0)

    def run(variant):
        scenario = load_scenario('moving_force_beam', values=SMALL + SHORT_UNITS + [
            ('solver.variant', variant), ('solver.duration', 0.06),
            ('solver.window_margin', 30.0),   # the default of its measurements; 100 m
            # would detail the whole of this short bridge
            ('irregularity.spectrum', 'paper'), ('irregularity.seed', 2)])
        sim = Simulation(scenario)
        frames = list(sim.frames())
        fz = np.array([f.wheel_rail[..., 2] for f in frames])
        fy = np.array([f.wheel_rail[..., 1] for f in frames])
        mid = np.array([f.midspan[:, 2] for f in frames])
        return sim, fz, fy, mid

    sim, *reduced = run('reduced')
    assert sim.coupling.window_moves >= 3
    assert sim.coupling.n_free < sim.structure.n_free
    _, *full = run('qdldl')

    def rms(x):
        return float(np.sqrt(np.mean(x**2)))

    for name, a, b, tol in zip(('Fz', 'Fy', 'mid'), reduced, full, (2e-4, 1.5e-2, 3e-4)):
        assert rms(a - b) <= tol * rms(b), name


def test_window_predicts_its_rail_motion_from_the_full_models_columns(monkeypatch):
    """
    The window's single-solve predictor: the full model's K^-1 columns, restricted.

    At frames after several window moves, the rail motion under the wheels that
    the restricted columns give for the window's Newmark history agrees with the
    window's own solve within contact.tolerance (1e-9 m); what is left, a slowly
    varying difference, the step's rail offsets carry from one step to the next,
    so its check passes on the one solve. The columns are the full model's: they
    differ from the window's by what the condensed far track changes (measured
    up to 1.1e-10 m, 1e-7 of the rail motion, on this small model whose far
    track lies close to the wheels).
    """
    pytest.importorskip('numba', reason='the single-solve step is taken compiled')
    monkeypatch.setattr(reduced_track, 'ADVANCE', 1.0)
    sim = Simulation(load_scenario('moving_force_beam', values=SMALL + SHORT_UNITS + [
        ('solver.variant', 'reduced'), ('solver.duration', 0.06),
        ('irregularity.spectrum', 'paper'), ('irregularity.seed', 2)]))
    tt = sim.coupling
    n = tt.n_cars
    solves, checked = [], 0
    for i, _ in enumerate(sim.frames()):
        solves.append(tt.solves)
        if i % 10 != 9:
            continue
        assert tt.compliance.influence
        head = sim.scenario.train.start_position + sim.speed * i * sim.output_every * sim.dt
        rows, slope, dofs, _, _ = rail_under_wheels(tt, head + tt.contact_x)
        element = np.searchsorted(tt.rails[0].start, head + tt.contact_x, side='right') - 1
        nm = tt.nm
        rhs = nm.effective_load(np.zeros(tt.n_free), *nm.history(tt.u, tt.v, tt.a)).copy()
        exact = np.append(nm.solve(rhs), 0.0)[dofs]
        r_exact = np.einsum('cwij,cwj->cwi', rows, exact)
        r_local, s_local = np.zeros((n, 8, 3)), np.zeros((n, 8, 3))
        infl_l, infl_r = tt.compliance.influence
        tt.contact_step.kernels.rail_predictor(element, tt.side, *infl_l, *infl_r, rows, slope,
                                               rhs, r_local, s_local)
        assert np.max(np.abs(r_exact)) > 1e-4       # the rail is loaded
        assert np.max(np.abs(r_local - r_exact)) < tt.tol
        checked += 1
    assert tt.window_moves >= 3
    assert checked >= 3
    assert np.mean(solves[1:]) < 1.1


def test_reduced_track_carries_partitioned_piled_piers():
    """
    ``reduced`` with a piled pier coupled through its bearings: the full model's results.

    One car over pier 3 of four spans (coarse soil): the bearing forces of the
    partitioned substructure act on girder DOFs that every window keeps, and the
    substructure reads the girder ends from the window's state. Measured over the
    0.05 s (RMS of the difference over the full model's RMS): pile heads 6.5e-8,
    bearing forces of pier 3 2.1e-6, girder mid-span 4.5e-5.
    """
    overrides = ['bridge.n_spans=4', 'foundation.piled_piers=[3]', 'soil.mesh.h=1.5',
                 'soil.mesh.h_max=5.0', 'soil.mesh.h_shaft=3.0', 'soil.block.lx=30.0',
                 'soil.block.ly=24.0', 'train.n_cars=1', 'train.start_position=75.0',
                 "output.observers=['girder_1=girder@80.0']", 'solver.duration=0.05',
                 'solver.window_margin=30']   # a window shorter than these four spans

    def run(variant):
        sim = Simulation(load_scenario('paper_ttbcpsi', [*overrides,
                                                         f'solver.variant={variant}']))
        frames = list(sim.frames())
        return sim, [np.array([f.pile_displacement for f in frames]),
                     np.array([f.bearings[2] for f in frames]),
                     np.array([f.midspan[:, 2] for f in frames])]

    sim, reduced = run('reduced')
    assert sim.coupling.n_free < sim.structure.n_free
    _, full = run('qdldl')
    assert np.abs(full[1]).max() > 1e5          # the bearings carry the car
    for name, a, b, tol in zip(('piles', 'bearings', 'mid-span'), reduced, full,
                               (1e-6, 1e-4, 1e-3)):
        assert np.sqrt(np.mean((a - b)**2)) <= tol * np.sqrt(np.mean(b**2)), name


@pytest.mark.parametrize('gap', [0.07, 0.0])
def test_slab_joints_are_where_the_units_end_with_or_without_a_gap(gap):
    """Every joint between slab units is found, one unit length apart, and cuts both rails."""
    scenario = load_scenario('moving_force_beam', values=SMALL + [('track.slab_gap', gap)])
    structure = build_structure(scenario)
    joints = slab_joints(structure)
    track = scenario.track
    pitch = track.fasteners_per_slab * track.fastener_spacing
    slab = structure.track.slab
    units = round((slab.start[-1] + slab.length[-1] - slab.start[0] + gap) / pitch)
    assert joints.size == units - 1
    np.testing.assert_allclose(np.diff(joints), pitch, rtol=1e-9)
    assert rail_cuts(structure, joints).size == 2 * 6 * joints.size


def test_window_margin_key_sets_the_window():
    """``solver.window_margin`` (default the module's MARGIN) widens the detailed track."""
    from ttb_sim.config.records import SolverConfig
    assert SolverConfig().window_margin == reduced_track.MARGIN
    sizes = []
    for margin in (10.0, 60.0):
        sim = Simulation(load_scenario('moving_force_beam', values=SMALL + [
            ('solver.variant', 'reduced'), ('solver.duration', 0.002),
            ('solver.window_margin', margin)]))
        list(sim.frames())
        window = sim.coupling.window
        rear = sim.scenario.train.start_position + float(np.min(sim.coupling.contact_x))
        track_start = float(track_free_dofs(sim.structure)[1].min())
        wanted = max(rear - margin, track_start)
        assert window.start <= wanted < window.start + 6.0   # widened to a joint
        sizes.append(window.size)
    assert sizes[0] < sizes[1]


def test_a_window_reaching_past_the_first_joint_takes_the_whole_end_unit(small):
    # An end unit cut inside the window would be condensed in part onto kept DOFs of its
    # own: a stiff link the multi-rate exchange does not survive (paper_ttbi, margin 60 m:
    # gain 0.037, the contact iteration diverged 0.11 s after the window moved there).
    from ttb_sim.sim.integrators.multirate import coupling_gain, MAX_COUPLING_GAIN
    st, _ = small
    static = static_track_basis(st, 'qdldl')
    track_x = track_free_dofs(st)[1]
    first, last = float(static.joints[0]), float(static.joints[-1])
    assert track_x.min() < first - 1.0 and last + 1.0 < track_x.max()
    window = track_window(st, static, rigid_track_basis(st), first - 1.0, last + 1.0)
    assert window.start == track_x.min() and window.end == track_x.max()
    fast = np.unique(window.full_to_reduced[reduced_track.rail_and_slab_dofs(st)])
    fast = fast[fast < window.size]   # one range, as the multi-rate step needs
    slow = np.setdiff1d(np.arange(window.size), fast)
    gain = coupling_gain(project(st.mass, window.local_basis),
                         project(st.damping, window.local_basis),
                         project(st.stiffness, window.basis),
                         slice(int(fast[0]), int(fast[-1]) + 1), slow, 1e-4, 5)
    assert gain <= MAX_COUPLING_GAIN


def test_a_window_at_the_track_end_stays_there():
    # Once the window takes the track to its last node it cannot move further: it must not
    # be rebuilt at every step while the train runs on towards the end.
    sim = Simulation(load_scenario('moving_force_beam', values=SMALL + [
        ('solver.variant', 'reduced'), ('solver.duration', 0.01),
        ('train.start_position', 120.0)]))   # front + margin beyond the track's end (142 m)
    list(sim.frames())
    window = sim.coupling.window
    assert window.reaches_end
    assert sim.coupling.window_moves == 1
