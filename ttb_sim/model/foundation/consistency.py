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
The checks of a pile-soil substructure that involve several of its records.

Each record checks its own fields (:mod:`.records`); :func:`check_substructure`
checks what they cannot alone: the piles inside the block and under the cap,
shorter than the deposit, the observation points inside the solid, and a load
on an existing pile that the mesh is fine enough to carry.
"""

from __future__ import annotations

from typing import Optional

from ttb_sim.model.foundation.records import FoundationError, PileLoad, Substructure


def check_substructure(spec: Substructure, load: Optional[PileLoad] = None) -> None:
    """
    Check what the single records cannot: geometry fits and mesh carries the load.

    Raises
    ------
    FoundationError
        Piles outside the block or the cap, a pile as long as the deposit or
        longer, a periodic block with piles, a load on a pile that does not
        exist, or a mesh whose near-pile size ``h`` cannot carry the load
        frequency (f > Vs_min / (points_per_wavelength h)).

    """
    soil, piles = spec.soil, spec.piles
    if piles is not None:
        if soil.periodic:
            raise FoundationError('soil.periodic = True is for soil columns; it cannot '
                                  'carry piles (set piles to none)')
        if piles.length >= soil.depth:
            message = (f'piles.length = {piles.length!r} m reaches the base of the '
                       f'{soil.depth:g} m deposit; allowed: < {soil.depth:g} m')
            raise FoundationError(message)
        half = 0.5 * piles.width
        xs = [c[0] for c in piles.centres()]
        ys = [c[1] for c in piles.centres()]
        margin = spec.mesh.h
        if (min(xs) - half < -0.5 * soil.lx + margin or max(xs) + half > 0.5 * soil.lx - margin
                or min(ys) - half < -0.5 * soil.ly + margin
                or max(ys) + half > 0.5 * soil.ly - margin):
            message = (f'piles extend over x [{min(xs) - half:g}, {max(xs) + half:g}] m, '
                       f'y [{min(ys) - half:g}, {max(ys) + half:g}] m: outside the soil block '
                       f'(soil.block.lx = {soil.lx:g}, ly = {soil.ly:g} m, centred at 0, '
                       f'less one element of {margin:g} m)')
            raise FoundationError(message)
        if spec.cap.enabled:
            if (max(abs(x) for x in xs) + half > 0.5 * spec.cap.lx + 1e-9
                    or max(abs(y) for y in ys) + half > 0.5 * spec.cap.ly + 1e-9):
                raise FoundationError(f'the cap ({spec.cap.lx:g} x {spec.cap.ly:g} m) does '
                                      'not cover the pile heads')
    top = spec.cap.thickness if spec.cap.enabled and piles is not None else 0.0
    for i, point in enumerate(spec.observation.points):
        x, y, z = point
        if not (abs(x) <= 0.5 * soil.lx and abs(y) <= 0.5 * soil.ly
                and -soil.depth <= z <= top):
            raise FoundationError(
                f'output.soil_points[{i}] = {list(point)!r} lies outside the soil block; '
                f'allowed: |x| <= {0.5 * soil.lx:g}, |y| <= {0.5 * soil.ly:g}, '
                f'{-soil.depth:g} <= z <= {top:g} m (soil.block.lx, soil.block.ly, soil.layers)')
    if load is not None and load.type != 'none':
        if load.target == 'cap' and not (spec.cap.enabled and piles is not None):
            raise FoundationError("load.target = 'cap' needs a cap; allowed: cap.enabled = "
                                  "true (with piles), or load.target 'pile' or 'surface'")
        if load.target in ('pile', 'cap'):
            count = piles.count if piles is not None else 0
            if load.pile > count:
                message = f'load.pile = {load.pile!r}; allowed: 1 .. {count} (piles in group)'
                raise FoundationError(message)
        if load.type != 'static':
            carried = soil.vs_min / (spec.mesh.points_per_wavelength * spec.mesh.h)
            largest = soil.vs_min / (spec.mesh.points_per_wavelength * load.frequency)
            if load.frequency > carried:
                message = (f'load.frequency = {load.frequency:g} Hz is above the '
                           f'{carried:.3g} Hz that soil.mesh.h = {spec.mesh.h:g} m carries '
                           f'(Vs_min / ({spec.mesh.points_per_wavelength:g} h)); '
                           f'allowed: soil.mesh.h <= {largest:.3g} m for this load')
                raise FoundationError(message)
