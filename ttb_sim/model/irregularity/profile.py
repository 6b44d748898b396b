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
Rail irregularity profiles on a grid along the track, and their sampling.

Frame and signs (REP 103 track frame: x along the track, y to the LEFT, z UP):

- ``z_left``, ``z_right``: vertical irregularity of each rail (m); positive
  raises the rail.
- ``y_left``, ``y_right``: lateral irregularity of each rail (m); positive
  moves the rail to the left (+y).
- Composition from the track-geometry components of :mod:`.spectra`::

      z_left  = vertical + cross_level / 2      z_right = vertical - cross_level / 2
      y_left  = alignment + gauge / 2           y_right = alignment - gauge / 2

  so a positive cross-level raises the LEFT rail (cross_level = z_left -
  z_right) and a positive gauge irregularity widens the gauge (left rail to
  +y, right rail to -y; gauge = y_left - y_right).  PHYSICS.md 1.1 writes the
  combination with the opposite signs (``z_v -/+ z_c/2``); for a spectrum only
  the sign convention of the realisation changes, not its statistics.
- The Sato short-wave spectrum has a vertical component only; it is added to
  ``vertical``, i.e. identically to both rails (as a common rail-surface
  roughness; it adds nothing to cross-level).

Between grid points :meth:`TrackIrregularity.sample` uses the quintic Hermite
interpolant of the node values, slopes and curvatures: it passes through the
grid values, is twice continuously differentiable, and the slope and curvature
it returns are the exact derivatives of the value it returns.  Positions
outside the grid raise :class:`~ttb_sim.errors.ModelError` by default, or
give zeros (value and derivatives) with ``outside='zero'``.

Profiles are synthesised from spectra in :mod:`.synthesis` and read from or
written to CSV in :mod:`.measured`.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ttb_sim.errors import ModelError
from ttb_sim.model.irregularity._checks import GRID_SLACK
from ttb_sim.model.irregularity.spectrum_records import COMPONENTS

__all__ = [
    'IrregularitySample',
    'RAIL_QUANTITIES',
    'TrackIrregularity',
]

#: Rail quantities, in the order of the first axis of every array here.
RAIL_QUANTITIES: tuple[str, ...] = ('z_left', 'z_right', 'y_left', 'y_right')


@dataclass(frozen=True)
class IrregularitySample:
    """
    Rail irregularities and their x-derivatives at a set of positions.

    The first axis of every array follows :data:`RAIL_QUANTITIES`
    (z_left, z_right, y_left, y_right); the other axes follow the shape of the
    positions asked for.

    Attributes
    ----------
    value : numpy.ndarray
        Irregularity (m).
    slope : numpy.ndarray
        First derivative d/dx (m/m).  Multiply by the speed V for a rate (m/s).
    curvature : numpy.ndarray
        Second derivative d^2/dx^2 (1/m).  Multiply by V^2 for m/s^2.

    """

    value: NDArray[np.float64]
    slope: NDArray[np.float64]
    curvature: NDArray[np.float64]

    def rail(
        self, name: str,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """
        Return (value, slope, curvature) of one rail quantity.

        Parameters
        ----------
        name : str
            One of :data:`RAIL_QUANTITIES`.

        Returns
        -------
        tuple of numpy.ndarray
            Value (m), slope (-), curvature (1/m).

        """
        i = RAIL_QUANTITIES.index(name)
        return self.value[i], self.slope[i], self.curvature[i]


@dataclass(frozen=True, eq=False)
class TrackIrregularity:
    """
    Realised rail irregularities on a uniform grid along the track.

    Attributes
    ----------
    x_start : float
        Position of the first grid point along the track (m).
    dx : float
        Grid spacing (m).
    values : numpy.ndarray
        Shape (4, N): z_left, z_right, y_left, y_right at the grid points (m).
    slopes : numpy.ndarray
        Shape (4, N): their first derivatives d/dx (-).
    curvatures : numpy.ndarray
        Shape (4, N): their second derivatives d^2/dx^2 (1/m).
    source : str
        Provenance, e.g. ``'paper seed=3 scale=1'`` or ``'csv:/path/file.csv'``.

    Notes
    -----
    The arrays are stored read-only.  Sign conventions are given in the
    module docstring.

    """

    x_start: float
    dx: float
    values: NDArray[np.float64]
    slopes: NDArray[np.float64]
    curvatures: NDArray[np.float64]
    source: str = ''

    def __post_init__(self) -> None:
        if not (math.isfinite(self.x_start) and math.isfinite(self.dx) and self.dx > 0.0):
            raise ModelError(f'need finite x_start and dx > 0, got {self.x_start}, {self.dx}')
        shape = None
        for name in ('values', 'slopes', 'curvatures'):
            arr = getattr(self, name)
            if not (isinstance(arr, np.ndarray) and arr.dtype == np.float64
                    and not arr.flags.writeable):
                arr = np.array(arr, dtype=np.float64)
                arr.flags.writeable = False
                object.__setattr__(self, name, arr)
            if arr.ndim != 2 or arr.shape[0] != len(RAIL_QUANTITIES) or arr.shape[1] < 2:
                raise ModelError(f'{name} must have shape (4, N) with N >= 2, got {arr.shape}')
            if shape is not None and arr.shape != shape:
                raise ModelError(f'{name} has shape {arr.shape}, values has {shape}')
            if not np.all(np.isfinite(arr)):
                raise ModelError(f'{name} contains non-finite numbers')
            shape = arr.shape

    @property
    def n_points(self) -> int:
        """Return the number of grid points."""
        return int(self.values.shape[1])

    @property
    def x_end(self) -> float:
        """Return the position of the last grid point (m)."""
        return self.x_start + (self.n_points - 1) * self.dx

    @property
    def length(self) -> float:
        """Return the covered length x_end - x_start (m)."""
        return (self.n_points - 1) * self.dx

    @property
    def x(self) -> NDArray[np.float64]:
        """Return the grid positions (m)."""
        return self.x_start + self.dx * np.arange(self.n_points, dtype=np.float64)

    @property
    def z_left(self) -> NDArray[np.float64]:
        """Return the vertical irregularity of the left rail at the grid (m, up)."""
        return self.values[0]

    @property
    def z_right(self) -> NDArray[np.float64]:
        """Return the vertical irregularity of the right rail at the grid (m, up)."""
        return self.values[1]

    @property
    def y_left(self) -> NDArray[np.float64]:
        """Return the lateral irregularity of the left rail at the grid (m, to the left)."""
        return self.values[2]

    @property
    def y_right(self) -> NDArray[np.float64]:
        """Return the lateral irregularity of the right rail at the grid (m, to the left)."""
        return self.values[3]

    def geometry(self, component: str) -> NDArray[np.float64]:
        """
        Return a track-geometry component recovered from the rails.

        Parameters
        ----------
        component : str
            ``vertical`` = (z_left + z_right)/2, ``cross_level`` = z_left -
            z_right, ``alignment`` = (y_left + y_right)/2 or ``gauge`` =
            y_left - y_right.

        Returns
        -------
        numpy.ndarray
            The component at the grid points (m).

        Raises
        ------
        ModelError
            If the component name is unknown.

        """
        z_l, z_r, y_l, y_r = self.values
        if component == 'vertical':
            return 0.5 * (z_l + z_r)
        if component == 'cross_level':
            return z_l - z_r
        if component == 'alignment':
            return 0.5 * (y_l + y_r)
        if component == 'gauge':
            return y_l - y_r
        raise ModelError(f'unknown component {component!r}; expected one of {COMPONENTS}')

    def sample(
        self, x: ArrayLike, *, outside: Literal['raise', 'zero'] = 'raise',
    ) -> IrregularitySample:
        """
        Evaluate the rail irregularities and their derivatives at positions.

        Parameters
        ----------
        x : array_like
            Positions along the track (m), any shape.
        outside : {'raise', 'zero'}
            What to do with positions outside [x_start, x_end]: raise
            :class:`ModelError` (default), or return zero value, slope and
            curvature there (a smooth track before and after the profile).

        Returns
        -------
        IrregularitySample
            Arrays of shape (4,) + x.shape.

        Raises
        ------
        ModelError
            With ``outside='raise'``, if a position is outside the profile or
            not finite.

        """
        xq = np.asarray(x, dtype=float)
        s = (xq - self.x_start) / self.dx
        last = self.n_points - 1
        inside = (s >= -GRID_SLACK) & (s <= last + GRID_SLACK)
        all_inside = bool(np.all(inside))
        if not all_inside:
            if outside == 'raise':
                bad = xq[~inside].flat[0]
                message = (
                    f'irregularity profile covers x = {self.x_start:g} to {self.x_end:g} m; '
                    f'position x = {bad:g} m is outside it (generate or load a longer profile)')
                raise ModelError(message)
            if outside != 'zero':
                raise ModelError(f"outside must be 'raise' or 'zero', got {outside!r}")
            s = np.where(inside, s, 0.0)
        i = np.clip(np.floor(s), 0, last - 1).astype(np.intp)
        t = s - i
        h = self.dx
        p0, p1 = self.values[:, i], self.values[:, i + 1]
        m0, m1 = h * self.slopes[:, i], h * self.slopes[:, i + 1]
        c0, c1 = h * h * self.curvatures[:, i], h * h * self.curvatures[:, i + 1]
        # Quintic Hermite on [0, 1]: p = a0 + a1 t + ... + a5 t^5 matching
        # value, first and second derivative at both ends.
        a2 = 0.5 * c0
        d0 = p1 - (p0 + m0 + a2)
        d1 = m1 - (m0 + c0)
        d2 = c1 - c0
        a3 = 10.0 * d0 - 4.0 * d1 + 0.5 * d2
        a4 = -15.0 * d0 + 7.0 * d1 - d2
        a5 = 6.0 * d0 - 3.0 * d1 + 0.5 * d2
        value = p0 + t * (m0 + t * (a2 + t * (a3 + t * (a4 + t * a5))))
        slope = (m0 + t * (2.0 * a2 + t * (3.0 * a3 + t * (4.0 * a4 + t * 5.0 * a5)))) / h
        curvature = (2.0 * a2 + t * (6.0 * a3 + t * (12.0 * a4 + t * 20.0 * a5))) / (h * h)
        if not all_inside:
            value = np.where(inside, value, 0.0)
            slope = np.where(inside, slope, 0.0)
            curvature = np.where(inside, curvature, 0.0)
        return IrregularitySample(value, slope, curvature)
