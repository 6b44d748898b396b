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
The assembled structure (`assemble_structure`) of girders, bearings and piers: closed forms.

Girder defaults: L = 32 m, EI = 4.646e11 N m^2, m = 35200 kg/m (PHYSICS.md 5), so
f1 = pi / (2 L^2) sqrt(EI / m) = 5.5730 Hz. The girders are cubic Hermite (Euler-
Bernoulli) elements with consistent mass: static nodal deflections are exact,
eigenvalues converge as h^4.
"""

import math

import numpy as np
import pytest
import scipy.linalg as la
import scipy.sparse.linalg as sla
from ttb_sim.model.bearings import bearing_forces, BearingParameters
from ttb_sim.model.bridge import BridgeParameters, PierParameters, span_frequency
from ttb_sim.model.foundation.pier_foundations import FoundationParameters
from ttb_sim.model.structure import assemble_structure

GIRDER = BridgeParameters()
L, EI, M = GIRDER.span_length, GIRDER.bending_stiffness, GIRDER.mass_per_length
F1 = math.pi / (2.0 * L**2) * math.sqrt(EI / M)


def _structure(n_spans=1, elements=16, bearings='rigid', foundation='rigid'):
    return assemble_structure(BridgeParameters(n_spans=n_spans, elements_per_span=elements),
                              BearingParameters(model=bearings), PierParameters(),
                              FoundationParameters(model=foundation), None, 0.0)


def _vertical_frequencies(structure):
    """Return the frequencies (Hz) of the modes whose kinetic energy is mostly in uz."""
    k, m = structure.stiffness.toarray(), structure.mass.toarray()
    w2, shapes = la.eigh(k, m)
    uz = (structure.free % 6) == 2
    energy = shapes * (m @ shapes)
    vertical = energy[uz].sum(axis=0) / energy.sum(axis=0) > 0.5
    return np.sqrt(w2[vertical]) / (2.0 * math.pi)


def _static_midspan(structure, span=0):
    """Return the mid-span uz of ``span`` under a unit downward force there, and the state."""
    force = np.zeros(structure.n_free)
    force[structure.midspan_dofs[span, 2]] = -1.0
    u = sla.spsolve(structure.stiffness.tocsc(), force)
    return u[structure.midspan_dofs[span, 2]], np.append(u, 0.0)


def test_span_frequency_closed_form():
    """span_frequency is j^2 pi / (2 L^2) sqrt(EI / m); the structure records mode 1."""
    assert span_frequency(L, EI, M) == pytest.approx(5.57299, rel=1e-5)
    assert span_frequency(L, EI, M, mode=2) == pytest.approx(4.0 * F1, rel=1e-12)
    assert _structure().fundamental_frequency == pytest.approx(F1, rel=1e-12)


def test_first_bending_frequency_from_assembled_matrices():
    """
    First two vertical modes of one span on rigid bearings: f_j = j^2 f1.

    Discretisation error of 16 Hermite elements: about 1e-6 on mode 1 and 2e-5
    on mode 2 (h^4). Tolerances 1e-5 and 1e-4.
    """
    f = _vertical_frequencies(_structure())
    assert f[0] == pytest.approx(F1, rel=1e-5)
    assert f[1] == pytest.approx(4.0 * F1, rel=1e-4)


def test_frequency_error_converges_as_h4():
    """Halving the element size divides the f1 error by 2^4 = 16 (between 14 and 18)."""
    errors = [_vertical_frequencies(_structure(elements=n))[0] / F1 - 1.0 for n in (4, 8, 16)]
    assert all(e > 0.0 for e in errors)  # consistent mass: the FE model is too stiff
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    assert ratios == pytest.approx([16.0, 16.0], abs=2.0)


def test_static_midspan_deflection_rigid_bearings():
    """Unit force at mid-span: w = F L^3 / (48 EI) (nodally exact, rel. 1e-9)."""
    structure = _structure()
    w, u = _static_midspan(structure)
    assert w == pytest.approx(-L**3 / (48.0 * EI), rel=1e-9)
    # Each end carries F / 2, shared by its two bearings: -0.25 N on every support bearing.
    zero = np.zeros_like(u)
    forces = bearing_forces(structure, u, zero, zero, np.zeros(structure.n_full))
    assert forces[:, :, 2] == pytest.approx(np.full((2, 2), -0.25), abs=1e-9)
    assert forces[:, :, :2] == pytest.approx(np.zeros((2, 2, 2)), abs=1e-9)


def test_bearing_springs_in_series_with_the_girder():
    """
    Elastic bearings: w = F L^3 / (48 EI) + F / (4 k_b) (rel. 1e-9).

    Each end carries F / 2 on two bearings of stiffness k_b, so it settles by
    F / (4 k_b) and so does the mid-span, on top of the bending deflection.
    """
    structure = _structure(bearings='elastic')
    k_b = BearingParameters().vertical_stiffness
    w, u = _static_midspan(structure)
    assert w == pytest.approx(-(L**3 / (48.0 * EI) + 1.0 / (4.0 * k_b)), rel=1e-9)
    zero = np.zeros_like(u)
    forces = bearing_forces(structure, u, zero, zero, np.zeros(structure.n_full))
    assert forces[:, :, 2] == pytest.approx(np.full((2, 2), -0.25), rel=1e-9)


def test_pier_and_foundation_in_series():
    """
    Two spans on a pier: the shared support also settles by (F / 2) (H / EA + 1 / k_f).

    The mid-span of span 1 moves by the mean of its end settlements, so
    w = F L^3 / (48 EI) + F / (4 k_b) + (F / 4) (H / EA + 1 / k_f) (rel. 1e-9).
    """
    pier, foundation = PierParameters(), FoundationParameters()
    k_b = BearingParameters().vertical_stiffness
    w, _ = _static_midspan(_structure(n_spans=2, bearings='elastic', foundation='springs'))
    pier_settlement = 0.5 * (pier.height / pier.axial_stiffness
                             + 1.0 / foundation.vertical_stiffness)
    expected = L**3 / (48.0 * EI) + 1.0 / (4.0 * k_b) + 0.5 * pier_settlement
    assert w == pytest.approx(-expected, rel=1e-9)


@pytest.mark.parametrize('direction', [0, 1, 2])
def test_translational_mass_is_conserved(direction):
    """
    A rigid translation carries m L n_spans + m_pier H (n_spans - 1) (rel. 1e-12).

    Three spans on elastic bearings and two piers on springs: every DOF is free,
    so r^T M r over the assembled mass matrix is the whole mass, in x, y and z.
    """
    n_spans, pier = 3, PierParameters()
    structure = _structure(n_spans=n_spans, bearings='elastic', foundation='springs')
    assert structure.n_free == structure.n_full
    r = (structure.free % 6 == direction).astype(float)
    total = M * L * n_spans + pier.mass_per_length * pier.height * (n_spans - 1)
    assert r @ (structure.mass @ r) == pytest.approx(total, rel=1e-12)


def test_rigid_supports_remove_the_pinned_dofs():
    """Rigid bearings fix ux, uy, uz, rx at the first end and uy, uz, rx at the second."""
    structure = _structure(n_spans=2)
    assert structure.bearings is None and structure.rigid is not None
    assert structure.n_full - structure.n_free == 2 * (4 + 3)
    assert structure.rigid.full_dofs.size == 2 * (4 + 3)
    assert structure.n_supports == 3
    # Mid-span nodes sit at x = L / 2 + k L; the girder line finds them there.
    element, xi, on = structure.girder.locate(np.array([0.5 * L, 1.5 * L, 2.5 * L]))
    assert on.tolist() == [True, True, False]
    assert (element[:2] * structure.girder.element_length + xi[:2]
            * structure.girder.element_length) == pytest.approx([0.5 * L, 1.5 * L])
