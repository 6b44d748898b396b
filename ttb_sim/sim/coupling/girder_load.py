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
Loads and rows of points on beams, for the lean solver variants.

:class:`MovingLoad` gives the free-DOF load of constant axle forces on the
girders (moving forces, quarter cars) and :func:`point_rows_and_slopes` the
rows of points on a beam with their slopes (the rail head under the wheels).
Each computes what a general routine of the reference path computes, with
fewer numpy calls and no full-size temporaries, for the one case a time step
needs; results agree with the reference to round-off. Each was kept because a
profile showed it wins (docs/performance.md).
"""

from __future__ import annotations

import numpy as np

from ttb_sim.fe.beam import hermite, offset_rows, V_DOFS, W_DOFS
from ttb_sim.model.bridge import GirderLine
from ttb_sim.sim.kernel_registry import KernelTable

_W_SIGN = np.array([1.0, -1.0, 1.0, -1.0])
"""Signs that turn Hermite functions into the (uz, ry) row (ry = -w')."""


def point_rows_and_slopes(xi: np.ndarray, length: np.ndarray,
                          arm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """
    Return ``point_rows(xi, length, arm)`` and its x-derivative, bit for bit.

    :func:`ttb_sim.fe.beam.point_rows` evaluates the Hermite functions four
    times per call, eight for the pair; here each derivative order (0, 1, 2)
    is evaluated once and shared (the same elementwise operations, so the same
    numbers). The rail-head rows under every wheel need the pair at each step.

    Parameters
    ----------
    xi, length : numpy.ndarray
        Local coordinate and element length, shape (n,).
    arm : numpy.ndarray
        Offset of the points from the beam axis, (3,) (m).

    Returns
    -------
    (rows, slopes)
        Each (n, 3, 12).

    """
    xi = np.asarray(xi, dtype=float)
    length = np.broadcast_to(np.asarray(length, dtype=float), xi.shape)
    h = [hermite(xi, length, d) for d in range(3)]
    fields = np.zeros((2,) + xi.shape + (6, 12))
    linear = (np.stack([1.0 - xi, xi], axis=-1),
              np.stack([-1.0 / length, 1.0 / length], axis=-1))
    for k in range(2):
        out = fields[k]
        out[..., 0, [0, 6]] = linear[k]
        out[..., 3, [3, 9]] = linear[k]
        out[..., 1, V_DOFS] = h[k]
        out[..., 2, W_DOFS] = h[k] * _W_SIGN
        out[..., 4, W_DOFS] = -(h[k + 1] * _W_SIGN)
        out[..., 5, V_DOFS] = h[k + 1]
    rows = offset_rows(fields, arm)
    return rows[0], rows[1]


class MovingLoad:
    """
    Load vectors of constant vertical axle forces on the girders.

    The reference path assembles the full-DOF load with the general girder
    lookup and then gathers the free DOFs; this evaluates the cubic Hermite
    rows inline and sums straight into the free DOFs (measured 68 -> 29 us per
    step on ten_span_train, 32 axles). With numba the free-DOF load is one
    compiled loop into a preallocated vector (:func:`moving_load`, the same
    arithmetic). The full-DOF load (support reactions) is only needed
    at output frames: :meth:`full`.

    Parameters
    ----------
    girder : GirderLine
        The girders (uniform elements).
    forces : numpy.ndarray
        (n_axles,) downward force of each axle (N).
    n_free : int
        Number of free DOFs.
    n_full : int
        Number of all DOFs.

    """

    def __init__(self, girder: GirderLine, forces: np.ndarray, n_free: int,
                 n_full: int) -> None:
        self._h = girder.element_length
        self._n_el = girder.n_spans * girder.elements_per_span
        self._length = girder.length
        self._dofs = girder.w_dofs
        self._dofs_full = girder.w_dofs_full
        self._forces = np.asarray(forces, dtype=float)
        self._n_free = n_free
        self._n_full = n_full
        self._kernel = KERNELS.compiled('moving_load')
        self._out = np.zeros(n_free + 1)

    def __call__(self, positions: np.ndarray) -> np.ndarray:
        """
        Return the (n_free,) load of the axles at ``positions`` (m along the track).

        With the compiled kernel the result is a view of a work vector that the
        next call overwrites.
        """
        if self._kernel is not None:
            self._kernel(np.asarray(positions, dtype=float), self._forces, float(self._h),
                         self._n_el, float(self._length), self._dofs, self._out)
            return self._out[:self._n_free]
        element, rows = self._rows(positions)
        load = np.bincount(self._dofs[element].ravel(), weights=rows.ravel(),
                           minlength=self._n_free + 1)
        return load[:self._n_free]

    def full(self, positions: np.ndarray) -> np.ndarray:
        """Return the (n_full,) load on all DOFs, for the support reactions of a frame."""
        if self._kernel is not None:
            out = np.empty(self._n_full)
            self._kernel(np.asarray(positions, dtype=float), self._forces, float(self._h),
                         self._n_el, float(self._length), self._dofs_full, out)
            return out
        element, rows = self._rows(positions)
        return np.bincount(self._dofs_full[element].ravel(), weights=rows.ravel(),
                           minlength=self._n_full)

    def _rows(self, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the element under each axle and its force-weighted row (n, 4)."""
        h = self._h
        s = positions / h
        element = np.minimum(np.maximum(np.floor(s), 0.0), self._n_el - 1).astype(np.intp)
        xi = np.minimum(np.maximum(s - element, 0.0), 1.0)
        on = (positions >= 0.0) & (positions <= self._length)
        weight = np.where(on, -self._forces, 0.0)
        xi2 = xi * xi
        xi3 = xi2 * xi
        rows = np.empty((positions.size, 4))
        rows[:, 0] = 1.0 - 3.0 * xi2 + 2.0 * xi3
        rows[:, 1] = (xi3 - 2.0 * xi2 + xi) * -h
        rows[:, 2] = 3.0 * xi2 - 2.0 * xi3
        rows[:, 3] = (xi3 - xi2) * -h
        rows *= weight[:, None]
        return element, rows


def moving_load(positions: np.ndarray, forces: np.ndarray, h: float, n_el: int,
                length: float, dofs: np.ndarray, out: np.ndarray) -> None:
    """
    Sum the consistent load of vertical axle forces on the girder into ``out``.

    The same arithmetic as :meth:`MovingLoad._rows` followed
    by ``np.bincount``, axle by axle.
    """
    out[:] = 0.0
    for i in range(positions.shape[0]):
        x = positions[i]
        s = x / h
        e = min(max(np.floor(s), 0.0), n_el - 1)
        element = int(e)
        xi = min(max(s - e, 0.0), 1.0)
        if x >= 0.0 and x <= length:
            weight = -forces[i]
        else:
            weight = 0.0
        xi2 = xi * xi
        xi3 = xi2 * xi
        r0 = (1.0 - 3.0 * xi2 + 2.0 * xi3) * weight
        r1 = ((xi3 - 2.0 * xi2 + xi) * -h) * weight
        r2 = (3.0 * xi2 - 2.0 * xi3) * weight
        r3 = ((xi3 - xi2) * -h) * weight
        out[dofs[element, 0]] += r0
        out[dofs[element, 1]] += r1
        out[dofs[element, 2]] += r2
        out[dofs[element, 3]] += r3


KERNELS = KernelTable({'moving_load': moving_load})
"""The compiled girder load."""
