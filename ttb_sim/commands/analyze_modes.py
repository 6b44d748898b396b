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
The modes section of ``ttb-sim analyze``: modes identified from the sensors beside the model's.

:func:`modes_section` takes the bag's accelerometer channels
(:func:`ttb_sim.io.sensor_records.accelerometer_records`), cuts the window (``free``: from
:data:`~ttb_sim.io.sensor_records.FREE_MARGIN_S` after the last axle has left the bridge,
placed by the odometry's head position, or by the scenario's speed without it, to the end
of the record;
``whole``: the whole record, e.g. ambient vibration), identifies the modes
(:func:`ttb_sim.analysis.oma.identify_modes`, SSI-data of ``strid``) and sets beside them
the modes of the model of the bag's scenario echo (``summary.json``), as ``ttb-sim modes``
builds and solves it (:func:`ttb_sim.sensors.modal.structure_modes`), with their shapes at
the same channels, paired by MAC (:func:`ttb_sim.analysis.oma.pair_modes`). Where the bag
has too few channels, no echo to place the window, or too short a window, the section says
why and nothing else fails.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
import logging
from pathlib import Path
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from ttb_sim.analysis.oma import (Identification, IdentificationError, identify_modes,
                                  MIN_CHANNELS, ModelMode, pair_modes, unit_shapes)
from ttb_sim.commands.analyze import MODES_WINDOWS
from ttb_sim.errors import TtbSimError
from ttb_sim.io.sensor_records import (accelerometer_records, FREE_MARGIN_S, Records,
                                       StillOnBridge, train_exit_time)
from ttb_sim.io.streams import Streams
from ttb_sim.report.modes import MODES_HEAD, modes_metrics, modes_rows, stabilisation_plot
from ttb_sim.report.output import FigureNote

if TYPE_CHECKING:
    from ttb_sim.config import Scenario

__all__ = ['ModesSection', 'modes_section', 'scenario_of', 'WINDOWS']

log = logging.getLogger(__name__)

WINDOWS = MODES_WINDOWS
"""Windows of ``--modes-window``: free vibration after the train, or the whole record."""
FIGURE = 'modes.png'


@dataclass
class ModesSection:
    """The ``modes`` section of ``metrics.json``, its table and (when identified) its figure."""

    metrics: dict[str, Any]
    draw: Callable[[Path], FigureNote] | None = None

    @property
    def reason(self) -> str | None:
        """Return why the section was skipped (None when modes were identified)."""
        return self.metrics.get('reason') if self.metrics.get('status') == 'skipped' else None

    def table(self) -> tuple[str, list[str], list[list[Any]]]:
        """Return (heading, head, rows) of the section's table in ``index.html``."""
        heading = 'Modes: identified from the sensors (SSI-data) beside the model'
        if self.reason is not None:
            return heading, ['skipped'], [[self.reason]]
        window = self.metrics['window']
        note = (f"{window['kind']} window t = {window['start_s']:.3f}..{window['end_s']:.3f} s,"
                f" {len(self.metrics['channels'])} channels")
        return f'{heading} ({note})', list(MODES_HEAD), modes_rows(self.metrics)


def _skipped(reason: str) -> ModesSection:
    log.info('modes skipped: %s', reason)
    return ModesSection({'status': 'skipped', 'reason': reason})


def scenario_of(s: Streams) -> tuple[Scenario | None, str]:
    """
    Return the scenario of the bag and where it came from (None and why without one).

    The echo of ``summary.json``, else the scenario ``ttb-sim run`` stores in the bag's
    ``metadata.yaml`` (:func:`ttb_sim.io.passage.recorded_scenario`).
    """
    from ttb_sim.io.passage import recorded_scenario

    echo, source = s.scenario, "summary.json's scenario echo"
    if not echo:
        echo, source = recorded_scenario(s.path), "the scenario in the bag's metadata.yaml"
    if not echo:
        return None, ('the bag has no scenario (no summary.json beside it, none in its '
                      'metadata.yaml)')
    from ttb_sim.config import from_mapping, Scenario
    from ttb_sim.config.conditions import check_conditions

    try:
        scenario = from_mapping(echo, Scenario)
        check_conditions(scenario)
    except (TtbSimError, ValueError, TypeError) as exc:
        return None, f"the bag's scenario cannot be read back ({exc})"
    return scenario, source


def _placed(records: Records, scenario: Scenario | None) -> Records:
    """Return the records with the places the bag does not describe taken from the scenario."""
    if scenario is None or all(c.place for c in records.channels):
        return records
    places = {c.name: c.at for c in scenario.all_sensors}
    channels = tuple(c if c.place else dataclasses.replace(c, place=places.get(c.sensor, ''))
                     for c in records.channels)
    return dataclasses.replace(records, channels=channels)


def _window(records: Records, s: Streams, scenario: Scenario | None, why: str,
            kind: str) -> tuple[Records, dict[str, Any]]:
    """Return the records of the window and its description; raise why there is none."""
    exit_time = None
    if kind == 'free':
        if scenario is None:
            raise IdentificationError(f'{why}: the free-vibration window after the train '
                                      'cannot be placed; --modes-window whole analyses the '
                                      'whole record')
        if scenario.substructure_only:
            raise IdentificationError(f'{scenario.name} is a substructure run without a '
                                      'train: no free vibration after a passage; '
                                      '--modes-window whole analyses the whole record')
        try:
            exit_time = train_exit_time(s, scenario)
        except StillOnBridge as exc:
            raise IdentificationError(f'{exc}: no free vibration to identify; --modes-window '
                                      'whole analyses the whole record') from None
        start = exit_time + FREE_MARGIN_S
        if start >= records.t[-1]:
            raise IdentificationError(
                f'the record ends at t = {records.t[-1]:.3f} s, before the free vibration '
                f'(the last axle leaves the bridge at {exit_time:.3f} s): lengthen '
                'solver.free_vibration_periods or solver.duration')
        records = records.between(start, float(records.t[-1]))
    start, end = float(records.t[0]), float(records.t[-1])
    return records, {'kind': kind, 'start_s': start, 'end_s': end, 'duration_s': end - start,
                     'train_exit_s': exit_time, 'margin_s': FREE_MARGIN_S if exit_time else 0.0}


def _model(scenario: Scenario | None, source: str, records: Records, ident: Identification,
           highest_hz: float) -> tuple[list[ModelMode] | None, dict[str, Any]]:
    """Return the model's modes at the channels and their description (None and why)."""
    if scenario is None:
        return None, {'reason': f'{source}: the model modes are not computed'}
    from ttb_sim.sensors.modal import channel_modes, FIRST_COUNT, NEAR_COUNT

    try:
        structure, found, shapes = channel_modes(
            scenario, [(c.place, c.axis) for c in records.channels],
            [m.frequency_hz for m in ident.modes], highest_hz)
    except (TtbSimError, ValueError) as exc:
        return None, {'reason': f'the model of {scenario.name} cannot be solved: {exc}'}
    model = unit_shapes([ModelMode(float(f), float(z), shapes[:, k]) for k, (f, z)
                         in enumerate(zip(found.frequencies, found.damping_ratios))])
    about = {'scenario': scenario.name, 'source': f'{source}, built and solved as ttb-sim '
             'modes does', 'free_dofs': structure.n_free, 'highest_hz': highest_hz,
             'modes': f'the {FIRST_COUNT} lowest and the {NEAR_COUNT} nearest each '
             'identified frequency, up to highest_hz',
             'channels_with_shape': int(np.sum(np.any(np.isfinite(shapes), axis=1)))
             if shapes.size else 0}
    return model, about


def modes_section(s: Streams, window: str = 'free') -> ModesSection:
    """
    Return the modes section of one bag: identified, paired with the model's, or why not.

    Raises
    ------
    ValueError
        For a window not in :data:`WINDOWS` (the CLI refuses it first).

    """
    if window not in WINDOWS:
        raise ValueError(f'window {window!r}: allowed {", ".join(WINDOWS)}')
    records = accelerometer_records(s)
    if len(records.channels) < MIN_CHANNELS:
        have = ', '.join(c.name for c in records.channels) or 'none'
        return _skipped(f'the bag has {len(records.channels)} accelerometer channel(s) ({have});'
                        f' operational modal analysis needs at least {MIN_CHANNELS} at one '
                        "rate: add sensors (e.g. --set 'sensor_layouts=[span:1]', "
                        'docs/sensors.md)')
    scenario, why = scenario_of(s)
    records = _placed(records, scenario)
    try:
        records, about = _window(records, s, scenario, why, window)
    except IdentificationError as exc:
        return _skipped(str(exc))
    highest = 0.4 * records.rate
    if records.passband_hz is not None:
        highest = min(highest, records.passband_hz)
    try:
        ident = identify_modes(records.values, records.rate, highest_hz=highest)
    except IdentificationError as exc:
        return _skipped(f"{about['kind']} window t = {about['start_s']:.3f}.."
                        f"{about['end_s']:.3f} s: {exc}")
    model, model_about = _model(scenario, why, records, ident, highest)
    pairs = pair_modes(ident.modes, model or [])
    metrics = modes_metrics(ident, records, about, model, pairs, model_about)
    if not ident.modes:
        metrics['note'] = ('no cluster of stable poles: the window holds no mode above the '
                           'noise (see the stabilisation diagram)')
    frequencies = [m.frequency_hz for m in model or []   # those the channels see
                   if m.shape is None or np.any(np.nan_to_num(m.shape))]
    return ModesSection(metrics, lambda out: _figure(out, ident, records, frequencies, about))


def _figure(out: Path, ident: Identification, records: Records, model: list[float],
            window: dict[str, Any]) -> FigureNote:
    title = (f'Stabilisation diagram, SSI-data: {len(records.channels)} accelerometer '
             f"channels, {window['kind']} window {window['start_s']:.2f}-{window['end_s']:.2f} s")
    path = stabilisation_plot(out / FIGURE, ident, records, model, title)
    found = ', '.join(f'{m.frequency_hz:.3f} Hz ({100 * m.damping_ratio:.2f} %)'
                      for m in ident.modes) or 'none'
    return FigureNote(path.name, 'Poles of SSI-data by model order (stable: filled), the '
                      'identified modes (solid) and the model modes the channels see (dashed) '
                      'over the '
                      f'summed PSD of the channels; identified {found}.')
