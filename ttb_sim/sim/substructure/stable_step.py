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
The implicit-explicit partition of a pile-soil block and the explicit stable step.

``scheme='mixed'`` makes the soil cells and the boundary explicit and the
piles, cap and interface implicit (:func:`implicit_dofs`); ``'implicit'``
makes every DOF implicit, and ``'auto'`` picks one by the model's size
(:func:`choose_scheme`). With every group implicit the Newmark average
acceleration method is unconditionally stable; explicit groups are stable for
omega_max dt <= 2, reduced by their stiffness-proportional damping
(:func:`stable_time_step`). :func:`explicit_omega_max` bounds omega_max of
the soil cells element by element, and :func:`mixed_stable_step` combines the
two into the step the mixed scheme may take.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
import scipy.sparse.linalg as sla

from ttb_sim.fe import hex8
from ttb_sim.model.foundation.substructure import PileSoilModel, rayleigh_coefficients

Scheme = Literal['auto', 'mixed', 'implicit']


def implicit_dofs(model: PileSoilModel) -> np.ndarray:
    """Return a mask of the DOFs of pile and cap cells and of interface elements."""
    mask = model.structure_dofs.copy()
    if model.interface is not None:
        mask[np.unique(model.interface.relative.indices)] = True
    return mask


def choose_scheme(model: PileSoilModel, scheme: Scheme) -> Literal['mixed', 'implicit']:
    """Resolve 'auto': mixed above 20 000 free DOFs (with piles or soil), else implicit."""
    if scheme == 'auto':
        return 'mixed' if int(model.free.sum()) > 20000 else 'implicit'
    return scheme


def explicit_omega_max(model: PileSoilModel) -> float:
    """
    Return an upper bound of the largest circular frequency (rad/s) of the soil cells.

    The largest eigenvalue of the assembled lumped-mass system is bounded by the
    largest over elements of each element's own K_e / m_e problem (element
    eigenvalue inequality; the assembled nodal masses are at least the
    element's). The structured soil cells are bricks, so the bound is taken
    over the distinct (dx, dy, dz, layer) combinations; boundary springs are
    added per node. Periodic columns (merged nodes) fall back on Lanczos.
    """
    mesh = model.mesh
    soil = mesh.cell_sets['soil']
    x = mesh.nodes[mesh.cells[soil]]
    span = x.max(axis=1) - x.min(axis=1)
    if model.spec.soil.periodic or np.any(span <= 0):
        free = np.flatnonzero(model.free)
        k = (model.soil_stiffness + model.boundary_stiffness).tocsr()[free][:, free]
        scale = 1.0 / np.sqrt(model.mass[free])
        op = sla.LinearOperator(k.shape, matvec=lambda v: scale * (k @ (scale * v)),
                                dtype=float)
        value = sla.eigsh(op, k=1, which='LA', tol=1e-4, return_eigenvectors=False,
                          ncv=min(40, len(free) - 1))[0]
        return float(math.sqrt(value) * 1.001)
    key = np.column_stack([np.round(span, 6), mesh.material[soil]])
    unique = np.unique(key, axis=0)
    layers = model.spec.soil.layers
    young = np.array([layers[int(m)].E for m in unique[:, 3]])
    poisson = np.array([layers[int(m)].nu for m in unique[:, 3]])
    rho = np.array([layers[int(m)].rho for m in unique[:, 3]])
    coords = (hex8.CORNERS[None] + 1.0) / 2.0 * unique[:, None, :3]
    k_e = hex8.stiffness(coords, young, poisson)
    m_e = np.repeat(hex8.lumped_mass(coords, rho), 3, axis=1)
    scaled = k_e / np.sqrt(m_e[:, :, None] * m_e[:, None, :])
    omega2 = float(np.linalg.eigvalsh(scaled)[:, -1].max())
    boundary = model.boundary_stiffness.diagonal() / model.mass
    return float(math.sqrt(omega2 + float(boundary.max(initial=0.0))) * 1.01)


def stable_time_step(omega: float, alpha: float, beta: float, safety: float = 0.9) -> float:
    """
    Return the largest stable step (s) of the explicit predictor-corrector at omega.

    The undamped limit is omega dt = 2; Rayleigh damping c = alpha + beta omega^2
    evaluated with the predicted velocity lowers it. Found by bisection on the
    spectral radius of the one-DOF amplification matrix, times ``safety``.
    """
    c = alpha + beta * omega**2

    def radius(dt: float) -> float:
        amp = np.zeros((3, 3))
        for j in range(3):
            u, v, a = np.eye(3)[j]
            ut = u + dt * v + dt * dt / 4 * a
            vt = v + dt / 2 * a
            an = -omega**2 * ut - c * vt
            amp[:, j] = [ut + dt * dt / 4 * an, vt + dt / 2 * an, an]
        return float(max(abs(np.linalg.eigvals(amp))))

    lo, hi = 0.0, 2.0 / omega
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if radius(mid) <= 1.0 + 1e-12:
            lo = mid
        else:
            hi = mid
    return safety * lo


def mixed_stable_step(model: PileSoilModel) -> float:
    """Return the stable step (s) of the explicit soil in the mixed scheme."""
    zeta = np.array([layer.damping_ratio for layer in model.spec.soil.layers])
    alpha, beta = rayleigh_coefficients(zeta, model.spec.rayleigh_frequencies)
    return stable_time_step(explicit_omega_max(model), float(alpha.min()), float(beta.max()))
