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
The build step: the only code that turns a :class:`~ttb_sim.config.Scenario` into model objects.

Model modules take their own parameter records (the scenario's sections are
those records) and never see the scenario tree; this module picks the pieces
out of the scenario once and hands each model builder what it needs.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ttb_sim.config import parse_observers, Scenario
from ttb_sim.errors import ScenarioError
from ttb_sim.model.bridge import assemble_structure, Structure
from ttb_sim.model.irregularity import load_csv, synthesize, TrackIrregularity
from ttb_sim.model.vehicle.train import Axles, MovingForces, MultibodyCars, QuarterCars, Vehicle

__all__ = ['build_irregularity', 'build_structure', 'build_vehicle', 'observer_rows',
           'PROFILE_MARGIN', 'train_length']


def train_length(scenario: Scenario) -> float:
    """Return the length of the train from its head to its last axle or car end (m)."""
    train = scenario.train
    if train.vehicle == 'car':
        return train.n_cars * train.car_length
    return max(scenario.axle_positions())


def build_structure(scenario: Scenario) -> Structure:
    """Assemble the bridge (and slab track) of a scenario, once, before time stepping."""
    track = scenario.track if scenario.track.model == 'slab' else None
    return assemble_structure(scenario.bridge, scenario.bearings, scenario.piers,
                              scenario.foundation, track, train_length(scenario))


def build_vehicle(scenario: Scenario) -> Vehicle:
    """Build the vehicle model a scenario's train (and car) sections describe."""
    train = scenario.train
    axles = Axles(offsets=np.asarray(scenario.axle_positions(), dtype=float))
    n = axles.count
    if train.vehicle == 'car':
        layout = replace(scenario, train=replace(train, axle_offsets=())).axle_positions()
        return MultibodyCars(axles=Axles(offsets=np.asarray(layout, dtype=float)),
                             n_cars=train.n_cars, car_length=train.car_length)
    if train.vehicle == 'moving_force':
        return MovingForces(axles=axles, loads=np.full(n, train.axle_load))
    return QuarterCars(axles=axles, sprung_mass=np.full(n, train.sprung_mass),
                       unsprung_mass=np.full(n, train.unsprung_mass),
                       stiffness=np.full(n, train.suspension_stiffness),
                       damping=np.full(n, train.suspension_damping))


def observer_rows(scenario: Scenario, structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """
    Return (extended free DOFs (n, 12), rows (n, 3, 12)) of the scenario's observers.

    Raises
    ------
    ScenarioError
        For an observer on a track component without a track, or outside the
        component.

    """
    observers = parse_observers(scenario.output.observers)
    dofs = np.zeros((len(observers), 12), dtype=int)
    rows = np.zeros((len(observers), 3, 12))
    ftf = structure.full_to_free
    track = structure.track
    for i, obs in enumerate(observers):
        where = f'output.observers[{i}] = {obs.name}={obs.component}@{obs.x:g}'
        if obs.component == 'girder':
            line = structure.girder_beam
        elif track is None:
            raise ScenarioError(f'{where}: component {obs.component!r} needs '
                                "track.model = 'slab'")
        else:
            line = {'rail_left': track.rails[0], 'rail_right': track.rails[1],
                    'slab': track.slab, 'base': track.base}[obs.component]
        element, r3, inside = line.rows(np.array([obs.x]), np.zeros(3))
        if not inside[0]:
            raise ScenarioError(f'{where}: x is not on the {obs.component}, which runs from '
                                f'{line.start[0]:g} to {line.end:g} m (slab and base units '
                                'have gaps)')
        full = line.dofs[element[0]]
        r = r3[0]
        dofs[i] = ftf[full]
        rows[i] = r
    return dofs, rows


PROFILE_MARGIN = 50.0
"""Track synthesised beyond the positions the train covers in a planned passage (m)."""


def build_irregularity(scenario: Scenario, train_length: float, bridge_length: float,
                       extent: tuple[float, float] | None = None) -> TrackIrregularity | None:
    """
    Realise the scenario's track irregularity once (None for a smooth track).

    A synthesised profile covers ``extent`` (the modelled track) or else the
    track from behind the last axle at the start to the end of the bridge, with
    a margin; a measured CSV profile is used as given. Outside the profile the
    track is smooth.

    Raises
    ------
    ScenarioError
        For an unreadable or invalid CSV file (the message names the row).

    """
    irr = scenario.irregularity
    if irr.scale == 0.0 or (irr.spectrum == 'none' and not irr.file):
        return None
    if irr.file:
        profile = load_csv(irr.file)
        if irr.scale == 1.0:
            return profile
        return TrackIrregularity(x_start=profile.x_start, dx=profile.dx,
                                 values=profile.values * irr.scale,
                                 slopes=profile.slopes * irr.scale,
                                 curvatures=profile.curvatures * irr.scale,
                                 source=profile.source)
    if extent is not None:
        x0, x1 = extent
    else:
        x0 = scenario.train.start_position - train_length - PROFILE_MARGIN
        x1 = max(bridge_length, scenario.train.start_position) + PROFILE_MARGIN
    return synthesize(irr.spectrum, length=x1 - x0, dx=irr.grid_spacing, seed=irr.seed,
                      scale=irr.scale, x_start=x0)
