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
The model's modes as the sensors see them: the structure ``ttb-sim modes`` solves, its shapes.

:func:`structure_modes` builds a scenario's structure as ``ttb-sim run`` does, without the
train, with piled piers monolithic so that their reduced coordinates take part ([P] Eq. 11),
and returns its natural modes (:func:`ttb_sim.model.modes.natural_modes`): ``ttb-sim
modes`` prints these. :func:`channel_shapes` evaluates each mode at sensor channels (a place
and an axis) with the rows the virtual sensors read (:func:`ttb_sim.sim.probe_rows`: the
beam element's interpolation), so that a shape identified from the records of those
sensors can be compared with the model's (MAC). Places off the beam lines (pile heads, car
bodies, ground points) get NaN.
"""

from __future__ import annotations

import dataclasses
import logging
from typing import Sequence, TYPE_CHECKING

import numpy as np

from ttb_sim.config.sensor_places import AXIS, parse_location, ProbeRequest
from ttb_sim.errors import ScenarioError, TtbSimError
from ttb_sim.model.modes import Modes, natural_modes
from ttb_sim.sim import build_structure, probe_rows

if TYPE_CHECKING:
    from ttb_sim.config import Scenario
    from ttb_sim.model.structure import Structure

__all__ = ['channel_modes', 'channel_shapes', 'modal_structure', 'modes_near', 'monolithic',
           'solve', 'structure_modes']

log = logging.getLogger(__name__)

FIRST_COUNT = 24
"""The lowest model modes :func:`modes_near` lists."""
NEAR_COUNT = 12
"""Model modes :func:`modes_near` takes nearest each identified frequency."""


def monolithic(scenario: Scenario) -> Scenario:
    """Return the scenario with piled piers monolithic, as ``ttb-sim modes`` solves them."""
    if scenario.foundation.model != 'piled':
        return scenario
    solver = dataclasses.replace(scenario.solver, coupling='monolithic', substructure_steps=1)
    return dataclasses.replace(scenario, solver=solver)


def modal_structure(scenario: Scenario) -> Structure:
    """
    Build the structure ``ttb-sim modes`` solves: as a run builds it, piled piers monolithic.

    Raises
    ------
    ScenarioError
        For a substructure run without a bridge.

    """
    if scenario.substructure_only:
        raise ScenarioError(f'load.type = {scenario.load.type!r}: {scenario.name} is a '
                            'pile-soil substructure run without a bridge; allowed: load.type '
                            "= 'none' (a scenario with a bridge)")
    return build_structure(monolithic(scenario))


def solve(structure: Structure, around: float, count: int) -> Modes:
    """Return the structure's ``count`` modes nearest ``around`` Hz."""
    return natural_modes(structure.mass, structure.stiffness, structure.damping, around,
                         min(count, structure.n_free))


def structure_modes(scenario: Scenario, around: float, count: int) -> tuple[Structure, Modes]:
    """
    Build a scenario's structure and return it with its ``count`` modes nearest ``around`` Hz.

    Raises
    ------
    ScenarioError
        For a substructure run without a bridge.

    """
    structure = modal_structure(scenario)
    return structure, solve(structure, around, count)


def modes_near(scenario: Scenario, frequencies: Sequence[float],
               highest_hz: float) -> tuple[Structure, Modes]:
    """
    Return the structure and its modes to set beside identified ones, up to ``highest_hz``.

    The :data:`FIRST_COUNT` lowest modes and the :data:`NEAR_COUNT` nearest each of
    ``frequencies`` (shift-invert about each: a long bridge has hundreds of modes below
    the band's top, and the ones near an identified mode are those to compare), in
    increasing frequency, each once.
    """
    structure = modal_structure(scenario)
    parts = [solve(structure, 0.0, FIRST_COUNT)]
    parts += [solve(structure, float(f), NEAR_COUNT) for f in frequencies]
    f = np.concatenate([m.frequencies for m in parts])
    zeta = np.concatenate([m.damping_ratios for m in parts])
    shapes = np.hstack([m.shapes for m in parts])
    order = np.argsort(f, kind='stable')
    keep = [int(order[0])] if order.size else []
    for k in order[1:]:   # the same mode found twice: equal frequency to round-off
        if not np.isclose(f[k], f[keep[-1]], rtol=1e-9, atol=1e-12):
            keep.append(int(k))
    keep = [k for k in keep if f[k] <= highest_hz]
    return structure, Modes(f[keep], zeta[keep], shapes[:, keep])


def channel_shapes(structure: Structure, modes: Modes,
                   channels: Sequence[tuple[str, str]]) -> np.ndarray:
    """
    Return the modes' values at channels (place, axis), shape (channels, modes).

    A place is a sensor's ``at`` as ``summary.json`` gives it (``girder@16``, ``slab@40``; a
    ``spanNN/x=X`` is already a girder point there); the value is the modal displacement the
    sensor's probe row reads on that axis. NaN for a place off the beam lines or outside them.
    """
    k = modes.frequencies.size
    out = np.full((len(channels), k), np.nan)
    ext = np.vstack([modes.shapes, np.zeros((1, k))])
    for c, (place, axis) in enumerate(channels):
        try:
            location = parse_location(place, 'sensor')
            if location.kind != 'line' or axis not in AXIS:
                continue
            rows = probe_rows([ProbeRequest(location.parts[0], location.x, 'displacement')],
                              structure)
        except (TtbSimError, ValueError) as exc:
            log.info('no model shape at %s: %s', place, exc)
            continue
        out[c] = rows.rows[0, AXIS[axis]] @ ext[rows.dofs[0]]
    return out


def channel_modes(scenario: Scenario, channels: Sequence[tuple[str, str]],
                  frequencies: Sequence[float],
                  highest_hz: float) -> tuple[Structure, Modes, np.ndarray]:
    """Return :func:`modes_near` and the modes' values at the channels (:func:`channel_shapes`)."""
    structure, found = modes_near(scenario, frequencies, highest_hz)
    return structure, found, channel_shapes(structure, found, channels)
