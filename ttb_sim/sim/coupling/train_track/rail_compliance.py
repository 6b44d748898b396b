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
The local compliance of the rails under the wheels, probed once from the factorised track.

The effective track matrix K + 2/dt C + 4/dt^2 M is dominated by its mass term,
so its inverse is local: :class:`RailCompliance` keeps the 12 x 12 block of
K^-1 over every rail element (the rail's compliance at a wheel on it) and, for
the single-solve step, each rail node's K^-1 columns on the DOFs within a few
couplings of it, all from a few simultaneous probe solves.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ttb_sim.model.beam_line import BeamLine
from ttb_sim.sim.integrators.protocol import Integrator

PROBE_SPACING = 24
"""Rail nodes between simultaneous probes of the local track compliance."""
INFLUENCE_HOPS = 10
"""Couplings of the effective track matrix over which the single-solve step keeps each
rail node's K^-1 columns (measured on paper_ttbi: the columns fall to 3e-7 of their peak
8 couplings away, 3e-15 at 10)."""
INFLUENCE_PROBE_DISTANCE = 30.0
"""Least distance (m) between simultaneous probes when the K^-1 columns are kept: the
probes' responses reach each other through the slab and the girders. Measured error of
the predictor's rail motion under the wheels: paper_ttbi (0.31 m rail elements) 2e-7 m
with probes 15 m apart, 4e-12 m at 30 m; a one-span model (0.6 m) 8e-8 m at 15 m,
9e-13 m at 29 m."""
INFLUENCE_DROP = 1e-12
"""Entries of a node's K^-1 columns below this fraction of their largest are dropped
(on a one-span model 590 of 1 870 DOFs kept per node on average)."""


def gather(vector: np.ndarray, index: np.ndarray) -> np.ndarray:
    """
    Return ``vector`` extended by one zero (the ground slot) at extended free indices.

    Equal to ``np.append(vector, 0.0)[index]`` without copying the whole vector.
    """
    n = vector.shape[0]
    return np.where(index < n, vector[np.minimum(index, n - 1)], 0.0)


def rail_section_columns(rail: BeamLine) -> np.ndarray:
    """Return a rail's (n_el, 4) EA, GJ, EI_y, EI_z, for its interior flexibility."""
    sec = rail.section
    assert sec is not None, 'the rails carry their sections (build_track)'
    return np.ascontiguousarray(np.column_stack([sec.ea, sec.gj, sec.ei_y, sec.ei_z]),
                                dtype=float)


class RailCompliance:
    """
    Local blocks of the inverse effective track matrix over each rail element.

    Parameters
    ----------
    integrator : Integrator
        The factorised track-bridge system.
    rails : tuple of BeamLine
        Left and right rail (full DOFs).
    full_to_free : numpy.ndarray
        Extended free index of each full DOF.
    influence_hops : int, optional
        Also keep each rail node's K^-1 columns (its 6 DOFs) on the DOFs within
        this many couplings of the node in the effective matrix, where they
        exceed INFLUENCE_DROP of their largest (from the same probes, spaced
        INFLUENCE_PROBE_DISTANCE apart so that they do not disturb each other):
        :attr:`influence`. None (the reference) keeps only the blocks.

    """

    def __init__(self, integrator: Integrator, rails: tuple[BeamLine, ...],
                 full_to_free: np.ndarray, influence_hops: int | None = None) -> None:
        n_free = integrator.mass.shape[0]
        self.blocks = []
        self.influence: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        """Per rail: (start (n_nodes + 1,), DOFs (nnz,), values (nnz, 6)): node i's
        K^-1 columns on the DOFs ``dofs[start[i]:start[i + 1]]``."""
        for rail in rails:
            spacing = PROBE_SPACING
            if influence_hops is not None:
                spacing = max(spacing, math.ceil(INFLUENCE_PROBE_DISTANCE / rail.length.min()))
            dofs = full_to_free[rail.dofs]                     # (n_el, 12)
            nodes = np.vstack([dofs[:, :6], dofs[-1:, 6:]])    # (n_nodes, 6)
            n_nodes = nodes.shape[0]
            columns = _Columns(n_nodes)
            reach = sp.csc_matrix((n_free, n_nodes))
            if influence_hops is not None:
                reach = neighbourhoods(integrator, nodes, influence_hops)
            # cols[i, j, :] = K^-1 column of node i, DOF j, restricted to nodes i-1..i+1.
            local = np.zeros((n_nodes, 6, 3, 6))
            for offset in range(spacing):
                probe = np.arange(offset, n_nodes, spacing)
                rhs = np.zeros((n_free + 1, 6))
                for j in range(6):
                    rhs[nodes[probe, j], j] = 1.0
                sol = np.vstack([integrator.solve(rhs[:n_free]), np.zeros((1, 6))])
                if influence_hops is not None:
                    for p in probe.tolist():
                        near = reach.indices[reach.indptr[p]:reach.indptr[p + 1]]
                        columns.add(p, near, sol)
                for k, shift in enumerate((-1, 0, 1)):
                    at = np.clip(probe + shift, 0, n_nodes - 1)
                    local[probe, :, k, :] = sol[nodes[at]].transpose(0, 2, 1)
            # Element block B[e] over (node e, node e+1) x (node e, node e+1).
            n_el = n_nodes - 1
            b = np.zeros((n_el, 12, 12))
            e = np.arange(n_el)
            b[:, :6, :6] = local[e, :, 1, :].transpose(0, 2, 1)
            b[:, 6:, :6] = local[e, :, 2, :].transpose(0, 2, 1)
            b[:, :6, 6:] = local[e + 1, :, 0, :].transpose(0, 2, 1)
            b[:, 6:, 6:] = local[e + 1, :, 1, :].transpose(0, 2, 1)
            self.blocks.append(0.5 * (b + b.transpose(0, 2, 1)))
            if influence_hops is not None:
                self.influence.append(columns.arrays())

    def restricted(self, free_to_kept: np.ndarray, n_kept: int) -> RailCompliance:
        """
        Return this compliance on a subset of the free DOFs (a reduced model's).

        The element blocks stay as they are (they are indexed by rail element);
        each node's K^-1 columns keep their entries on kept DOFs, renumbered.
        Used where the kept DOFs solve the same model near the rails (the
        reduced track's window): the columns then differ only by what the
        condensed DOFs far away change, and the single-solve step's check
        corrects the rest.

        Parameters
        ----------
        free_to_kept : numpy.ndarray
            (n_free + 1,) the new index of each free DOF (and of the ground slot);
            ``n_kept`` where the DOF is not kept.
        n_kept : int
            Number of kept DOFs.

        """
        out = RailCompliance.__new__(RailCompliance)
        out.blocks = self.blocks
        out.influence = []
        for start, dofs, values in self.influence:
            new = free_to_kept[dofs]
            keep = new < n_kept
            node = np.repeat(np.arange(start.size - 1), np.diff(start))[keep]
            counts = np.bincount(node, minlength=start.size - 1)
            out.influence.append((np.concatenate([[0], np.cumsum(counts)]).astype(np.intp),
                                  new[keep].astype(np.intp),
                                  np.ascontiguousarray(values[keep])))
        return out


class _Columns:
    """Each rail node's K^-1 columns on its neighbourhood, the small entries dropped."""

    def __init__(self, n_nodes: int) -> None:
        self._dofs: list[np.ndarray] = [np.zeros(0, dtype=np.intp)] * n_nodes
        self._values: list[np.ndarray] = [np.zeros((0, 6))] * n_nodes

    def add(self, node: int, near: np.ndarray, solution: np.ndarray) -> None:
        """Keep the probe solution (n_free + 1, 6) of ``node`` on its DOFs ``near``."""
        values = solution[near]
        keep = np.any(np.abs(values) >= INFLUENCE_DROP * np.abs(values).max(), axis=1)
        self._dofs[node] = near[keep].astype(np.intp)
        self._values[node] = values[keep]

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Return (start (n_nodes + 1,), DOFs (nnz,), values (nnz, 6)), node after node."""
        counts = [d.size for d in self._dofs]
        start = np.concatenate([[0], np.cumsum(counts)]).astype(np.intp)
        return (start, np.concatenate(self._dofs),
                np.ascontiguousarray(np.concatenate(self._values)))


def neighbourhoods(integrator: Integrator, nodes: np.ndarray, hops: int) -> sp.csc_matrix:
    """
    Return the free DOFs within ``hops`` couplings of each node: column i holds node i's.

    Couplings are the non-zeros of the effective matrix (K, C, M).
    """
    n_free = integrator.mass.shape[0]
    pattern = (abs(integrator.stiffness) + abs(integrator.damping)
               + abs(integrator.mass)).tocsr()
    pattern.data[:] = 1.0
    n_nodes = nodes.shape[0]
    valid = nodes < n_free
    cols = np.repeat(np.arange(n_nodes), 6)[valid.ravel()]
    reach = sp.csr_matrix((np.ones(cols.size), (nodes.ravel()[valid.ravel()], cols)),
                          shape=(n_free, n_nodes))
    for _ in range(hops):
        reach = pattern @ reach + reach
        reach.data[:] = 1.0
    reach = reach.tocsc()
    reach.sort_indices()
    return reach
