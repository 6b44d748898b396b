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

"""The reduction basis built class by class spans what the whole system's basis spans."""

import dataclasses
import math

import numpy as np
import pytest
import scipy.sparse as sp

from ttb_sim.fe.complex_solve import pardiso_available
from ttb_sim.model.foundation import krylov
from ttb_sim.model.foundation.mirror_classes import class_coordinates, invariant
from ttb_sim.model.foundation.records import (BlockSize, Cap, MeshSize, Observation, PileGroup,
                                              ReductionParameters, SoilLayer, SoilParameters,
                                              Substructure)
from ttb_sim.model.foundation.substructure import build
from ttb_sim.model.foundation.tied import cap_tie, tie_cap

LAYERS = (SoilLayer(2.0, 4e6, 0.35, 1835.0, 20e3, 5.0),
          SoilLayer(6.0, 6e6, 0.25, 1529.0, 10e3, 30.0))


def _tied(centre_x=0.0):
    spec = Substructure(
        soil=SoilParameters(LAYERS, BlockSize(10.0, 8.0), MeshSize(h=1.0, growth=1.5,
                                                                   h_max=3.0)),
        piles=PileGroup(rows=2, cols=2, spacing=3.0, side=0.8, length=4.0,
                        centre=(centre_x, 0.0)),
        cap=Cap(enabled=True, lx=5.0, ly=5.0, thickness=1.0),
        observation=Observation(line_points=3, val_points=False))
    return tie_cap(build(spec))


@pytest.fixture(scope='module')
def tied():
    return _tied()


def _whole(tied):
    return [krylov.MirrorPart(tuple(range(6)), sp.identity(tied.size, format='csr'),
                              tied.stiffness, tied.damping, tied.mass)]


def _flexibility(tied, psi, v, freqs):
    """Return the master's 6 x 6 dynamic flexibility of the Galerkin-reduced block."""
    phi = np.hstack([psi, np.vstack([np.zeros((6, v.shape[1])), v])])
    m, c, k = (phi.T @ (a @ phi) for a in (tied.mass, tied.damping, tied.stiffness))
    out = []
    for f in freqs:
        w = 2 * math.pi * f
        out.append(np.linalg.inv(k - w * w * m + 1j * w * c)[:6, :6])
    return np.array(out)


def test_a_centred_group_splits_into_four_classes_of_a_quarter(tied):
    parts = krylov.mirror_parts(tied)
    assert sorted(p.components for p in parts) == [(0, 4), (1, 3), (2,), (5,)]
    sizes = [p.coordinates.shape[1] for p in parts]
    # each class keeps about a quarter of the unknowns (those on the planes go to fewer)
    assert all(0.2 * tied.size < s < 0.3 * tied.size for s in sizes)


@pytest.mark.parametrize('axis', ['real', 'imaginary'])
def test_class_basis_gives_the_whole_systems_reduced_response(tied, monkeypatch, axis):
    """
    The class split is exact: the two reduced models' master flexibility agree to 1e-8.

    Krylov vectors of a class's loads lie in the class's unknowns when K, C and
    M keep the mirror, so the two bases span the same space up to round-off and
    deflation; 1e-8 is far below the reduction's own error (1e-4 at the least).
    """
    reduction = ReductionParameters(shifts=(0.0, 10.0), levels=3, shift_axis=axis)
    psi, v = krylov.reduction_basis(tied, reduction)
    monkeypatch.setattr(krylov, 'mirror_parts', _whole)
    psi_w, v_w = krylov.reduction_basis(tied, reduction)
    assert v.shape[1] == v_w.shape[1]
    np.testing.assert_allclose(psi, psi_w, rtol=0, atol=1e-9 * np.abs(psi_w).max())
    freqs = [0.0, 3.0, 7.0, 15.0]
    got, want = _flexibility(tied, psi, v, freqs), _flexibility(tied, psi_w, v_w, freqs)
    scale = np.abs(want).max(axis=(1, 2))[:, None, None]
    assert np.abs(got - want).max(axis=(1, 2)).max() < 1e-8 * scale.min()


def test_a_model_that_breaks_the_mirror_is_solved_whole(tied):
    """An asymmetric stiffness (one DOF stiffened) fails the invariance check."""
    parts = krylov.mirror_parts(tied)
    assert all(invariant((tied.stiffness, tied.damping, tied.mass), p.coordinates)
               for p in parts)
    bump = sp.csr_matrix(([1e9], ([40], [40])), shape=tied.stiffness.shape)
    broken = dataclasses.replace(tied, stiffness=(tied.stiffness + bump).tocsr())
    assert not all(invariant((broken.stiffness,), p.coordinates) for p in parts)
    assert [p.components for p in krylov.mirror_parts(broken)] == [tuple(range(6))]


def test_a_group_off_centre_in_x_splits_about_y_only():
    """The mirror about x = 0 is lost; the one about y = 0 still splits the master in two."""
    off = _tied(centre_x=0.5)
    assert sorted(p.components for p in krylov.mirror_parts(off)) == [(0, 2, 4), (1, 3, 5)]


def test_class_coordinates_pick_the_components_and_tie_mirror_pairs(tied):
    assert np.array_equal(tied.kept, cap_tie(tied.model)[1])
    p = class_coordinates(tied.model, tied.kept, (2,), ())
    assert p.shape == (tied.size, 1 + len(tied.kept))
    assert p[2, 0] == 1.0 and p[:6, 0].sum() == 1.0


@pytest.mark.skipif(not pardiso_available(), reason='MKL PARDISO not installed (pip install '
                    'ttb_sim[pardiso]): the positive definite pencils go to CHOLMOD alone')
def test_pardiso_and_cholmod_pencils_give_the_same_reduced_response(tied, monkeypatch):
    """The two Cholesky factorisations of the static and real-shift pencils agree to 1e-8."""
    reduction = ReductionParameters(shifts=(0.0, 10.0), levels=3)
    assert krylov.positive_definite_method() == 'pardiso'
    psi, v = krylov.reduction_basis(tied, reduction)
    monkeypatch.setattr(krylov, 'pardiso_available', lambda: False)
    assert krylov.positive_definite_method() == 'cholmod'
    psi_c, v_c = krylov.reduction_basis(tied, reduction)
    freqs = [0.0, 3.0, 7.0, 15.0]
    got, want = _flexibility(tied, psi, v, freqs), _flexibility(tied, psi_c, v_c, freqs)
    scale = np.abs(want).max(axis=(1, 2))
    assert (np.abs(got - want).max(axis=(1, 2)) < 1e-8 * scale).all()
