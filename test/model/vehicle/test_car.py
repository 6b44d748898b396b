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
Tests of the 42-DOF car (PHYSICS.md 3, VALIDATION.md V4).

Reference numbers are typed again from PHYSICS.md 3.1 and [P] Table 1; the
closed-form estimates are written out here independently of the module.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttb_sim.errors import ModelError
import ttb_sim.model.vehicle as car
from ttb_sim.model.wheel_rail import hertz_constant, linearised_stiffness

UPPER = ('car_body', 'bogie_1', 'bogie_2')
G = 9.81


@pytest.fixture(scope='module')
def matrices() -> car.CarMatrices:
    return car.car_matrices()


def _energy_fractions(mode: np.ndarray, mass: np.ndarray) -> dict[str, float]:
    """Kinetic-energy share of DOF groups in a mode (the shape that names it)."""
    e = np.diag(mass) * mode ** 2
    e = e / e.sum()
    groups = {
        'car_body_bounce': [car.dof('car_body', 'z')],
        'car_body_pitch': [car.dof('car_body', 'pitch')],
        'bogie_bounce': [car.dof(b, 'z') for b in ('bogie_1', 'bogie_2')],
        'bogie_pitch': [car.dof(b, 'pitch') for b in ('bogie_1', 'bogie_2')],
        'longitudinal': list(car.dofs(UPPER, ['x'])),
    }
    return {name: float(e[idx].sum()) for name, idx in groups.items()}


def test_v4_vertical_in_plane_frequencies(matrices):
    """
    V4: in-plane (x, z, pitch) modes of car body and bogies, wheelsets fixed.

    Reference PHYSICS.md 3.1 [derived]: car-body bounce 0.840 Hz, car-body
    pitch 0.952 Hz, bogie pitch 4.78 Hz, bogie bounce 6.27 Hz; tolerance 1 %.
    Modes are named by their kinetic-energy shares (> 50 % in one group), not by
    sorting: the longitudinal car-body mode (about 0.71 Hz) lies below the bounce.
    Measured: 0.8400, 0.9521, 4.7820 (both bogies), 6.2770 / 6.2802 Hz.
    """
    subset = car.dofs(UPPER, ['x', 'z', 'pitch'])
    freq, modes = car.eigenfrequencies(matrices.mass, matrices.stiffness, subset)
    named: dict[str, list[float]] = {}
    for f, mode in zip(freq, modes.T):
        shares = _energy_fractions(mode, matrices.mass)
        name, share = max(shares.items(), key=lambda kv: kv[1])
        assert share > 0.5, (f, shares)
        named.setdefault(name, []).append(f)
    reference = {'car_body_bounce': (0.840, 1), 'car_body_pitch': (0.952, 1),
                 'bogie_pitch': (4.78, 2), 'bogie_bounce': (6.27, 2)}
    for name, (f_ref, count) in reference.items():
        assert len(named[name]) == count, named
        for f in named[name]:
            assert f == pytest.approx(f_ref, rel=0.01), (name, f)
    assert len(named['longitudinal']) == 3


def test_v4_closed_form_estimates(matrices):
    """Bogie pitch equals sqrt(4 Kpz lt^2 / Ity) / 2 pi (decoupled); bounce series estimate 1 %."""
    p = matrices.params
    subset = car.dofs(UPPER, ['z', 'pitch'])
    freq, _ = car.eigenfrequencies(matrices.mass, matrices.stiffness, subset)
    f_pitch = math.sqrt(4 * 1.04e6 * 1.25 ** 2 / 7200.0) / (2 * math.pi)
    assert np.min(np.abs(freq - f_pitch)) < 1e-9 * f_pitch
    k_eq = 1.0 / (1.0 / (4 * 0.4e6) + 1.0 / (8 * 1.04e6))
    assert freq[0] == pytest.approx(math.sqrt(k_eq / 48000.0) / (2 * math.pi), rel=0.01)
    assert p.car_body_mass == 48000.0 and p.bogie_semi_spacing == 7.85


def test_matrices_symmetric_and_positive_semidefinite(matrices):
    """M, C, K symmetric to round-off; K and C positive semi-definite; M positive definite."""
    for a in (matrices.mass, matrices.damping, matrices.stiffness):
        assert a.shape == (42, 42)
        assert np.allclose(a, a.T, rtol=0.0, atol=1e-12 * np.abs(a).max())
    for a in (matrices.stiffness, matrices.damping):
        w = np.linalg.eigvalsh(a)
        assert w.min() > -1e-12 * w.max()
    assert np.linalg.eigvalsh(matrices.mass).min() > 0.0


def _null_space(k: np.ndarray) -> np.ndarray:
    w, v = np.linalg.eigh(k)
    return v[:, np.abs(w) < 1e-10 * np.abs(w).max()]


def _rigid_motions(pitch_moves_x: bool) -> list[np.ndarray]:
    """Rigid-body motions of the whole car and the wheelset spins."""
    pos = car.body_positions()
    motions = []
    for axis in range(3):
        v = np.zeros(42)
        v[axis::6] = 1.0
        motions.append(v)
        theta = np.eye(3)[axis]
        v = np.zeros(42)
        for b in range(7):
            shift = np.cross(theta, pos[b])
            if axis == 1 and not pitch_moves_x:
                shift[0] = 0.0  # Zhai-type model: pitch without the x = theta z shift
            v[6 * b:6 * b + 3] = shift
            v[6 * b + 3:6 * b + 6] = theta
        motions.append(v)
    for w in car.WHEELSETS:
        v = np.zeros(42)
        v[car.dof(w, 'pitch')] = 1.0
        motions.append(v)
    return motions


@pytest.mark.parametrize('coupled', [False, True])
def test_free_car_zero_stiffness_modes(coupled):
    """
    Wheelsets free: exactly 12 zero-stiffness modes.

    Expected: 6 rigid-body motions of the car, 4 wheelset spins (the axle boxes
    do not restrain rotation about the axle) and 2 bogie-plus-wheelsets rocking
    mechanisms about the air-spring line of each bogie.  In the default
    Zhai-type model (longitudinal springs without pitch arms) the rigid pitch
    is the vertical-plane rotation z = -theta x without the x = theta z shift;
    with ``longitudinal_pitch_coupling`` it is the true rigid rotation.
    """
    p = car.CarParameters(longitudinal_pitch_coupling=coupled)
    k = car.stiffness_matrix(p)
    null = _null_space(k)
    assert null.shape[1] == 12
    scale = np.abs(k).max()
    for v in _rigid_motions(pitch_moves_x=coupled):
        assert np.linalg.norm(k @ v) < 1e-9 * scale * np.linalg.norm(v)
    if not coupled:
        true_pitch = _rigid_motions(pitch_moves_x=True)[3]
        assert np.linalg.norm(k @ true_pitch) > 1e-3 * scale
    # Rocking of bogie 1 and its wheelsets about the air-spring line (x = l_c, z = h_s).
    pos = car.body_positions(p)
    rocking = np.zeros(42)
    for body in (1, 3, 4):
        dx, dz = pos[body, 0] - 7.85, pos[body, 2] - 0.90
        rocking[car.dof(body, 'x')] = dz if coupled else 0.0
        rocking[car.dof(body, 'z')] = -dx
        rocking[car.dof(body, 'pitch')] = 1.0
    assert np.linalg.norm(k @ rocking) < 1e-9 * scale * np.linalg.norm(rocking)


def test_wheelsets_fixed_has_no_zero_modes(matrices):
    """Wheelsets clamped (rigid track): the 18 car-body and bogie DOFs are fully restrained."""
    subset = car.dofs(UPPER, car.COMPONENTS)
    freq, _ = car.eigenfrequencies(matrices.mass, matrices.stiffness, subset)
    assert freq.min() > 0.4


def test_contact_springs_leave_only_rolling(matrices):
    """
    Contact-point springs in x, y, z to a rigid rail: one zero mode, rolling along the track.

    The springs restrain x - r0 pitch, not pitch alone, so the whole car can
    roll (x_i = d, wheelset spin = d / r0); with the spins also held there is
    no zero mode.
    """
    cmap = matrices.contacts
    k = matrices.stiffness + car.contact_spring_stiffness(cmap, 1.5e9, 1e8, 1e8)
    null = _null_space(k)
    assert null.shape[1] == 1
    rolling = np.zeros(42)
    rolling[0::6] = 1.0
    for w in car.WHEELSETS:
        rolling[car.dof(w, 'pitch')] = 1.0 / 0.46
    rolling /= np.linalg.norm(rolling)
    assert abs(null[:, 0] @ rolling) == pytest.approx(1.0, abs=1e-9)
    spins = [car.dof(w, 'pitch') for w in car.WHEELSETS]
    keep = np.setdiff1d(np.arange(42), spins)
    freq, _ = car.eigenfrequencies(matrices.mass, k, keep)
    assert freq.min() > 0.1


def test_static_wheel_loads_on_contact_springs(matrices):
    """
    Gravity on linearised Hertz springs gives P0 = 78.5 kN per wheel (+-0.5 %), no lateral force.

    Reference PHYSICS.md 2.1: P0 = (Mc/8 + Mt/4 + Mw/2) g = 78.5 kN.  Solved on
    all DOFs but the wheelset spins (which carry no static load).
    """
    cmap = matrices.contacts
    p0_expected = (48000 / 8 + 3200 / 4 + 2400 / 2) * G
    assert car.static_wheel_load() == pytest.approx(78.5e3, rel=0.005)
    assert car.static_wheel_load() == pytest.approx(p0_expected, rel=1e-12)
    k_h = float(linearised_stiffness(p0_expected, hertz_constant(0.46, 'lm')))
    k = matrices.stiffness + car.contact_spring_stiffness(cmap, k_h, 1e8, 1e8)
    spins = [car.dof(w, 'pitch') for w in car.WHEELSETS]
    keep = np.setdiff1d(np.arange(42), spins)
    u = np.zeros(42)
    u[keep] = np.linalg.solve(k[np.ix_(keep, keep)], matrices.gravity[keep])
    wheel_load = -k_h * (cmap.hz @ u)
    lateral = -1e8 * (cmap.hy @ u)
    assert wheel_load == pytest.approx(np.full(8, 78.5e3), rel=0.005)
    assert wheel_load.sum() == pytest.approx((48000 + 2 * 3200 + 4 * 2400) * G, rel=1e-9)
    assert np.abs(lateral).max() < 1e-6 * wheel_load.max()


def test_gravity_vector_and_mass():
    """Gravity acts in -z (REP 103, z up) on every body; total equals the car weight."""
    f = car.gravity_vector()
    z = car.dofs(range(7), ['z'])
    assert np.all(f[z] < 0.0)
    assert np.count_nonzero(f) == 7
    assert f.sum() == pytest.approx(-car.CarParameters().total_mass * G)


def test_damping_ratio_limits():
    """
    Car-body bounce damping ratio with a rigid primary tends to PHYSICS.md's 0.71.

    Secondary-only estimate (PHYSICS.md 3.1): zeta = 4 C_sz / (2 sqrt(4 K_sz Mc))
    = 0.707 (tolerance 1 %).  The projected ratios scale with the damper counts.
    """
    per_spring = {'primary_vertical_dampers': 8, 'secondary_vertical_dampers': 4,
                  'secondary_lateral_dampers': 4}  # one damper per spring position
    stiff_primary = car.CarParameters(primary_stiffness_z=1e12, **per_spring)
    m, c, k = (car.mass_matrix(stiff_primary), car.damping_matrix(stiff_primary),
               car.stiffness_matrix(stiff_primary))
    subset = car.dofs(UPPER, ['z', 'pitch'])
    _, zeta = car.modal_damping_ratios(m, c, k, subset)
    expected = 4 * 98e3 / (2 * math.sqrt(4 * 0.4e6 * 48000))
    assert zeta[0] == pytest.approx(expected, rel=0.01)
    default = car.car_matrices(car.CarParameters(**per_spring))
    half = car.car_matrices(car.CarParameters())  # the record's 4 / 2 / 2
    _, z_full = car.modal_damping_ratios(default.mass, default.damping, default.stiffness, subset)
    _, z_half = car.modal_damping_ratios(half.mass, half.damping, half.stiffness, subset)
    assert z_half == pytest.approx(0.5 * z_full, rel=1e-9)
    assert z_full[0] == pytest.approx(0.558, abs=0.005)


def test_longitudinal_pitch_coupling_option():
    """With physical moment arms the pitch modes stiffen slightly (documented: < 1 %)."""
    coupled = car.car_matrices(car.CarParameters(longitudinal_pitch_coupling=True))
    subset = car.dofs(UPPER, ['z', 'pitch'])
    f_c, _ = car.eigenfrequencies(coupled.mass, coupled.stiffness, subset)
    plain = car.car_matrices()
    f_0, _ = car.eigenfrequencies(plain.mass, plain.stiffness, subset)
    assert np.all(f_c >= f_0 - 1e-9)
    assert np.all(f_c <= 1.01 * f_0)


def test_dof_helpers():
    """DOF ordering is body-major: index = 6 body + component."""
    assert car.N_DOF == 42
    assert car.dof('car_body', 'x') == 0
    assert car.dof('bogie_2', 'yaw') == 17
    assert car.dof(3, 'z') == 20
    assert car.dof('wheelset_4', 'pitch') == 40
    assert list(car.wheelset_dofs(0)) == list(range(18, 24))
    with pytest.raises(ModelError, match='wheelset_9'):
        car.dof('wheelset_9', 'z')
    with pytest.raises(ModelError, match='component'):
        car.dof(0, 6)
    with pytest.raises(ModelError, match='wheelset number'):
        car.wheelset_dofs(4)


def test_contact_map_kinematics(matrices):
    """Contact point (0, s b, -r0): z_w + s b roll, y_w + r0 roll, x_w - r0 pitch - s b yaw."""
    cmap = matrices.contacts
    b, r0 = 0.7465, 0.46
    assert list(cmap.side) == [1, -1] * 4
    assert list(cmap.wheelset) == [0, 0, 1, 1, 2, 2, 3, 3]
    for k in range(8):
        w = car.WHEELSETS[cmap.wheelset[k]]
        s = cmap.side[k]
        hz = np.zeros(42)
        hz[car.dof(w, 'z')], hz[car.dof(w, 'roll')] = 1.0, s * b
        hy = np.zeros(42)
        hy[car.dof(w, 'y')], hy[car.dof(w, 'roll')] = 1.0, r0
        hx = np.zeros(42)
        hx[car.dof(w, 'x')], hx[car.dof(w, 'pitch')], hx[car.dof(w, 'yaw')] = 1.0, -r0, -s * b
        assert np.allclose(cmap.hz[k], hz) and np.allclose(cmap.hy[k], hy)
        assert np.allclose(cmap.hx[k], hx)
        assert cmap.hyaw[k, car.dof(w, 'yaw')] == 1.0 and cmap.hyaw[k].sum() == 1.0
    assert np.allclose(cmap.x_offset, np.repeat([9.1, 6.6, -6.6, -9.1], 2))


def test_gyroscopic_matrix():
    """Skew-symmetric, I_wy V / r0 between roll and yaw of each wheelset."""
    g = car.gyroscopic_matrix(None, 83.3)
    assert np.allclose(g, -g.T)
    h = 200.0 * 83.3 / 0.46
    assert g[car.dof(3, 'yaw'), car.dof(3, 'roll')] == pytest.approx(h)
    assert np.count_nonzero(g) == 8
    with pytest.raises(ModelError, match='speed'):
        car.gyroscopic_matrix(None, -1.0)


def test_train_matrices():
    """Block-diagonal stack of 8 cars of 25 m; wheelset positions relative to the head."""
    t = car.train_matrices()
    one = car.car_matrices()
    assert t.mass.shape == (336, 336) and t.hz.shape == (64, 336)
    assert np.allclose(t.stiffness[42:84, 42:84].toarray(), one.stiffness)
    assert t.stiffness[0:42, 42:84].nnz == 0
    x = t.wheelset_x
    assert x.shape == (32,)
    assert x[:4] == pytest.approx([-3.4, -5.9, -19.1, -21.6])
    assert x[4:8] == pytest.approx(x[:4] - 25.0)
    assert x[-1] == pytest.approx(-200.0 + 3.4)
    assert t.contact_x[:2] == pytest.approx([-3.4, -3.4])
    assert t.gravity.sum() == pytest.approx(-8 * one.params.total_mass * G)
    short = car.train_matrices(n_cars=2, car_length=20.0)
    assert short.mass.shape == (84, 84)
    with pytest.raises(ModelError, match='car_length'):
        car.train_matrices(car_length=15.0)
    with pytest.raises(ModelError, match='n_cars'):
        car.train_matrices(n_cars=0)


def test_parameter_validation():
    """Bad parameters raise ModelError naming the parameter, value and range."""
    with pytest.raises(ModelError, match='car_body_mass = -1.0'):
        car.CarParameters(car_body_mass=-1.0)
    with pytest.raises(ModelError, match='secondary_vertical_dampers'):
        car.CarParameters(secondary_vertical_dampers=2.5)
    with pytest.raises(ModelError, match='wheelbase_semi'):
        car.CarParameters(wheelbase_semi=8.0)
    with pytest.raises(ModelError, match='vertical'):
        car.contact_spring_stiffness(car.contact_map(), -1.0)
