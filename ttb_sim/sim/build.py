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

from dataclasses import dataclass
import logging
from typing import Sequence

import numpy as np

from ttb_sim.config import car_layout, Scenario
from ttb_sim.config.conditions import (bearing_factors, check_conditions, conditioned_bearings,
                                       conditioned_bridge, girder_bending, pier_substructure)
from ttb_sim.config.sensor_places import ProbeRequest
from ttb_sim.errors import ScenarioError
from ttb_sim.fe.beam import BeamSection, field_rows, point_rows
from ttb_sim.inputs import shown
from ttb_sim.model.beam_line import BeamLine
from ttb_sim.model.bridge import pier_section, rayleigh_coefficients, span_frequency
from ttb_sim.model.constants import GRAVITY
from ttb_sim.model.foundation.operator import FoundationOperator
from ttb_sim.model.foundation.records import Substructure
from ttb_sim.model.irregularity import load_csv, synthesize, TrackIrregularity
from ttb_sim.model.structure import assemble_structure, Structure
from ttb_sim.model.vehicle.payload import loaded_car, mass_per_axle
from ttb_sim.model.vehicle.train import Axles, MovingForces, MultibodyCars, QuarterCars, Vehicle
from ttb_sim.sim.coupling import (Coupling, MovingForceCoupling, QuarterCarTrain,
                                  ReducedTrainTrackCoupling, TrainTrackCoupling)
from ttb_sim.sim.integrators import Integrator

LOG = logging.getLogger(__name__)

__all__ = ['build_coupling', 'build_irregularity', 'build_structure', 'build_vehicle',
           'CONTACT_STEP', 'observer_rows', 'probe_rows', 'ProbeRows', 'StepLimits',
           'vehicle_track_setup',
           'PROFILE_MARGIN', 'train_length']


def train_length(scenario: Scenario) -> float:
    """Return the length of the train from its head to its last axle or car end (m)."""
    train = scenario.train
    if train.vehicle == 'car':
        return train.n_cars * train.car_length
    return max(scenario.axle_positions())


def build_structure(scenario: Scenario) -> Structure:
    """
    Assemble the bridge (and slab track, and piled piers) of a scenario, once.

    The ``damage`` and ``environment`` sections act here (:mod:`ttb_sim.config.conditions`):
    the girders and bearings at the temperature, the damaged girder elements and
    bearings, and each piled pier on its own (scoured, damaged, scaled) ground.
    """
    check_conditions(scenario)
    track = scenario.track if scenario.track.model == 'slab' else None
    fd = scenario.foundation
    foundations = None
    if fd.model == 'piled':
        foundations = {}
        built: dict[Substructure, FoundationOperator] = {}
        for support in fd.piled:  # piers on the same ground share one operator
            spec = pier_substructure(scenario, support + 1)
            if spec not in built:
                built[spec] = build_foundation(scenario, spec)
            foundations[support] = built[spec]
    return assemble_structure(conditioned_bridge(scenario), conditioned_bearings(scenario),
                              scenario.piers, fd, track, train_length(scenario), foundations,
                              monolithic=scenario.solver.coupling == 'monolithic',
                              girder_bending=girder_bending(scenario),
                              bearing_stiffness=bearing_factors(scenario))


def build_foundation(scenario: Scenario, spec: Substructure | None = None
                     ) -> FoundationOperator:
    """
    Return the substructure of a piled pier: its column on the cap-pile-soil block.

    The pier column is damped like the bridge's beams (Rayleigh, the girder's
    ratio at its first and fourth bending frequencies, at the temperature); the
    soil, piles and cap as their own records say, or as ``spec`` (a pier's
    damaged ground, :func:`ttb_sim.config.conditions.pier_substructure`) says.
    """
    from ttb_sim.model.foundation.reduction import pile_soil_operator

    spec = scenario.substructure() if spec is None else spec
    operator = pile_soil_operator(spec, *pier_column_parameters(scenario),
                                  scenario.soil.reduction)
    warn_unresolved_loading(scenario, float(operator.summary.get('f_max', np.inf)))
    return operator


def pier_column_parameters(scenario: Scenario
                           ) -> tuple[float, int, BeamSection, tuple[float, float]]:
    """
    Return a piled pier's column: (height, elements, section, Rayleigh (a0, a1)).

    Damped like the bridge's beams: the girder's ratio at its first and fourth
    bending frequencies, at the scenario's temperature.
    """
    b, pr = conditioned_bridge(scenario), scenario.piers
    f1 = span_frequency(b.span_length, b.bending_stiffness, b.mass_per_length)
    return (pr.height, pr.elements, pier_section(pr),
            rayleigh_coefficients(b.damping_ratio, f1, 4 * f1))


def warn_unresolved_loading(scenario: Scenario, f_max: float) -> bool:
    """
    Warn when the train loads the piled piers above what the soil mesh carries.

    The first car-passage line V / car length is always in the pier load; above
    the mesh's f_max (Vs_min / (8 h) in its coarsest cells) the pile and soil
    streams are the truncated, coarse block's resonances rather than waves in the
    ground. Returns whether it warned.
    """
    line = scenario.train.speed / scenario.train.car_length
    if f_max >= line:
        return False
    LOG.warning('the soil mesh carries waves up to %.2f Hz in its coarsest cells '
                '(soil.mesh.h_max = %g m), below the first car-passage frequency %.2f Hz: '
                'the pile and soil streams above %.2f Hz show the coarse block, not the ground '
                '(docs/coupled.md, "The reduced substructure")', f_max,
                scenario.soil.mesh.h_max, line, f_max)
    return True


def build_vehicle(scenario: Scenario) -> Vehicle:
    """Build the vehicle model a scenario's train (and car) sections describe."""
    train = scenario.train
    axles = Axles(offsets=np.asarray(scenario.axle_positions(), dtype=float))
    n = axles.count
    if train.vehicle == 'car':
        layout = car_layout(train, scenario.car)
        return MultibodyCars(axles=Axles(offsets=np.asarray(layout, dtype=float)),
                             n_cars=train.n_cars, car_length=train.car_length)
    per_car = scenario.axles_per_car()   # four by the car layout, one per axle by hand
    payload = mass_per_axle(train.passenger_load, per_car)  # train.passenger_load
    if train.vehicle == 'moving_force':
        return MovingForces(axles=axles, loads=np.full(n, train.axle_load + payload * GRAVITY))
    return QuarterCars(axles=axles, sprung_mass=np.full(n, train.sprung_mass + payload),
                       unsprung_mass=np.full(n, train.unsprung_mass),
                       stiffness=np.full(n, train.suspension_stiffness),
                       damping=np.full(n, train.suspension_damping), axles_per_car=per_car)


CONTACT_STEP = 1e-4
"""Largest automatic time step with wheel-rail contact (s), the step of [P]."""


@dataclass(frozen=True)
class StepLimits:
    """What the vehicle model asks of the automatic time step."""

    element_length: float
    """Shortest element a wheel load crosses (m): girder, or rail with a slab track."""
    vehicle_frequency: float | None
    """Highest vehicle frequency to resolve (Hz), or None."""
    max_step: float | None
    """Largest step the coupling allows (s), or None."""


def vehicle_track_setup(scenario: Scenario, structure: Structure,
                        vehicle: Vehicle) -> tuple[StepLimits, TrackIrregularity | None]:
    """
    Return the vehicle's time-step limits and the irregularity it runs on.

    Moving forces ignore the irregularity; quarter cars follow it over the part of
    the track the train covers; multibody cars run on it over the whole modelled
    track and ask for the contact step.
    """
    girder = structure.girder
    if isinstance(vehicle, QuarterCars):
        irregularity = build_irregularity(scenario, vehicle.axles.train_length, girder.length)
        return StepLimits(girder.element_length, float(vehicle.natural_frequency().max()),
                          None), irregularity
    if isinstance(vehicle, MultibodyCars):
        track = structure.track
        if track is None:  # the scenario rules make this unreachable
            raise ScenarioError("train.vehicle = 'car' needs track.model = 'slab'")
        irregularity = build_irregularity(scenario, vehicle.length, girder.length,
                                          (track.x_start, track.x_end))
        return StepLimits(float(track.rails[0].length.min()), None, CONTACT_STEP), irregularity
    return StepLimits(girder.element_length, None, None), None


def build_coupling(scenario: Scenario, structure: Structure, vehicle: Vehicle,
                   integrator: Integrator, irregularity: TrackIrregularity | None, *,
                   lean: bool = False, reduced: bool = False, rail_steps: int = 0) -> Coupling:
    """
    Couple the scenario's vehicle model to the structure (the one place that dispatches on it).

    Parameters
    ----------
    scenario, structure, vehicle
        The scenario and the model built from it.
    integrator : Integrator
        The structure's integrator.
    irregularity : TrackIrregularity or None
        The realised track irregularity.
    lean : bool
        Lean load kernels (solver variants other than ``reference``).
    reduced : bool
        Multibody cars on the reduced track-bridge, detailed only around the
        train (:mod:`ttb_sim.sim.coupling.train_track.reduced_track`); the other vehicles
        ignore it.
    rail_steps : int
        Multibody cars (``realtime``): on the reduced track-bridge of ``reduced``, with the
        window's rails and slabs at dt and the rest at rail_steps dt
        (:class:`~ttb_sim.sim.integrators.multirate.MultiRateNewmark`); 0 = one system.

    """
    if isinstance(vehicle, MultibodyCars):
        car = loaded_car(scenario.car, scenario.train.passenger_load)
        if reduced or rail_steps:
            return ReducedTrainTrackCoupling(car, scenario.contact, vehicle.n_cars,
                                             vehicle.car_length, structure, integrator,
                                             irregularity, scenario.solver.window_margin,
                                             rail_steps)
        return TrainTrackCoupling(car, scenario.contact, vehicle.n_cars,
                                  vehicle.car_length, structure, integrator, irregularity)
    if isinstance(vehicle, QuarterCars):
        return QuarterCarTrain(vehicle, structure, integrator, irregularity)
    return MovingForceCoupling(vehicle, structure, integrator, lean=lean)


def observer_rows(scenario: Scenario, structure: Structure) -> tuple[np.ndarray, np.ndarray]:
    """
    Return (extended free DOFs (n, 12), rows (n, 3, 12)) of the scenario's observers.

    Raises
    ------
    ScenarioError
        For an observer on a track component without a track, or outside the
        component.

    """
    observers = scenario.output.points
    dofs = np.zeros((len(observers), 12), dtype=int)
    rows = np.zeros((len(observers), 3, 12))
    for i, obs in enumerate(observers):
        where = f'output.observers[{i}] = {shown(scenario.output.observers[i])}'
        line, element, xi = _line_point(structure, obs.component, obs.x, where)
        dofs[i] = structure.full_to_free[line.dofs[element]]
        rows[i] = point_rows(xi, line.length[element], np.zeros(3))[0]
    return dofs, rows


PROBE_STATES = {'displacement': 0, 'rotation': 0, 'strain': 0, 'velocity': 1,
                'acceleration': 2}
"""Which state a probe's rows apply to: 0 displacement, 1 velocity, 2 acceleration."""


@dataclass(frozen=True)
class ProbeRows:
    """The beam-line probes of the sensors as rows on the extended structure state."""

    dofs: np.ndarray
    """(n, 12) extended free DOFs of each probe's element."""
    rows: np.ndarray
    """(n, 3, 12) rows of the probe's three values."""
    states: np.ndarray
    """(n,) the state each probe reads (:data:`PROBE_STATES`)."""

    def values(self, states: np.ndarray) -> np.ndarray:
        """Return the probes' (n, 3) values from the stacked (3, n_extended) state."""
        return np.einsum('pij,pj->pi', self.rows, states[self.states[:, None], self.dofs])


def probe_rows(requests: Sequence[ProbeRequest], structure: Structure) -> ProbeRows:
    """
    Return the rows of the sensors' beam-line probes.

    Displacement, velocity and acceleration: the motion of the beam axis;
    rotation: (theta_x, theta_y, theta_z); strain: the fibre strain
    u' - z w'' - y v'' at the fibre (y, z), then two zeros.

    Raises
    ------
    ScenarioError
        For a probe on a track component without a track, or outside the component.

    """
    n = len(requests)
    dofs = np.zeros((n, 12), dtype=int)
    rows = np.zeros((n, 3, 12))
    for i, req in enumerate(requests):
        where = f'sensor at {req.component}@{req.x:g}'
        line, element, xi = _line_point(structure, req.component, req.x, where)
        dofs[i] = structure.full_to_free[line.dofs[element]]
        length = line.length[element]
        if req.quantity == 'rotation':
            rows[i] = field_rows(xi, length)[0, 3:6]
        elif req.quantity == 'strain':
            arm = np.array([0.0, req.fibre[0], req.fibre[1]])
            rows[i, 0] = point_rows(xi, length, arm, derivative=1)[0, 0]
        else:
            rows[i] = point_rows(xi, length, np.zeros(3))[0]
    states = np.array([PROBE_STATES[r.quantity] for r in requests], dtype=int)
    return ProbeRows(dofs, rows, states)


def _line_point(structure: Structure, component: str, x: float,
                where: str) -> tuple[BeamLine, np.ndarray, np.ndarray]:
    """Return (line, element (1,), xi (1,)) of a point of a beam line at track position x."""
    track = structure.track
    if component == 'girder':
        line = structure.girder_beam
    elif track is None:
        raise ScenarioError(f"{where}: component {component!r} needs track.model = 'slab'")
    else:
        line = {'rail_left': track.rails[0], 'rail_right': track.rails[1],
                'slab': track.slab, 'base': track.base}[component]
    element, xi, inside = line.locate(np.array([x]))
    if not inside[0]:
        raise ScenarioError(f'{where}: x is not on the {component}, which runs from '
                            f'{line.start[0]:g} to {line.end:g} m (slab and base units '
                            'have gaps)')
    return line, element, xi


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
