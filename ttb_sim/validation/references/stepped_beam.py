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
Exact bending frequencies and static deflection of a stepped simply supported beam.

The continuum reference of V23 (damage), written without the package's finite
elements: each segment of constant EI and mass per length m is an exact
Euler-Bernoulli field transfer matrix in the Krylov-Duncan functions of beta x,
beta^4 = m omega^2 / EI, acting on the state (w, w', EI w'', EI w''') (continuous at
the steps). The simply supported ends (w = M = 0) leave a 2 x 2 determinant in omega
whose roots are the natural frequencies; they are bracketed on a scan and refined by
Brent's method (Pestel & Leckie, Matrix Methods in Elastomechanics, 1963, ch. 5). The
static mid-span deflection under a mid-span point load is the virtual-work integral
of M m / EI, done exactly segment by segment.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Sequence

import numpy as np
from scipy.optimize import brentq

__all__ = ['SteppedBeam']


@dataclass(frozen=True)
class SteppedBeam:
    """A simply supported beam of segments, each with its own EI (uniform mass)."""

    lengths: tuple[float, ...]
    """Segment lengths from the left support (m)."""
    stiffness: tuple[float, ...]
    """Bending stiffness EI of each segment (N m^2)."""
    mass_per_length: float
    """Mass per length (kg/m), the same on every segment."""

    @classmethod
    def with_zones(cls, span: float, ei: float, mass: float,
                   zones: Sequence[tuple[float, float, float]]) -> SteppedBeam:
        """
        Return a span of stiffness ``ei`` with zones (start, end, loss) of EI (1 - loss).

        Zones must lie inside the span and not overlap.
        """
        cuts = [0.0]
        values = []
        for start, end, loss in sorted(zones):
            if start > cuts[-1]:
                cuts.append(start)
                values.append(ei)
            cuts.append(end)
            values.append(ei * (1.0 - loss))
        if cuts[-1] < span:
            cuts.append(span)
            values.append(ei)
        return cls(tuple(float(b - a) for a, b in zip(cuts[:-1], cuts[1:])), tuple(values),
                   mass)

    @property
    def length(self) -> float:
        """Span (m)."""
        return float(sum(self.lengths))

    def determinant(self, omega: float) -> float:
        """Return the simply supported frequency determinant at omega (rad/s)."""
        t = np.eye(4)
        for length, ei in zip(self.lengths, self.stiffness):
            t = _segment(length, ei, self.mass_per_length, omega) @ t
        # start (0, theta, 0, Q): columns 1 and 3; end w = 0 and M = 0: rows 0 and 2
        return float(t[0, 1] * t[2, 3] - t[0, 3] * t[2, 1])

    def frequencies(self, count: int = 1, points_per_mode: int = 200) -> np.ndarray:
        """Return the lowest ``count`` natural frequencies in Hz."""
        ei_min = min(self.stiffness)
        ei_max = max(self.stiffness)
        scale = math.pi**2 / self.length**2 / math.sqrt(self.mass_per_length)
        w_lo = 0.5 * scale * math.sqrt(ei_min)
        w_hi = 1.5 * (count + 0.5)**2 * scale * math.sqrt(ei_max)
        grid = np.linspace(w_lo, w_hi, points_per_mode * (count + 1)**2)
        values = np.array([self.determinant(w) for w in grid])
        roots: list[float] = []
        for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:])):
            roots.append(brentq(self.determinant, grid[i], grid[i + 1], xtol=1e-14,
                                rtol=1e-15, maxiter=200))
            if len(roots) == count:
                break
        if len(roots) < count:  # pragma: no cover - the scan covers the band
            raise RuntimeError(f'found {len(roots)} of {count} roots below {w_hi:g} rad/s')
        return np.array(roots) / (2.0 * math.pi)

    def midspan_deflection(self, force: float) -> float:
        """Return the mid-span deflection (m) under a mid-span point load (N), by virtual work."""
        half = 0.5 * self.length
        total = 0.0
        x0 = 0.0
        for length, ei in zip(self.lengths, self.stiffness):
            x1 = x0 + length
            # M m = (F x / 2)(x / 2) on the left half, mirrored on the right: int x^2 / 4
            for a, b, mirror in ((x0, min(x1, half), False), (max(x0, half), x1, True)):
                if b > a:
                    lo, hi = (self.length - b, self.length - a) if mirror else (a, b)
                    total += force * (hi**3 - lo**3) / 12.0 / ei
            x0 = x1
        return total


def _segment(length: float, ei: float, mass: float, omega: float) -> np.ndarray:
    """Return the field transfer matrix of (w, w', EI w'', EI w''') over one segment."""
    beta = (mass * omega**2 / ei) ** 0.25
    z = beta * length
    ch, c, sh, s = math.cosh(z), math.cos(z), math.sinh(z), math.sin(z)
    k_s, k_t, k_u, k_v = 0.5 * (ch + c), 0.5 * (sh + s), 0.5 * (ch - c), 0.5 * (sh - s)
    b = beta
    a = np.array([[k_s, k_t / b, k_u / b**2, k_v / b**3],
                  [b * k_v, k_s, k_t / b, k_u / b**2],
                  [b**2 * k_u, b * k_v, k_s, k_t / b],
                  [b**3 * k_t, b**2 * k_u, b * k_v, k_s]])
    d = np.array([1.0, 1.0, ei, ei])
    return d[:, None] * a / d[None, :]
