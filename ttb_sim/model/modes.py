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
Natural modes of an assembled linear structure: the modes nearest a frequency.

The undamped pencil K phi = omega^2 M phi is solved by shift-invert Lanczos
about (2 pi f_c)^2 (ARPACK through scipy), so that a band of a large bridge
and track model is found without the modes below it. Shapes are mass
normalised (phi^T M phi = 1); the damping ratio of each mode is the diagonal
term of the projected damping, phi^T C phi / (2 omega), exact for
proportional damping and the usual estimate otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any

import numpy as np
import scipy.linalg as la
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ttb_sim.errors import ModelError


__all__ = ['DENSE_LIMIT', 'Modes', 'natural_modes']

DENSE_LIMIT = 400
"""Below this size, or when nearly every mode is asked for, the pencil is solved densely."""


@dataclass(frozen=True)
class Modes:
    """Modes of a structure, in increasing frequency."""

    frequencies: np.ndarray
    """Natural frequencies (Hz), shape (k,)."""
    damping_ratios: np.ndarray
    """phi^T C phi / (2 omega phi^T M phi), shape (k,)."""
    shapes: np.ndarray
    """Mass-normalised shapes over the free DOFs, shape (n, k)."""


def natural_modes(mass: Any, stiffness: Any, damping: Any, around: float,
                  count: int) -> Modes:
    """
    Return the ``count`` natural modes nearest ``around`` Hz.

    Parameters
    ----------
    mass, stiffness, damping : sparse or dense (n, n)
        Symmetric matrices over the free DOFs; M positive definite.
    around : float
        Centre frequency f_c (Hz), >= 0.
    count : int
        Number of modes, 1 <= count <= n.

    Raises
    ------
    ModelError
        For a count or centre outside those ranges.

    """
    n = mass.shape[0]
    if not (isinstance(count, (int, np.integer)) and 1 <= count <= n):
        raise ModelError(f'count = {count}: allowed values are 1 to {n} (the free DOFs)')
    if not (math.isfinite(around) and around >= 0.0):
        raise ModelError(f'around = {around}: allowed values are finite and >= 0 Hz')
    sigma = (2.0 * math.pi * around) ** 2
    if n <= DENSE_LIMIT or count >= n - 1:
        k_d, m_d = (a.toarray() if sp.issparse(a) else np.asarray(a) for a in (stiffness, mass))
        w2_all, phi_all = la.eigh(k_d, m_d)
        keep = np.sort(np.argsort(np.abs(w2_all - sigma))[:count])
        w2, phi = w2_all[keep], phi_all[:, keep]
    else:
        w2, phi = spla.eigsh(sp.csc_matrix(stiffness), k=count, M=sp.csc_matrix(mass),
                             sigma=sigma, which='LM')
        order = np.argsort(w2)
        w2, phi = w2[order], phi[:, order]
    modal_mass = np.einsum('ik,ik->k', phi, mass @ phi)
    phi = phi / np.sqrt(modal_mass)
    omega = np.sqrt(np.clip(w2, 0.0, None))
    modal_damping = np.einsum('ik,ik->k', phi, damping @ phi)
    with np.errstate(divide='ignore', invalid='ignore'):
        zeta = np.where(omega > 0, modal_damping / (2.0 * omega), np.nan)
    return Modes(omega / (2.0 * math.pi), zeta, phi)
