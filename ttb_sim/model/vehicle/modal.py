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

"""Modal analysis of the car matrices: eigenfrequencies and projected damping ratios."""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import scipy.linalg


def eigenfrequencies(
        mass: np.ndarray, stiffness: np.ndarray,
        subset: Sequence[int] | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """
    Return undamped eigenfrequencies and modes of a DOF subset.

    DOFs outside ``subset`` are held fixed (e.g. pass the vertical DOFs of the
    car body and bogies to get the modes with the wheelsets fixed).

    Parameters
    ----------
    mass, stiffness : numpy.ndarray
        Full square matrices.
    subset : sequence of int, optional
        DOF indices kept free; all DOFs if omitted.

    Returns
    -------
    frequencies : numpy.ndarray
        Ascending frequencies (Hz); tiny negative eigenvalues are clipped to 0.
    modes : numpy.ndarray
        Shape (n_dof, n_subset): mass-normalised mode shapes expanded to the
        full DOF vector (zeros on held DOFs), column i for frequency i.

    """
    n = mass.shape[0]
    idx = np.arange(n) if subset is None else np.asarray(subset, dtype=int)
    k = stiffness[np.ix_(idx, idx)]
    m = mass[np.ix_(idx, idx)]
    lam, vec = scipy.linalg.eigh(0.5 * (k + k.T), 0.5 * (m + m.T))
    freq = np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * math.pi)
    modes = np.zeros((n, idx.size))
    modes[idx] = vec
    return freq, modes


def modal_damping_ratios(
        mass: np.ndarray, damping: np.ndarray, stiffness: np.ndarray,
        subset: Sequence[int] | np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """
    Return damping ratios of the undamped modes, zeta_i = phi_i^T C phi_i / (2 omega_i).

    This projection neglects the coupling of modes by non-proportional
    damping; it is the usual way to quote a suspension's damping ratio.

    Parameters
    ----------
    mass, damping, stiffness : numpy.ndarray
        Full square matrices.
    subset : sequence of int, optional
        DOF indices kept free (others held fixed).

    Returns
    -------
    frequencies : numpy.ndarray
        Undamped frequencies (Hz), ascending.
    ratios : numpy.ndarray
        Damping ratio per mode (-); NaN for zero-frequency modes.

    """
    freq, modes = eigenfrequencies(mass, stiffness, subset)
    omega = 2.0 * math.pi * freq
    proj = np.einsum('ij,ik,kj->j', modes, damping, modes)
    with np.errstate(divide='ignore', invalid='ignore'):
        ratios = np.where(omega > 0.0, proj / (2.0 * omega), np.nan)
    return freq, ratios
