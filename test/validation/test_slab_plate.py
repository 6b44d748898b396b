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
The pipeline's beam slab and base plate against Mindlin plates (X1).

Tolerances and why
------------------
- Vertical bending pairs below 150 Hz, 1 % (slab) and 3 % (base): a wide plate
  in cylindrical bending would be 1/sqrt(1 - nu^2) = 2.1 % stiffer than the
  beam, but the free long edges let the unit bend anticlastically, nearly as
  a beam, and the plate's shear and rotary inertia lower it slightly; the
  slab shows at most 0.5 %, the thicker, wider base plate 2.1 %.
- Torsion 1, 3 %: the beam's St Venant constant J = 0.947 b h^3 / 3 matches the
  plate's uniform twisting; the plate adds some warping (its bending from the
  twist gradient, D b^3 / 12 theta''), which the beam lacks: beam 2.2 % low.
- Torsion 2 is where that matters: beam 7.5 % (slab) / 9.6 % (base) below the
  plate; asserted as a known, bounded deficit (beam lower, by less than 12 %).
- Transverse bending (no beam counterpart): first plate mode above 100 Hz.
- On the layer (rigid ground below), nothing below 105 Hz in either model, so
  below 100 Hz the unit follows its support quasi-statically.
- Rail-seat receptance on the layer, 0-100 Hz: slab alone within 20 % (the
  beam's rigid cross-section is 14-18 % too stiff under both rails, 4-13 %
  off under one); the support seen by the rail (fastener in series) within
  2 %, since the slab is a small part of that compliance.
"""

import numpy as np
import pytest
from ttb_sim.validation.cases import slab_plate as sp


@pytest.fixture(scope='module')
def slab_free():
    return sp.compare('slab', False, f_max=150.0)


@pytest.fixture(scope='module')
def base_free():
    return sp.compare('base', False, f_max=150.0)


def _pairs(comparison):
    return {p.label: p for p in comparison.pairs}


def test_beam_is_the_pipelines_one_unit():
    unit = sp.beam_unit('slab')
    assert unit.x == pytest.approx([0.0, 0.28, *(0.28 + 0.63 * np.arange(1, 9)), 5.6])
    plate = sp.plate_of('slab')
    # Slab concrete plus half the filling layer, spread over the slab section.
    assert plate.mass_per_area * 2.5 == pytest.approx(2500 * 2.5 * (0.21 + 0.045))


def test_free_slab_bending_and_torsion_pair_with_plate(slab_free):
    pairs = _pairs(slab_free)
    assert [pairs[f'vertical bending {i}'].beam for i in (1, 2)] == pytest.approx(
        [23.70, 65.36], abs=0.05)
    for p in slab_free.pairs:
        assert p.mac > 0.9
        if p.label.startswith('vertical') and p.beam < 150.0:
            assert abs(p.difference) < 0.01, p
    assert abs(pairs['torsion 1'].difference) < 0.03
    assert -0.12 < pairs['torsion 2'].difference < 0.0
    assert not slab_free.beam_only


def test_free_slab_transverse_bending_is_above_100_hz(slab_free):
    transverse = [f for label, f in slab_free.plate_only if label.startswith('transverse')]
    assert 110.0 < min(transverse) < 125.0


def test_free_base_plate(base_free):
    pairs = _pairs(base_free)
    for label in ('vertical bending 1', 'vertical bending 2'):
        assert abs(pairs[label].difference) < 0.03
    assert abs(pairs['torsion 1'].difference) < 0.03
    assert -0.12 < pairs['torsion 2'].difference < 0.0
    transverse = [f for label, f in base_free.plate_only if label.startswith('transverse')]
    assert min(transverse) > 100.0


@pytest.mark.parametrize('component, beam_min, plate_min',
                         [('slab', 140.0, 150.0), ('base', 105.0, 115.0)])
def test_on_layer_no_mode_below_100_hz(component, beam_min, plate_min):
    # The layer alone gives sqrt(k / m) = 154 Hz (slab), 121 Hz (base); the beam's
    # roll couples with its lateral sway through the layer acting at the bottom
    # face, which lowers one of the pair (143 Hz, 111 Hz).
    beam = sp.beam_modes(component, True, f_max=400.0)
    plate = sp.plate_modes(component, True, f_max=200.0)
    assert beam.frequency.min() > beam_min
    assert plate.frequency.min() > plate_min


def test_rail_seat_receptance_on_layer():
    d = sp.support_differences(np.linspace(0.0, 100.0, 6))
    assert np.abs(d['slab']).max() < 0.20
    assert np.abs(d['support']).max() < 0.02
