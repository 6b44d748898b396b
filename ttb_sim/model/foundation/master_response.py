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
What a piled pier's column stands on: the dynamic flexibility at the cap's master.

A bridge sees its piled pier's soil only through the 6-DOF master at the
centre of the cap top (:func:`~.tied.cap_tie`), on which the pier column
stands. :func:`master_response` loads the tied, *unreduced* substructure with a
unit force (or moment) along each master component and solves it in the
frequency domain, optionally inside a perfectly matched layer
(:class:`~.frequency_response.MatchedLayer`): the reference.
:func:`dense_master_response` does the same for a small dense model, such as
the reduced substructure the time stepping uses
(:func:`~.reduction.substructure_block`), so the two can be compared entry by
entry (:func:`master_errors`).

The components split into mirror-symmetry classes (a centred group: uz; ux with
ry; uy with rx; rz), each solved on its own part of the unknowns
(:mod:`ttb_sim.fe.symmetry`), exactly.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import logging
import math
import time
from typing import Callable, Optional, Sequence

import numpy as np
import scipy.sparse as sp

from ttb_sim.fe.complex_solve import factorize_complex
from ttb_sim.fe.symmetry import MirrorPlane
from ttb_sim.model.foundation.frequency_response import (DynamicStiffness, MatchedLayer,
                                                         SymmetryChoice, with_matched_layer)
from ttb_sim.model.foundation.mirror_classes import class_coordinates, symmetry_classes
from ttb_sim.model.foundation.records import FoundationError, Substructure
from ttb_sim.model.foundation.substructure import build, PileSoilModel
from ttb_sim.model.foundation.tied import cap_tie

log = logging.getLogger(__name__)

MASTER_COMPONENTS = ('ux', 'uy', 'uz', 'rx', 'ry', 'rz')
"""The master's coordinates: displacements (m) and rotations (rad) about x, y, z."""


@dataclass
class MasterResponse:
    """
    Responses of the tied substructure to unit master forces, per frequency.

    Attributes
    ----------
    frequencies : array (n_f,)
        Hz.
    flexibility : complex array (n_f, 6, 6)
        Master displacement (column j: per unit force or moment along
        component j), m/N, rad/N, m/(N m), rad/(N m).
    heads : complex array (n_f, n_piles, 3, 6)
        Pile-head mean displacement per unit master force j.
    points : complex array (n_f, n_points, 3, 6)
        Soil-point displacement per unit master force j.
    point_names : tuple of str
        Names of the soil points.
    unknowns : tuple of int
        Unknowns of each symmetry class's solve (the coordinates, for a dense model).
    method : str
        Solver.
    seconds : list of float
        Wall time of each frequency (s).

    """

    frequencies: np.ndarray
    flexibility: np.ndarray
    heads: np.ndarray
    points: np.ndarray
    point_names: tuple[str, ...]
    unknowns: tuple[int, ...]
    method: str
    seconds: list[float] = field(default_factory=list)

    def impedance(self) -> np.ndarray:
        """Return the master's dynamic stiffness Z = flexibility^-1, shape (n_f, 6, 6)."""
        return np.linalg.inv(self.flexibility)

    def head_transfer(self) -> np.ndarray:
        """Return pile-head displacement per unit master displacement, (n_f, n_piles, 3, 6)."""
        return np.einsum('fpaj,fjk->fpak', self.heads, self.impedance())

    def point_transfer(self) -> np.ndarray:
        """Return soil-point displacement per unit master displacement, (n_f, n_pts, 3, 6)."""
        return np.einsum('fpaj,fjk->fpak', self.points, self.impedance())


def class_basis(model: PileSoilModel, transform: sp.csr_matrix, kept: np.ndarray,
                components: Sequence[int], planes: tuple[MirrorPlane, ...]) -> sp.csr_matrix:
    """
    Return S (n_dofs x n): all DOFs from [the class's master components, its interior part].

    The interior part is the mirror reduction of the tie's free DOFs off the cap top.
    """
    return (transform @ class_coordinates(model, kept, components, planes)).tocsr()


def master_response(spec: Substructure, frequencies: Sequence[float], *,
                    layer: Optional[MatchedLayer] = None, symmetry: SymmetryChoice = 'auto',
                    method: str = 'auto',
                    progress: Optional[Callable[[int, float, float], None]] = None
                    ) -> MasterResponse:
    """
    Return the unreduced tied substructure's responses to unit master forces.

    Parameters
    ----------
    spec : Substructure
        A piled pier's soil, piles and cap (enabled).
    frequencies : sequence of float
        Hz; > 0 with a matched layer, >= 0 otherwise.
    layer : MatchedLayer, optional
        Wrap the block in it (the scenario's boundary is then not used).
    symmetry : {'auto', 'none'}
        Solve each mirror-symmetry class on its own part of the unknowns, or all
        six components on all of them.
    method : str
        Complex sparse solver (:data:`ttb_sim.fe.complex_solve.METHODS`).
    progress : callable, optional
        Called as ``progress(index, frequency, seconds)`` after each frequency.

    """
    freqs = _checked(frequencies, layer is not None)
    model = build(with_matched_layer(spec, layer) if layer is not None else spec)
    operator = DynamicStiffness(model, layer, spec.soil if layer is not None else None)
    transform, kept, _ = cap_tie(model)
    classes = [(comps, class_basis(model, transform, kept, comps, planes))
               for comps, planes in (symmetry_classes(model, transform) if symmetry == 'auto'
                                     else [(tuple(range(6)), ())])]
    n_piles = model.head_displacement.shape[0] // 3
    n_points = model.soil_points.operator.shape[0] // 3
    out = _empty(len(freqs), n_piles, n_points)
    seconds: list[float] = []
    chosen = method
    for i, f in enumerate(freqs):
        start = time.perf_counter()
        z = operator.matrix(2.0 * math.pi * f)
        for comps, basis in classes:
            factor = factorize_complex((basis.T @ z @ basis).tocsr(), method)
            chosen = factor.method
            k = len(comps)
            rhs = np.zeros((basis.shape[1], k), dtype=complex)
            rhs[:k] = np.eye(k)
            y = factor.solve(rhs)
            del factor
            u = basis @ y
            _store(out, i, comps, y[:k], model.head_displacement @ u,
                   model.soil_points.operator @ u)
        seconds.append(time.perf_counter() - start)
        if progress is not None:
            progress(i, float(f), seconds[-1])
    return MasterResponse(freqs, *out, tuple(model.soil_points.names),
                          tuple(int(b.shape[1]) for _, b in classes), chosen, seconds)


def dense_master_response(mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray,
                          heads: np.ndarray, points: np.ndarray,
                          frequencies: Sequence[float],
                          point_names: Sequence[str] = ()) -> MasterResponse:
    """
    Return the responses of a dense model whose first 6 coordinates are the master.

    ``heads`` (3 n_piles x n) and ``points`` (3 n_points x n) are its output rows.
    """
    freqs = _checked(frequencies, False)
    n = mass.shape[0]
    out = _empty(len(freqs), heads.shape[0] // 3, points.shape[0] // 3)
    rhs = np.zeros((n, 6))
    rhs[:6] = np.eye(6)
    comps = tuple(range(6))
    seconds: list[float] = []
    for i, f in enumerate(freqs):
        start = time.perf_counter()
        w = 2.0 * math.pi * f
        y = np.linalg.solve(stiffness - (w * w) * mass + (1j * w) * damping, rhs)
        _store(out, i, comps, y[:6], heads @ y, points @ y)
        seconds.append(time.perf_counter() - start)
    return MasterResponse(freqs, *out, tuple(point_names), (n,), 'dense', seconds)


def master_errors(model: MasterResponse, reference: MasterResponse) -> dict[str, np.ndarray]:
    """
    Return |model / reference - 1| per frequency for what the bridge and the streams see.

    Keys: the impedance's diagonal ('Z_ux' ... 'Z_rz') and the sway-rocking
    couplings ('Z_ux_ry', 'Z_uy_rx'); the central pile head along x and z per
    unit master motion along x and z ('head_x', 'head_z'), and each soil point
    along z per unit master uz ('<name>_z'), as |difference| / |reference|.
    """
    if not np.allclose(model.frequencies, reference.frequencies):
        raise FoundationError('the two responses are at different frequencies')
    za, zb = model.impedance(), reference.impedance()
    out: dict[str, np.ndarray] = {}
    for j, name in enumerate(MASTER_COMPONENTS):
        out[f'Z_{name}'] = np.abs(za[:, j, j] / zb[:, j, j] - 1.0)
    for a, b in ((0, 4), (1, 3)):
        out[f'Z_{MASTER_COMPONENTS[a]}_{MASTER_COMPONENTS[b]}'] = np.abs(
            za[:, a, b] / zb[:, a, b] - 1.0)
    ha, hb = model.head_transfer(), reference.head_transfer()
    centre = ha.shape[1] // 2
    for axis, comp in ((0, 0), (2, 2)):
        ref = hb[:, centre, axis, comp]
        out['head_' + 'xyz'[axis]] = np.abs(ha[:, centre, axis, comp] - ref) / np.abs(ref)
    pa, pb = model.point_transfer(), reference.point_transfer()
    for k, name in enumerate(reference.point_names):
        ref = pb[:, k, 2, 2]
        out[f'{name}_z'] = np.abs(pa[:, k, 2, 2] - ref) / np.abs(ref)
    return out


def _checked(frequencies: Sequence[float], matched: bool) -> np.ndarray:
    freqs = np.asarray(frequencies, dtype=float)
    if freqs.ndim != 1 or len(freqs) == 0 or not np.all(np.isfinite(freqs)) or \
            np.any(freqs < 0):
        raise FoundationError('frequencies must be a non-empty list of finite values >= 0 Hz')
    if matched and np.any(freqs <= 0):
        raise FoundationError('a matched layer needs frequencies above 0 Hz')
    return freqs


def _empty(n_f: int, n_piles: int, n_points: int
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (np.zeros((n_f, 6, 6), dtype=complex), np.zeros((n_f, n_piles, 3, 6), dtype=complex),
            np.zeros((n_f, n_points, 3, 6), dtype=complex))


def _store(out: tuple[np.ndarray, np.ndarray, np.ndarray], i: int, comps: Sequence[int],
           master: np.ndarray, heads: np.ndarray, points: np.ndarray) -> None:
    flexibility, head_out, point_out = out
    idx = np.asarray(comps)
    flexibility[i][np.ix_(idx, idx)] = master
    head_out[i][..., idx] = heads.reshape(head_out.shape[1], 3, -1)
    point_out[i][..., idx] = points.reshape(point_out.shape[1], 3, -1)
