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
A beam along the track (x) for point lookups: :class:`BeamLine`.

The girders, rails, slabs and base plates are each a line of 3-D beam
elements along x, possibly in separate units; a beam line finds the element
and local coordinate under a position and gives the rows of the motion of
points at an arm from the beam axis, for sensors, wheel contacts and the
spring links between beams.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ttb_sim.fe.beam import BeamSection, field_rows, offset_rows, point_rows


@dataclass(frozen=True)
class BeamLine:
    """
    Elements of one beam along x (possibly in separate units), for point lookups.

    Attributes
    ----------
    start : numpy.ndarray
        (n_el,) x of each element's first node (ascending).
    length : numpy.ndarray
        (n_el,) element lengths (m).
    dofs : numpy.ndarray
        (n_el, 12) full DOF indices of each element.
    z : float
        Height of the beam axis (m).
    y : float
        Lateral position of the beam axis (m).
    section : BeamSection or None
        Section of each element (the rails carry theirs: a wheel load inside an
        element deflects it beyond the nodes' interpolation,
        :func:`ttb_sim.fe.beam.interior_compliance`).

    """

    start: np.ndarray
    length: np.ndarray
    dofs: np.ndarray
    z: float
    y: float = 0.0
    section: BeamSection | None = None

    @property
    def end(self) -> float:
        """Return x of the last node (m)."""
        return float(self.start[-1] + self.length[-1])

    def locate(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return (element, xi, inside) for positions x along the track.

        ``inside`` is False in the gaps between units and beyond the ends; the
        element is then the nearest one to the left (or the first).
        """
        x = np.asarray(x, dtype=float)
        element = np.clip(np.searchsorted(self.start, x, side='right') - 1, 0,
                          self.start.size - 1)
        local = x - self.start[element]
        inside = (local >= 0.0) & (local <= self.length[element] * (1 + 1e-12))
        xi = np.clip(local / self.length[element], 0.0, 1.0)
        return element, xi, inside

    def rows(self, x: np.ndarray, arm: np.ndarray,
             derivative: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return the rows of the motion of points at ``arm`` from the beam axis.

        Returns
        -------
        (element, rows (n, 3, 12), inside); rows are zero outside the beam.

        """
        element, xi, inside = self.locate(x)
        r = point_rows(xi, self.length[element], arm, derivative)
        return element, r * inside[:, None, None], inside

    def link_rows(self, x: np.ndarray, arm: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Return what a spring link needs from points at ``arm`` from the beam axis.

        Returns
        -------
        (full DOFs (n, 12), rows (n, 4, 12) of the x, y, z motion and the roll,
        inside); rows are zero outside the beam.

        """
        element, xi, inside = self.locate(x)
        f = field_rows(xi, self.length[element])
        rows = np.concatenate([offset_rows(f, arm), f[:, 3:4, :]], axis=1)
        return self.dofs[element], rows * inside[:, None, None], inside
