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
The scenario records: one frozen dataclass per section, each key declared once.

A scenario is a tree of these records (:class:`Scenario` at the root).  Every
leaf is declared with :func:`~ttb_sim.declarations.param` (default, unit, range
or choices, description). The sections the model consumes are the model's own
records: car (:class:`~ttb_sim.model.vehicle.car.CarParameters`), track, bridge,
piers, bearings, foundation (``model/track.py``, ``model/bridge.py``,
``model/bearings.py``, ``model/foundation/pier_foundations.py``), contact
(``model/wheel_rail/contact_parameters.py``) and the pile-soil sections soil, piles, cap,
interface and load (``model/foundation/records.py``); the rest (train, irregularity, solver,
output) are declared here.  Rules that involve more
than one key are checked when a :class:`Scenario` is made.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
import functools
import math
from typing import Any

from ttb_sim.config.observers import Observer, parse_observers
from ttb_sim.config.schema import to_plain
from ttb_sim.config.sensor_layouts import expand_layouts
from ttb_sim.config.sensor_places import check_places, gauge_of, on_girders
from ttb_sim.config.sensor_records import decimation_factor, SensorConfig, SensorError
from ttb_sim.declarations import param
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.model.bearings import BearingParameters
from ttb_sim.model.bridge import BridgeParameters, PierParameters, span_frequency
from ttb_sim.model.damage import DamageParameters
from ttb_sim.model.environment import EnvironmentParameters
from ttb_sim.model.foundation.consistency import check_substructure
from ttb_sim.model.foundation.pier_foundations import FoundationParameters
from ttb_sim.model.foundation.records import (Cap, Interface, Observation, PileGroup, PileLoad,
                                              SoilParameters, Substructure)
from ttb_sim.model.foundation.soil_mesh import planned_nodes
from ttb_sim.model.track import track_extent, TrackExtent, TrackParameters
from ttb_sim.model.vehicle.car import CarParameters
from ttb_sim.model.wheel_rail.contact_parameters import ContactParameters


@dataclass(frozen=True)
class TrainConfig:
    """Train: vehicle model, axle layout and running speed."""

    vehicle: str = param('moving_force', '-', 'Vehicle model: constant moving forces, '
                         'quarter cars (a sprung mass on a spring-dashpot over each axle), or '
                         "42-DOF multibody cars ([P] Table 1, section 'car') on wheel-rail "
                         "contact (needs track.model = 'slab').",
                         choices=('moving_force', 'sprung_mass', 'car'))
    speed_kmh: float = param(300.0, 'km/h', 'Running speed of the train (the upper bound '
                             'is a numerical guard: validation runs use high speed '
                             'parameters).', low=0.0, high=10000.0, low_inclusive=False,
                             dynamic=True)
    start_position: float = param(0.0, 'm', 'Position of the train head along the track at '
                                  't = 0 (0 is the start of the first span).',
                                  low=-5000.0, high=5000.0)
    axle_offsets: tuple[float, ...] = param((), 'm', 'Distances of the axles behind the train '
                                            'head; empty = derived from the car geometry.',
                                            low=0.0, high=5000.0)
    n_cars: int = param(8, '-', 'Number of cars (when axle_offsets is empty).', low=1, high=32)
    car_length: float = param(25.0, 'm', 'Length of one car over couplers.', low=1.0,
                              high=60.0)
    axle_load: float = param(156960.0, 'N', 'Magnitude of each moving force (moving_force '
                             'vehicle); default = (Mc/4 + Mt/2 + Mw) g of [P] Table 1.',
                             low=0.0, high=1e7)
    sprung_mass: float = param(5750.0, 'kg', 'Sprung mass of each quarter car.', low=0.0,
                               high=1e6, low_inclusive=False)
    unsprung_mass: float = param(0.0, 'kg', 'Unsprung (wheel) mass of each quarter car, '
                                 'which follows the girder; 0 = massless wheel.', low=0.0,
                                 high=1e5)
    suspension_stiffness: float = param(1.595e6, 'N/m', 'Suspension stiffness of each '
                                        'quarter car.', low=0.0, high=1e12,
                                        low_inclusive=False)
    suspension_damping: float = param(0.0, 'N*s/m', 'Suspension damping of each quarter car.',
                                      low=0.0, high=1e9)
    passenger_load: float = param(0.0, 'kg', 'Passenger load per car, carried by the car '
                                  'body (multibody cars: body mass and inertias; quarter cars: '
                                  'sprung mass; moving forces: m g per car; docs/damage.md).',
                                  low=0.0, high=1e5, dynamic=True)

    @property
    def speed(self) -> float:
        """Return the running speed in m/s."""
        return self.speed_kmh / 3.6


@dataclass(frozen=True)
class IrregularityConfig:
    """Track irregularity (applied under quarter cars; moving forces ignore it)."""

    spectrum: str = param('none', '-', "Irregularity spectrum ('paper' = Chinese HSR vertical "
                          "and alignment 1-50 m plus Sato 0.05-1 m; 'chinese_sato' the same with "
                          "1-200 m); 'none' is a smooth track.",
                          choices=('none', 'paper', 'chinese_sato', 'chinese_hsr', 'sato',
                                   'german_low',
                                   'german_high', 'fra1', 'fra2', 'fra3', 'fra4', 'fra5',
                                   'fra6'), dynamic=True)
    seed: int = param(1, '-', 'Seed of the random phases (same seed, same track).', low=0,
                      high=2**31 - 1, dynamic=True)
    scale: float = param(1.0, '-', 'Factor on the irregularity amplitude; 0 gives a smooth '
                         'track.', low=0.0, high=100.0, dynamic=True)
    file: str = param('', '-', 'CSV of a measured profile in metres: a header row naming '
                      'x, z_left, z_right, y_left, y_right (any order; other columns are '
                      'ignored), or no header and exactly these five numeric columns in this '
                      'order; a regular file of at most 64 MiB; smooth outside its range. '
                      'Empty = synthesise from the spectrum.', dynamic=True)
    grid_spacing: float = param(0.01, 'm', 'Grid spacing of the synthesised profile (must be '
                                'under half the shortest wavelength).', low=0.001, high=1.0)


@dataclass(frozen=True)
class SolverConfig:
    """Time integration (Newmark average acceleration)."""

    dt: float = param(0.0, 's', 'Time step; 0 picks it automatically (docs/model.md).', low=0.0,
                      high=0.1)
    duration: float = param(0.0, 's', 'Simulated time; 0 runs until the last axle has left '
                            'the bridge plus free_vibration_periods fundamental periods.',
                            low=0.0, high=1e5)
    free_vibration_periods: float = param(1.0, '-', 'Fundamental periods of free vibration '
                                          'appended to an automatic duration.', low=0.0,
                                          high=1000.0)
    divergence_limit: float = param(10.0, 'm', 'Any displacement larger than this (or not '
                                    'finite) stops the run as diverged.', low=0.0, high=1e6,
                                    low_inclusive=False)
    variant: str = param('qdldl', '-', "Solver variant: 'reference' is the validated path "
                         '(general SuperLU LU, step as written); the others factorise the '
                         'symmetric effective matrices with a fill-reducing order and take the '
                         "lean step: 'qdldl' (LDL^T, the fastest measured), 'cholmod' "
                         "(CHOLMOD Cholesky via cholespy), 'superlu_sym' (pure scipy). They "
                         "agree with 'reference' to round-off (docs/performance.md). 'reduced' "
                         '(opt-in) is qdldl with the slab track detailed only in a window '
                         "around the train, the far track condensed onto the bridge. 'realtime' "
                         'is qdldl with the steps between frames in one compiled loop, one '
                         'thread (moving forces and quarter cars); with multibody cars the '
                         'rails at dt and the structure under them at rail_steps * dt '
                         '(multi-rate; docs/performance.md).',
                         choices=('qdldl', 'cholmod', 'superlu_sym', 'reference', 'reduced',
                                  'realtime'))
    substructure_steps: int = param(3, '-', 'Piled foundations: solver steps per substructure '
                                    'step n ([P] Eqs. 13-14: the substructures advance at '
                                    'n dt, the pier tops interpolated in between); 1 = every '
                                    'step.', low=1, high=100)
    coupling: str = param('partitioned', '-', "Piled foundations: 'partitioned' exchanges the "
                          'bearing forces between bridge and substructures ([P] Eq. 12, '
                          "multi-time-step); 'monolithic' solves them as one system ([P] "
                          'Eq. 11, the reference; substructure_steps must be 1).',
                          choices=('partitioned', 'monolithic'))
    threads: int = param(0, '-', 'Threads of the parallel kernels (the split solve of the '
                         'lean variants, the rail predictor of multibody cars); 0 = auto: '
                         'two when the 1-minute load average leaves at least 1.5 cores free, '
                         'else one (two threads on a busy machine wait for each other). The '
                         'results are the same bits with any count.', low=0, high=64)
    rail_steps: int = param(2, '-', "solver.variant 'realtime' with multibody cars: rail "
                            'steps (dt) per step of the structure under the slabs (base '
                            'plates, girders, bearings, piers), which advances at rail_steps * '
                            'dt '
                            '(docs/performance.md: 5 moves the dynamic wheel-rail force by '
                            '1.3 %, 2 by 0.2 %); 1 = both at dt, still staggered.', low=1,
                            high=50)
    window_margin: float = param(100.0, 'm', "solver.variant 'reduced' and 'realtime' "
                                 '(multibody cars): detailed track kept behind the last axle '
                                 "and ahead of the first; more keeps more of the track's waves "
                                 'at more cost (docs/performance.md: 30 m misses the bearing '
                                 'forces by 1.4-1.7 %, 100 m by 0.5-0.75 %).', low=5.0,
                                 high=10000.0)


@dataclass(frozen=True)
class OutputConfig:
    """What is written, and how often."""

    rate_hz: float = param(0.0, 'Hz', 'Frame (message) rate in simulation time; 0 = every '
                           'solver step. Rounded so that frames fall on solver steps.',
                           low=0.0, high=1e6)
    observers: tuple[str, ...] = param((), '-', 'Named displacement observers, each '
                                       "'name=component@x' with component rail_left, "
                                       'rail_right, slab, base or girder and x the position '
                                       'along the track (m); published on ~/observers/name.')
    soil_points: tuple[tuple[float, ...], ...] = param(
        (), 'm', 'Ground observation points [x, y, z] of a pile-soil substructure, besides '
        "[P]'s observation line and VAL points (published on ~/soil/points).", low=-1e4,
        high=1e4)
    soil_grid_spacing: float = param(
        0.0, 'm', 'Spacing of a ground-surface grid of soil points over the cap of each piled '
        'pier (its pile group without a cap) plus output.soil_grid_margin (published on '
        '~/soil/points with the other points); 0 = no grid.', low=0.0, high=100.0)
    soil_grid_margin: float = param(3.0, 'm', 'Margin of the soil grid beyond the cap on '
                                    'every side.', low=0.0, high=1000.0)

    @functools.cached_property
    def points(self) -> tuple[Observer, ...]:
        """The observers parsed once (see :func:`parse_observers`)."""
        return parse_observers(self.observers)


@dataclass(frozen=True)
class Scenario:
    """A complete simulation case."""

    name: str = param('custom', '-', 'Short name of the scenario.')
    description: str = param('', '-', 'One line describing the scenario.')
    train: TrainConfig = field(default_factory=TrainConfig)
    car: CarParameters = field(default_factory=CarParameters)
    track: TrackParameters = field(default_factory=TrackParameters)
    contact: ContactParameters = field(default_factory=ContactParameters)
    bridge: BridgeParameters = field(default_factory=BridgeParameters)
    bearings: BearingParameters = field(default_factory=BearingParameters)
    piers: PierParameters = field(default_factory=PierParameters)
    foundation: FoundationParameters = field(default_factory=FoundationParameters)
    irregularity: IrregularityConfig = field(default_factory=IrregularityConfig)
    soil: SoilParameters = field(default_factory=SoilParameters)
    piles: PileGroup = field(default_factory=PileGroup)
    cap: Cap = field(default_factory=Cap)
    interface: Interface = field(default_factory=Interface)
    load: PileLoad = field(default_factory=PileLoad)
    damage: DamageParameters = field(default_factory=DamageParameters)
    environment: EnvironmentParameters = field(default_factory=EnvironmentParameters)
    solver: SolverConfig = field(default_factory=SolverConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    sensors: tuple[SensorConfig, ...] = param(
        (), '-', 'Virtual sensors, each {name, type, at, axes, rate_hz, noise_density, bias, '
        'bias_walk, resolution, full_scale, dropout_probability, dropout_mean_length, '
        'clock_offset, seed, ...}: what a monitoring system records, published on '
        '~/sensors/<name> (docs/sensors.md).')
    sensor_layouts: tuple[str, ...] = param(
        (), '-', "Built-in sensor layouts, each 'kind:number': 'span:N' (girder N: "
        'accelerometers and soffit strain gauges at 1/4, 1/2, 3/4, end inclinometers, bearing '
        "LVDTs), 'pier:N' (piled pier N: pile-head accelerometers, geophones, settlement), "
        "'wheelset:N' (car N's first axle); added to sensors (docs/sensors.md).")

    def __post_init__(self) -> None:
        """Check the rules that involve more than one key."""
        _check_consistency(self)

    @property
    def substructure_only(self) -> bool:
        """True when the scenario is the pile-soil substructure alone under ``load``."""
        return self.load.type != 'none'

    def substructure(self, name: str = 'pier01') -> Substructure:
        """Return the pile-soil substructure the soil, piles, cap and interface keys describe."""
        return Substructure(name=name, soil=self.soil, piles=self.piles, cap=self.cap,
                            interface=self.interface,
                            observation=Observation(
                                points=self.output.soil_points,
                                grid_spacing=self.output.soil_grid_spacing,
                                grid_margin=self.output.soil_grid_margin))

    @functools.cached_property
    def all_sensors(self) -> tuple[SensorConfig, ...]:
        """The sensors of ``sensor_layouts`` (expanded), then those of ``sensors``."""
        piers = self.foundation.model in ('springs', 'piled') and self.bearings.model == 'elastic'
        sensors = expand_layouts(self.sensor_layouts, self.bridge.span_length,
                                 self.bridge.n_spans, piers,
                                 (self.piles.rows, self.piles.cols)) + self.sensors
        return tuple(on_girders(s, self.bridge.span_length, self.bridge.n_spans)
                     for s in sensors)

    def axle_positions(self) -> tuple[float, ...]:
        """Distances of all axles behind the head (m): ``train.axle_offsets`` or the car layout."""
        if self.train.axle_offsets:
            return tuple(float(a) for a in self.train.axle_offsets)
        return car_layout(self.train, self.car)

    def axles_per_car(self) -> int:
        """
        Return the axles a moving-force or quarter-car model groups into one car.

        The axles of the car layout (``train.axle_offsets`` empty) come four to a car;
        axles placed by hand each stand for a car of their own. Multibody cars always have
        the car layout.
        """
        train = self.train
        n = len(self.axle_positions())
        return n // train.n_cars if not train.axle_offsets and n % train.n_cars == 0 else 1

    def car_count(self) -> int:
        """
        Return the number of cars the model runs (the labels' ``n_cars``).

        ``train.n_cars`` for multibody cars and for the car layout; one car per axle when
        the axles are placed by hand (``train.n_cars`` then plays no part): each carries
        ``train.passenger_load``, and quarter cars publish one ``train/carNN`` each.
        """
        if self.train.vehicle == 'car':
            return self.train.n_cars
        return len(self.axle_positions()) // self.axles_per_car()

    def to_dict(self) -> dict[str, Any]:
        """Return the scenario as plain nested dicts."""
        return to_plain(dataclasses.asdict(self))

    def echo(self) -> dict[str, Any]:
        """Return the sections the run uses as plain nested dicts (for ``summary.json``)."""
        if self.substructure_only:
            unused: tuple[str, ...] = TRAIN_SECTIONS
        elif self.foundation.model == 'piled':
            unused = ('load',)
        else:
            unused = SUBSTRUCTURE_SECTIONS
        return {k: v for k, v in self.to_dict().items() if k not in unused}


TRAIN_SECTIONS = ('train', 'car', 'track', 'contact', 'bridge', 'bearings', 'piers',
                  'foundation', 'irregularity')
"""Sections a substructure-only run (``load.type`` set) ignores."""
SUBSTRUCTURE_SECTIONS = ('soil', 'piles', 'cap', 'interface', 'load')
"""Sections of the pile-soil substructure, unused by a train run on foundation springs."""


def car_layout(train: TrainConfig, car: CarParameters) -> tuple[float, ...]:
    """Distances of the axles of ``train.n_cars`` cars behind the head (m), by car geometry."""
    lc, lt = car.bogie_semi_spacing, car.wheelbase_semi
    length = train.car_length
    first = length / 2.0 - lc - lt
    local = (first, first + 2 * lt, first + 2 * lc, first + 2 * lc + 2 * lt)
    return tuple(k * length + a for k in range(train.n_cars) for a in local)


def _check_consistency(s: Scenario) -> None:
    _check_sensors(s)
    if s.substructure_only:
        _check_substructure(s)
        return
    if s.bridge.elements_per_span % 2:
        raise ScenarioError(f'bridge.elements_per_span = {s.bridge.elements_per_span}: must be '
                            'even, so that a node sits at mid-span')
    _check_girder(s)
    if s.foundation.model in ('springs', 'piled') and s.bearings.model == 'rigid':
        raise ScenarioError(f'foundation.model = {s.foundation.model!r} needs bearings.model = '
                            "'elastic' (rigid bearings model ideal fixed supports)")
    _check_piled(s)
    if s.train.vehicle == 'car' and s.track.model != 'slab':
        raise ScenarioError(f"train.vehicle = 'car' needs track.model = 'slab' (got "
                            f'{s.track.model!r}): wheels run on rails')
    if s.track.model == 'slab' and s.train.vehicle != 'car':
        raise ScenarioError(f"track.model = 'slab' needs train.vehicle = 'car' (got "
                            f'{s.train.vehicle!r})')
    _check_model_size(s)
    _check_track_fit(s)
    _check_observers(s)


def _check_sensors(s: Scenario) -> None:
    """Refuse repeated sensor names, sensors where their type cannot be, rates off the frames."""
    try:
        sensors = s.all_sensors
    except SensorError as exc:
        raise ScenarioError(str(exc)) from None
    seen: set[str] = set()
    n_layout = len(sensors) - len(s.sensors)
    for i, sensor in enumerate(sensors):
        where = f'sensors[{i - n_layout}]' if i >= n_layout else 'sensor_layouts'
        if sensor.name in seen:
            raise ScenarioError(f'{where}.name = {sensor.name!r} is used twice')
        seen.add(sensor.name)
        try:
            check_places(sensor)
            if s.output.rate_hz > 0:
                decimation_factor(s.output.rate_hz, sensor)
            _check_gauge(s, sensor)
        except SensorError as exc:
            raise ScenarioError(f'{where}: {exc}') from None
    if sensors and s.substructure_only and s.load.type == 'static':
        raise ScenarioError("sensors: a static load (load.type = 'static') gives one frame, "
                            'nothing a sensor can sample; use load.type harmonic or pulse, or '
                            'read the frame (no sensors)')


def _check_gauge(s: Scenario, sensor: SensorConfig) -> None:
    """Refuse a pile strain gauge off the scenario's piles (pier, pile number, depth)."""
    gauge = gauge_of(sensor)
    if gauge is None:
        return
    piled = (1,) if s.substructure_only else (
        tuple(s.foundation.piled_piers) if s.foundation.model == 'piled' else ())
    what = f'{sensor.name}: at = {sensor.at!r}'
    if gauge.pier not in piled:
        raise SensorError(f'{what}: pier {gauge.pier} has no piles; piled piers: '
                          f'{list(piled)} (foundation.piled_piers; a substructure alone is '
                          'pier01)')
    count = s.piles.rows * s.piles.cols
    if not 1 <= gauge.pile <= count:
        raise SensorError(f'{what}: pile {gauge.pile} does not exist; the group has {count} '
                          f'(1 to {count}, piles.rows x piles.cols)')
    if gauge.depth > s.piles.length:
        raise SensorError(f'{what}: depth {gauge.depth:g} m is below the pile tip; allowed 0 '
                          f'to {s.piles.length:g} m (piles.length)')


def _check_girder(s: Scenario) -> None:
    """Refuse girder values whose beam elements or first bending mode are not finite numbers."""
    b = s.bridge
    element = b.span_length / b.elements_per_span
    values: tuple[float, ...]
    try:   # (a span of 1e-300 m is within the declared range; its element**3 is 0)
        values = (12.0 * b.bending_stiffness / element**3, b.mass_per_length * element,
                  span_frequency(b.span_length, b.bending_stiffness, b.mass_per_length))
    except (ZeroDivisionError, OverflowError):
        values = (math.inf,)
    if not all(math.isfinite(v) and v > 0.0 for v in values):
        message = (f'bridge.span_length = {b.span_length:g} m over bridge.elements_per_span = '
                   f'{b.elements_per_span} gives beam elements of {element:g} m, whose stiffness '
                   f'with bridge.bending_stiffness = {b.bending_stiffness:g} N*m^2 and '
                   f'bridge.mass_per_length = {b.mass_per_length:g} kg/m is not a finite '
                   'number: give a span of a bridge (metres)')
        raise ScenarioError(message)


def _check_piled(s: Scenario) -> None:
    """Refuse piled piers that are not piers, or a coupling the solver cannot do."""
    fd, solver = s.foundation, s.solver
    if fd.model != 'piled':
        if solver.coupling == 'monolithic':
            raise ScenarioError("solver.coupling = 'monolithic' needs foundation.model = "
                                "'piled' (there is no substructure to couple)")
        return
    last = s.bridge.n_spans
    outside = [p for p in fd.piled_piers if not 2 <= p <= last]
    if outside:
        raise ScenarioError(f'foundation.piled_piers = {list(fd.piled_piers)!r}: '
                            f'{outside[0]} is not a pier; allowed: 2 to {last} (supports 1 and '
                            f'{last + 1} are the abutments of bridge.n_spans = {last})')
    if not s.cap.enabled:
        raise ScenarioError("foundation.model = 'piled' needs cap.enabled = true (the pier "
                            'stands on the cap)')
    if solver.coupling == 'monolithic' and solver.substructure_steps != 1:
        raise ScenarioError(f"solver.coupling = 'monolithic' needs solver.substructure_steps = "
                            f'1 (got {solver.substructure_steps}): one system has one step')
    if solver.variant == 'reduced' and solver.coupling == 'monolithic':
        raise ScenarioError("solver.variant = 'reduced' does not support solver.coupling = "
                            "'monolithic' (the piled piers inside the track-bridge system); "
                            "allowed: 'partitioned', or solver.variant qdldl, cholmod, "
                            'superlu_sym, reference')
    _check_substructure(s)


MAX_SOIL_NODES = 600_000
"""Most brick-mesh nodes a pile-soil substructure may have (1.8 million DOFs, about 8 GiB;
pile_harmonic: 250 000)."""


def _check_substructure(s: Scenario) -> None:
    """Refuse a substructure that does not fit together or is too large, before building it."""
    spec = s.substructure()
    check_substructure(spec, s.load)
    nodes = planned_nodes(spec)
    if nodes > MAX_SOIL_NODES:
        m = spec.mesh
        raise ScenarioError(
            f'the soil mesh would have {nodes} nodes (about {3 * nodes:.3g} DOFs), over the '
            f'limit of {MAX_SOIL_NODES}: raise soil.mesh.h = {m.h:g} m, soil.mesh.h_max = '
            f'{m.h_max:g} m or soil.mesh.growth = {m.growth:g}, or reduce soil.block.lx = '
            f'{s.soil.block.lx:g} m, soil.block.ly = {s.soil.block.ly:g} m')


MAX_MODEL_NODES = 200_000
"""Most finite-element nodes a scenario may ask for (about 1.2 million DOFs; paper_ttbi: 8 000)."""


def model_nodes(s: Scenario) -> int:
    """Count the beam nodes the model of a scenario will have, before building it."""
    nodes = s.bridge.n_spans * (s.bridge.elements_per_span + 1)
    if s.foundation.model in ('springs', 'piled'):
        piers = s.bridge.n_spans - 1 - len(s.foundation.piled_piers)
        nodes += max(piers, 0) * (s.piers.elements + 1)
    if s.track.model == 'slab':
        t = s.track
        units = _extent(s).n_units
        fasteners = units * t.fasteners_per_slab
        nodes += 2 * ((fasteners - 1) * t.rail_elements_per_bay + 1)
        nodes += 2 * units * (t.fasteners_per_slab + 2)
    return nodes


def _check_model_size(s: Scenario) -> None:
    """Refuse a model too large to build (memory and set-up time), before building it."""
    nodes = model_nodes(s)
    if nodes > MAX_MODEL_NODES:
        track = ''
        if s.track.model == 'slab':
            track = (', track.approach_length, track.fastener_spacing, '
                     'track.rail_elements_per_bay')
        raise ScenarioError(
            f'the model would have {nodes} beam nodes (about {6 * nodes:.3g} DOFs), over the '
            f'limit of {MAX_MODEL_NODES}: reduce bridge.n_spans = {s.bridge.n_spans}, '
            f'bridge.span_length = {s.bridge.span_length:g} m, bridge.elements_per_span = '
            f'{s.bridge.elements_per_span}{track}')


def _bridge_length(s: Scenario) -> float:
    return s.bridge.n_spans * s.bridge.span_length


def _extent(s: Scenario) -> TrackExtent:
    return track_extent(s.track, _bridge_length(s), s.train.n_cars * s.train.car_length)


def _check_track_fit(s: Scenario) -> None:
    """Refuse a car run whose wheels would start or end off the modelled rails."""
    if s.train.vehicle != 'car':
        return
    ext = _extent(s)
    offsets = car_layout(s.train, s.car)
    head = s.train.start_position
    where = (f'the modelled rails run from x = {ext.rail_start:.2f} to {ext.rail_end:.2f} m '
             f'(track.approach_length = {s.track.approach_length:g} m'
             f'{" = automatic" if not s.track.approach_length else ""} before and after the '
             f'{_bridge_length(s):g} m bridge)')
    rear, front = head - max(offsets), head - min(offsets)
    if rear < ext.rail_start or front > ext.rail_end:
        raise ScenarioError(
            f'train.start_position = {head:g} m: the axles would start at x = {rear:.2f} .. '
            f'{front:.2f} m, off the track: {where}; move the train or lengthen '
            'track.approach_length')
    speed = s.train.speed
    f1 = span_frequency(s.bridge.span_length, s.bridge.bending_stiffness,
                        s.bridge.mass_per_length)
    if s.solver.duration > 0.0:
        travel = speed * s.solver.duration
        key = f'solver.duration = {s.solver.duration:g} s'
    else:
        exit_position = _bridge_length(s) + max(offsets)
        travel = max(exit_position - head, 0.0) + speed * s.solver.free_vibration_periods / f1
        key = ('solver.duration = 0 (automatic: until the last axle leaves the bridge plus '
               f'solver.free_vibration_periods = {s.solver.free_vibration_periods:g} periods)')
    front_end = front + travel
    if front_end > ext.rail_end:
        raise ScenarioError(
            f'{key}: the run is longer than the track: the front axle would reach '
            f'x = {front_end:.2f} m at {s.train.speed_kmh:g} km/h, but {where}; shorten '
            'solver.duration or lengthen track.approach_length')


def _check_observers(s: Scenario) -> None:
    """Refuse observers on a component the scenario does not have, or off its extent."""
    observers = s.output.points
    length = _bridge_length(s)
    for i, obs in enumerate(observers):
        where = f'output.observers[{i}] = {shown(s.output.observers[i])}'
        if obs.component == 'girder':
            low, high = 0.0, length
        elif s.track.model != 'slab':
            raise ScenarioError(f'{where}: component {obs.component!r} needs '
                                "track.model = 'slab'")
        else:
            ext = _extent(s)
            if obs.component.startswith('rail'):
                low, high = ext.rail_start, ext.rail_end
            else:
                low, high = ext.unit_start, ext.unit_end
        if not low <= obs.x <= high:
            raise ScenarioError(f'{where}: x is not on the {obs.component}, which runs from '
                                f'{low:g} to {high:g} m')
