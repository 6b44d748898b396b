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
The quarter-car coupling (`QuarterCarCoupling`) with the wheel on a very stiff girder.

A 10 m span with EI = 1e16 N m^2 (f1 = 8.4 kHz; 4.8e14 N/m at mid-span, 3e8 times the
suspension) holds the wheel practically still, so the sprung mass is a single
oscillator: f = sqrt(k / M_s) / (2 pi) = 2.6507 Hz for the Yang & Yau vehicle
(M_s = 5750 kg, k = 1595 kN/m, PHYSICS.md 9.3), here with a 400 kg wheel.
Newmark's average acceleration lengthens the period by (omega dt)^2 / 12 (2.3e-5
at dt = 1 ms) and keeps the amplitude.
"""

import math

import numpy as np
import pytest
from ttb_sim.model.bearings import BearingParameters
from ttb_sim.model.bridge import BridgeParameters, PierParameters
from ttb_sim.model.foundation.pier_foundations import FoundationParameters
from ttb_sim.model.structure import assemble_structure
from ttb_sim.model.vehicle.train import Axles, QuarterCars
from ttb_sim.sim.coupling.quarter_car.wheels import QuarterCarCoupling
from ttb_sim.sim.integrators.newmark import Newmark

MS, MU, K = 5750.0, 400.0, 1.595e6
WEIGHT = (MS + MU) * 9.81
DT = 1e-3
F_REF = math.sqrt(K / MS) / (2.0 * math.pi)
MIDSPAN = np.array([5.0])


def _coupling():
    structure = assemble_structure(
        BridgeParameters(span_length=10.0, bending_stiffness=1e16, damping_ratio=0.0),
        BearingParameters(), PierParameters(), FoundationParameters(), None, 0.0)
    cars = QuarterCars(Axles(np.zeros(1)), np.array([MS]), np.array([MU]), np.array([K]),
                       np.zeros(1))
    integrator = Newmark(structure.mass, structure.damping, structure.stiffness, DT)
    return QuarterCarCoupling(cars, structure.girder, integrator, structure.n_free), structure


def _run(coupling, n_free, n_steps):
    """Step a car standing at mid-span; return z, the sprung acceleration and the contact."""
    u, v, a = np.zeros(n_free), np.zeros(n_free), np.zeros(n_free)
    zero = np.zeros(n_free)
    z, acc, contact = [coupling.z[0]], [coupling.a[0]], [coupling.contact[0]]
    for _ in range(n_steps):
        u, v, a = coupling.step(u, v, a, zero, MIDSPAN, 0.0)
        z.append(coupling.z[0])
        acc.append(coupling.a[0])
        contact.append(coupling.contact[0])
    return np.array(z), np.array(acc), np.array(contact)


def test_static_wheel_load():
    """From equilibrium the car stays put and the girder carries (M_s + M_u) g (1e-3)."""
    coupling, structure = _coupling()
    assert coupling.contact == pytest.approx([WEIGHT], rel=1e-12)  # initial contact
    z, _, contact = _run(coupling, structure.n_free, 500)
    assert contact == pytest.approx(np.full(contact.size, WEIGHT), rel=1e-3)
    assert np.max(np.abs(z)) < 1e-8  # m; the static girder deflection is 1.3e-10 m


def test_bounce_frequency_from_free_vibration():
    """
    Released from z0 = 10 mm: f = sqrt(k / M_s) / (2 pi) within 1e-4.

    The measured frequency (mean of the zero-crossing intervals over five
    periods) also matches Newmark's discrete frequency (2 / dt) atan(omega dt / 2)
    within 1e-6, and the amplitude is kept within 1e-4 (no numerical damping).
    """
    coupling, structure = _coupling()
    z0 = 0.01
    coupling.z[:] = z0
    coupling.a[:] = -K * z0 / MS
    n_steps = int(round(5.0 / F_REF / DT))
    z, acc, contact = _run(coupling, structure.n_free, n_steps)
    crossing = np.flatnonzero(np.signbit(z[1:]) != np.signbit(z[:-1]))
    t_cross = (crossing - z[crossing] / (z[crossing + 1] - z[crossing])) * DT
    frequency = 0.5 / np.mean(np.diff(t_cross))
    assert crossing.size == 10
    assert frequency == pytest.approx(F_REF, rel=1e-4)
    omega = 2.0 * math.pi * F_REF
    discrete = 2.0 / DT * math.atan(0.5 * omega * DT) / (2.0 * math.pi)
    assert frequency == pytest.approx(discrete, rel=1e-6)
    assert np.max(np.abs(z)) == pytest.approx(z0, rel=1e-4)
    # The wheel barely moves, so the contact force balances weight and sprung inertia:
    # R = (M_s + M_u) g + M_s z'' (z up), within 1e-3 of the weight (from the first step on;
    # the released state at t = 0 was set by hand, its contact is not computed).
    balance = contact[1:] - MS * acc[1:]
    assert balance == pytest.approx(np.full(n_steps, WEIGHT), rel=1e-3)


def test_the_quarter_cars_of_a_car_layout_are_published_as_cars_with_their_axles():
    """live_train's 4 cars of 4 quarter cars: car01..car04, axle1..4; body = mean of four."""
    from ttb_sim.config import load_scenario
    from ttb_sim.sim import Simulation
    sim = Simulation(load_scenario('live_train', values=[('solver.duration', 0.05),
                                                         ('irregularity.seed', 2)]))
    frames = list(sim.frames())
    cp = sim.coupling
    assert (sim.layout.n_bodies, sim.layout.n_axles) == (4, 4)
    last = frames[-1]
    assert last.wheel_rail.shape == (4, 4, 2, 3)
    np.testing.assert_array_equal(last.wheel_rail[..., 2].ravel(),
                                  np.repeat(0.5 * cp.kernel.contact, 2))
    np.testing.assert_allclose(last.body_acceleration[:, 2],
                               cp.kernel.a.reshape(4, 4).mean(axis=1), rtol=1e-15)
    assert np.all(last.body_angular_velocity == 0.0)


def test_axles_placed_by_hand_are_one_car_each():
    """sprung_mass_beam (axle_offsets [0]): car01 with axle1, as the contract names them."""
    from ttb_sim.config import load_scenario
    from ttb_sim.sim import Simulation
    sim = Simulation(load_scenario('sprung_mass_beam', values=[
        ('train.axle_offsets', [0.0, 3.0, 6.0])]))
    assert (sim.layout.n_bodies, sim.layout.n_axles) == (3, 1)
