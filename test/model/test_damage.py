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
The damage and environment sections through the user pipeline, against closed forms.

Every physical test builds the structure from a :class:`Scenario` the way a run
does (``build_structure``) and states its reference and tolerance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from ttb_sim.config import load_scenario, Scenario
from ttb_sim.config.conditions import pier_substructure
from ttb_sim.errors import ScenarioError
from ttb_sim.model.bridge import pier_section
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.damage import SCOUR_RESIDUAL
from ttb_sim.model.foundation.operator import spring_pier
from ttb_sim.model.foundation.records import Substructure
from ttb_sim.model.foundation.substructure import materials
from ttb_sim.model.vehicle.payload import loaded_car
from ttb_sim.sim import build_structure, build_vehicle, Simulation
import ttb_sim.sim.build as build
from ttb_sim.validation.cases.damage import first_bending_frequency, girder_damage
from ttb_sim.validation.references.stepped_beam import SteppedBeam

BEAM = 'moving_force_beam'
ELASTIC = ['bearings.model=elastic']


def _beam() -> tuple[float, float, float]:
    b = load_scenario(BEAM).bridge
    return b.span_length, b.bending_stiffness, b.mass_per_length


def _static(scenario: Scenario, dof: str, force: float) -> float:
    """Return the displacement under a static force ``force`` (N) on span 1 (K u = f)."""
    st = build_structure(scenario)
    index = {'midspan': int(st.midspan_dofs[0, 2]), 'end': int(st.girder.w_dofs[0, 0])}[dof]
    f = np.zeros(st.n_free)
    f[index] = force
    return float(spla.spsolve(st.stiffness.tocsc(), f)[index])


# --------------------------------------------------------------------------------------
# The reference itself
# --------------------------------------------------------------------------------------

def test_stepped_beam_reference_is_the_uniform_closed_form_to_1e12() -> None:
    """Uniform span: f_j = j^2 pi / (2 L^2) sqrt(EI/m), delta = F L^3 / (48 EI)."""
    span, ei, mass = _beam()
    beam = SteppedBeam.with_zones(span, ei, mass, ())
    closed = [j**2 * math.pi / (2 * span**2) * math.sqrt(ei / mass) for j in (1, 2, 3)]
    assert beam.frequencies(3) == pytest.approx(closed, rel=1e-12)
    assert beam.midspan_deflection(1e5) == pytest.approx(1e5 * span**3 / (48 * ei), rel=1e-12)
    # a 'step' of the same EI changes nothing
    split = SteppedBeam.with_zones(span, ei, mass, ((5.0, 9.0, 0.0),))
    assert split.frequencies(1)[0] == pytest.approx(closed[0], rel=1e-12)


# --------------------------------------------------------------------------------------
# Girder damage
# --------------------------------------------------------------------------------------

@pytest.mark.parametrize('loss', [0.1, 0.5])
def test_loss_over_the_whole_span_scales_f1_by_sqrt_1_minus_loss_to_1e9(loss: float) -> None:
    """EI (1 - loss) everywhere: f1 times sqrt(1 - loss), whatever the mesh error."""
    sound = first_bending_frequency()
    damaged = first_bending_frequency([girder_damage(16.0, 32.0, loss)])
    assert damaged == pytest.approx(sound * math.sqrt(1.0 - loss), rel=1e-9)


@pytest.mark.parametrize('position, length, loss, tolerance', [
    (16.0, 4.0, 0.3, 1e-5),    # on element boundaries: the 16-element mesh error (1.1e-6)
    (4.0, 8.0, 0.5, 1e-5),
    (9.0, 4.0, 0.3, 5e-4),     # two elements half covered: the flexibility average
    (16.0, 1.0, 0.5, 5e-4),    # inside one element
])
def test_f1_of_a_damaged_segment_matches_the_stepped_beam(
        position: float, length: float, loss: float, tolerance: float) -> None:
    """First bending frequency against the transfer-matrix stepped beam (V23's reference)."""
    span, ei, mass = _beam()
    zone = (position - length / 2, position + length / 2, loss)
    reference = SteppedBeam.with_zones(span, ei, mass, (zone,)).frequencies(1)[0]
    computed = first_bending_frequency([girder_damage(position, length, loss)])
    assert computed == pytest.approx(reference, rel=tolerance)


def test_static_midspan_deflection_of_a_damaged_span_is_virtual_work_to_1e9() -> None:
    """Cubic beam elements are exact at the nodes for piecewise EI on element boundaries."""
    span, ei, mass = _beam()
    zones = ((6.0, 10.0, 0.4), (14.0, 18.0, 0.3))
    overrides = ['damage.girders=[{span: 1, start: 6, length: 4, loss: 0.4}, '
                 '{span: 1, start: 14, length: 4, loss: 0.3}]']
    computed = -_static(load_scenario(BEAM, overrides), 'midspan', -1e5)
    reference = SteppedBeam.with_zones(span, ei, mass, zones).midspan_deflection(1e5)
    assert computed == pytest.approx(reference, rel=1e-9)
    assert reference > 1e5 * span**3 / (48 * ei) * 1.05


def test_girder_damage_acts_on_its_span_only() -> None:
    """Span 2 damaged: span 1's elements keep their stiffness, span 2's lose it."""
    base = ['bridge.n_spans=2']
    sound = build_structure(load_scenario(BEAM, base))
    damaged = build_structure(load_scenario(BEAM, [*base, 'damage.girders=[{span: 2, '
                                                   'start: 0, length: 32, '
                                                   'loss: 0.5}]']))
    d1, d2 = (s.midspan_dofs[:, 2] for s in (sound, damaged))
    k_sound, k_damaged = sound.stiffness.toarray(), damaged.stiffness.toarray()
    assert k_damaged[d2[0], d2[0]] == k_sound[d1[0], d1[0]]
    assert k_damaged[d2[1], d2[1]] == pytest.approx(0.5 * k_sound[d1[1], d1[1]], rel=1e-12)


# --------------------------------------------------------------------------------------
# Bearings and temperature
# --------------------------------------------------------------------------------------

def test_bearing_loss_gives_the_support_stiffness_2k_1_minus_loss_to_1e9() -> None:
    """A load over support 1 goes to its two bearings alone: u = F / (2 k (1 - loss))."""
    s = load_scenario(BEAM, [*ELASTIC, 'damage.bearings=[{support: 1, stiffness_loss: 0.4}]'])
    k = s.bearings.vertical_stiffness
    assert _static(s, 'end', 1e6) == pytest.approx(1e6 / (2 * k * 0.6), rel=1e-9)
    one_side = load_scenario(BEAM, [*ELASTIC, 'damage.bearings=[{support: 1, side: left, '
                                    'stiffness_loss: 0.4}]'])
    st = build_structure(one_side)
    assert st.bearings is not None
    k_z = st.bearings.stiffness[:, 2]
    first = st.bearings.support == 0
    assert sorted(k_z[first]) == pytest.approx([0.6 * k, k], rel=1e-15)
    assert np.all(k_z[~first] == k)


@pytest.mark.parametrize('temperature', [-10.0, 35.0])
def test_temperature_shifts_f1_by_sqrt_of_the_modulus_factor_to_1e9(temperature: float) -> None:
    """Frequency goes with sqrt(E): f1(T) / f1(T_ref) = sqrt(1 + alpha_E (T - T_ref))."""
    s = load_scenario(BEAM, [f'environment.temperature={temperature}'])
    alpha = s.environment.girder_modulus_coefficient
    ratio = math.sqrt(1.0 + alpha * (temperature - 20.0))
    computed = first_bending_frequency([f'environment.temperature={temperature}'])
    assert computed == pytest.approx(first_bending_frequency() * ratio, rel=1e-9)
    assert build_structure(s).fundamental_frequency == pytest.approx(
        build_structure(load_scenario(BEAM)).fundamental_frequency * ratio, rel=1e-12)


def test_cold_stiffens_the_bearings_and_warmth_leaves_them() -> None:
    """k(T) = k_ref (1 + alpha_b (T - T_ref)) below T_ref; k_ref above (docs/damage.md)."""
    cold = load_scenario(BEAM, [*ELASTIC, 'environment.temperature=-5'])
    factor = 1.0 + cold.environment.bearing_stiffness_coefficient * (-25.0)
    assert factor == pytest.approx(1.0 + 25.0 * 2.0 / 45.0)
    k = cold.bearings.vertical_stiffness
    assert _static(cold, 'end', 1e6) == pytest.approx(1e6 / (2 * k * factor), rel=1e-9)
    warm = load_scenario(BEAM, [*ELASTIC, 'environment.temperature=35'])
    assert _static(warm, 'end', 1e6) == pytest.approx(1e6 / (2 * k), rel=1e-9)


# --------------------------------------------------------------------------------------
# Passenger load
# --------------------------------------------------------------------------------------

def test_passenger_load_adds_m_g_over_n_axles_to_every_vehicle_model() -> None:
    """Moving forces and quarter cars: m g / 4 per axle; multibody cars: m g / 8 per wheel."""
    m = 6000.0
    base = load_scenario('ten_span_train')
    loaded = load_scenario('ten_span_train', [f'train.passenger_load={m}'])
    f0, f1 = build_vehicle(base), build_vehicle(loaded)
    assert np.allclose(f1.loads - f0.loads, m * GRAVITY / 4, rtol=1e-12)  # type: ignore
    quarter = ['train.vehicle=sprung_mass']
    q0 = build_vehicle(load_scenario('ten_span_train', quarter))
    q1 = build_vehicle(load_scenario('ten_span_train', [*quarter, f'train.passenger_load={m}']))
    added = (q1.sprung_mass - q0.sprung_mass) * GRAVITY  # type: ignore
    assert np.allclose(added, m * GRAVITY / 4, rtol=1e-12)
    car = base.car
    heavy = loaded_car(car, m)
    assert heavy.static_wheel_load - car.static_wheel_load == pytest.approx(m * GRAVITY / 8)
    ratio = (car.car_body_mass + m) / car.car_body_mass
    for name in ('roll', 'pitch', 'yaw'):
        key = f'car_body_{name}_inertia'
        assert getattr(heavy, key) == pytest.approx(getattr(car, key) * ratio, rel=1e-15)
    assert heavy.bogie_mass == car.bogie_mass
    hand = load_scenario(BEAM, [f'train.passenger_load={m}'])  # one axle placed by hand
    assert build_vehicle(hand).loads[0] == hand.train.axle_load + m * GRAVITY  # type: ignore


# --------------------------------------------------------------------------------------
# Piled piers: scour, piles, soil (records; the substructure build is not run here)
# --------------------------------------------------------------------------------------

def test_scour_removes_the_soil_above_the_depth_and_piles_lose_their_modulus() -> None:
    """Layers 2/4/16 m scoured to 3 m: 2 + 1 m removed (same wave speeds), 3 + 16 m kept."""
    s = load_scenario('paper_ttbcpsi', ['damage.scour=[{pier: 7, depth: 3.0}]',
                                        'damage.piles=[{pier: 8, stiffness_loss: 0.25}]',
                                        'environment.soil_modulus_scale=[2.0, 1.0, 1.0]'])
    sound = s.substructure().soil.layers
    scoured = pier_substructure(s, 7)
    layers = scoured.soil.layers
    assert [lay.thickness for lay in layers] == pytest.approx([2.0, 1.0, 3.0, 16.0])
    assert layers[0].E == pytest.approx(2.0 * sound[0].E * SCOUR_RESIDUAL)
    assert layers[1].E == pytest.approx(sound[1].E * SCOUR_RESIDUAL)
    assert [lay.vs for lay in layers[:3]] == pytest.approx(
        [sound[0].vs * math.sqrt(2.0), sound[1].vs, sound[1].vs])
    assert layers[2].E == sound[1].E and layers[3] == sound[2]
    assert scoured.piles == s.piles
    other = pier_substructure(s, 8)
    assert other.soil.layers[1:] == sound[1:]
    assert other.piles is not None and s.piles is not None
    young = materials(other).young
    assert young[len(other.soil.layers)] == pytest.approx(0.75 * s.piles.E, rel=1e-15)


def test_each_piled_pier_stands_on_its_own_damaged_ground(monkeypatch) -> None:
    """Piers 3 and 4 piled, pier 3 scoured: two substructures; undamaged: one, shared."""
    specs: list[Substructure] = []

    def spring_founded(scenario: Scenario, spec: Substructure | None = None) -> object:
        specs.append(spec if spec is not None else scenario.substructure())
        fd, pr = scenario.foundation, scenario.piers
        k = np.array([fd.lateral_stiffness] * 2 + [fd.vertical_stiffness]
                     + [fd.rotational_stiffness] * 3)
        return spring_pier(pr.height, pr.elements, pier_section(pr), k, np.zeros(6), (0.0, 0.0))

    monkeypatch.setattr(build, 'build_foundation', spring_founded)
    piled = ['bridge.n_spans=4', 'foundation.model=piled', 'foundation.piled_piers=[3, 4]',
             'cap.enabled=true', 'bearings.model=elastic']
    st = build_structure(load_scenario('ten_span_train', piled))
    assert len(specs) == 1 and st.piled[0].operator is st.piled[1].operator
    specs.clear()
    st = build_structure(load_scenario('ten_span_train', [*piled, 'damage.scour=[{pier: 3, '
                                                          'depth: 1.5}]']))
    assert len(specs) == 2 and st.piled[0].operator is not st.piled[1].operator
    assert specs[0].soil.layers[0].E == pytest.approx(
        specs[1].soil.layers[0].E * SCOUR_RESIDUAL)


# --------------------------------------------------------------------------------------
# Defaults change nothing
# --------------------------------------------------------------------------------------

ZERO = ['damage.girders=[{span: 1, start: 14, length: 4, loss: 0.0}]',
        'environment.temperature=20', 'train.passenger_load=0']
ZERO_BEARINGS = ['damage.bearings=[{support: 2, stiffness_loss: 0.0}]']


def test_an_all_zero_damage_section_gives_bit_identical_matrices_and_frames() -> None:
    """Zero losses at the reference temperature: the same bits as no section at all."""
    for extra, zero in (([], ZERO), (ELASTIC, [*ZERO, *ZERO_BEARINGS])):
        a = build_structure(load_scenario(BEAM, extra))
        b = build_structure(load_scenario(BEAM, [*extra, *zero]))
        for name in ('stiffness', 'mass', 'damping'):
            ma, mb = getattr(a, name), getattr(b, name)
            assert (ma != mb).nnz == 0 and np.array_equal(ma.data, mb.data)
    short = [*ELASTIC, 'solver.duration=0.05']
    runs = [list(Simulation(load_scenario(BEAM, [*short, *zero])).frames())
            for zero in ([], [*ZERO, *ZERO_BEARINGS])]
    assert len(runs[0]) == len(runs[1]) > 10
    for fa, fb in zip(*runs):
        assert np.array_equal(fa.midspan, fb.midspan)
        assert np.array_equal(fa.bearings, fb.bearings)


def test_echo_carries_the_damage_and_environment_sections() -> None:
    """summary.json names them 'damage' and 'environment'."""
    echo = load_scenario(BEAM, ZERO[:1]).echo()
    assert echo['damage']['girders'][0]['loss'] == 0.0
    assert echo['environment']['reference_temperature'] == 20.0


# --------------------------------------------------------------------------------------
# Refusals: the key, the value and what is allowed, before anything is built
# --------------------------------------------------------------------------------------

@pytest.mark.parametrize('scenario, overrides, match', [
    (BEAM, ['damage.girders=[{span: 2, start: 14, length: 4, loss: 0.3}]'],
     r'damage.girders\[0\].span = 2 is not a span; allowed: 1 to 1'),
    (BEAM, ['damage.girders=[{span: 1, start: 29, length: 4, loss: 0.3}]'],
     r'damage.girders\[0\]: .* off the span; allowed: inside 0 to 32 m'),
    (BEAM, ['damage.girders=[{span: 1, start: 14, length: 4, loss: 1.0}]'],
     r'damage.girders\[0\].loss = 1.* allowed \[0, 1\)'),
    (BEAM, ['damage.girders=[{span: 1, start: 14, length: 4, loss: -0.1}]'],
     r'damage.girders\[0\].loss = -0.1'),
    (BEAM, ['damage.girders=[{span: 1, start: 14, length: 4, loss: 0.1}, '
            '{span: 1, start: 16, length: 4, loss: 0.1}]'],
     r'damage.girders\[1\] .* overlaps damage.girders\[0\]'),
    (BEAM, ['damage.bearings=[{support: 1, stiffness_loss: 0.5}]'],
     r"damage.bearings\[0\]: bearing damage needs bearings.model = 'elastic'"),
    (BEAM, [*ELASTIC, 'damage.bearings=[{support: 3, stiffness_loss: 0.5}]'],
     r'damage.bearings\[0\].support = 3 is not a support; allowed: 1 to 2'),
    (BEAM, ['damage.scour=[{pier: 2, depth: 1.0}]'],
     r'damage.scour\[0\].pier = 2 is not a piled pier; allowed: none'),
    ('paper_ttbcpsi', ['damage.piles=[{pier: 6, stiffness_loss: 0.5}]'],
     r'damage.piles\[0\].pier = 6 is not a piled pier; allowed: \[7, 8\]'),
    ('paper_ttbcpsi', ['damage.scour=[{pier: 7, depth: 30.0}]'],
     r'damage.scour\[0\].depth = 30 m is not above the base of the soil block \(22 m'),
    ('paper_ttbcpsi', ['damage.scour=[{pier: 7, depth: 12.0}]'],
     r'damage.scour\[0\].depth = 12 m reaches the pile tips'),
    ('paper_ttbcpsi', ['environment.soil_modulus_scale=[2.0]'],
     r'environment.soil_modulus_scale = \[2.0\] has 1 factors for 3 soil.layers'),
    (BEAM, ['environment.soil_modulus_scale=[2.0]'],
     r"environment.soil_modulus_scale .* needs foundation.model = 'piled'"),
    (BEAM, ['environment.temperature=-60', 'environment.girder_modulus_coefficient=0.0125'],
     r'environment.girder_modulus_coefficient = 0.0125 .* stiffness factor of 0; allowed'),
    (BEAM, ['train.passenger_load=-1'], r'train.passenger_load = -1'),
])
def test_bad_damage_and_environment_input_is_refused_naming_the_key(
        scenario: str, overrides: list[str], match: str) -> None:
    """Each refusal names the key, the value and what is allowed."""
    with pytest.raises(ScenarioError, match=match):
        load_scenario(scenario, overrides)
