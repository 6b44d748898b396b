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
The ground truth of a run, as labels: the state a twin pipeline is asked to recognise.

Labels are written to ``summary.json`` (``labels``), to the bag's metadata
(``custom_data`` key :data:`LABELS_KEY`) and on the latched ``~/labels`` topic: the
scenario, the damage and environment state (the ``damage`` and ``environment``
sections, empty when the scenario has none), the train (its vehicle model, the
cars the model runs, :meth:`~ttb_sim.config.records.Scenario.car_count`: one per axle
when the axles are placed by hand, whatever ``train.n_cars`` says; its axles and its
speed), the track irregularity and every seed.

Where the labels change during a run (the live node's speed, damage and environment
parameters), every change is a message of the labels' topic, stamped when it took
effect; the bag's ``custom_data`` is rewritten at each change and so holds the last
labels written to the bag (those of its last frames) when it is closed.
"""

from __future__ import annotations

import json
from typing import Any, Mapping, TYPE_CHECKING

if TYPE_CHECKING:
    from ttb_sim.config.records import Scenario

__all__ = ['LABELS_KEY', 'labels_json', 'run_labels']

LABELS_KEY = 'ttb_sim.labels'
"""The key of the labels (JSON) in a bag's ``custom_data``."""

STATE_SECTIONS = ('damage', 'environment')
"""Scenario sections that describe the state of the structure and its surroundings."""


def run_labels(scenario: Scenario, speed_kmh: float | None = None) -> dict[str, Any]:
    """
    Return the labels of a run of ``scenario`` (plain data, JSON-ready).

    Parameters
    ----------
    scenario : Scenario
        The validated scenario.
    speed_kmh : float, optional
        The train speed now (the node changes it); default the scenario's.

    """
    plain = scenario.to_dict()
    labels: dict[str, Any] = {'scenario': scenario.name}
    for section in STATE_SECTIONS:
        labels[section] = plain.get(section, {})
    if scenario.substructure_only:
        labels['load'] = plain['load']
    else:
        train = plain['train']
        labels['train'] = {'vehicle': train['vehicle'], 'n_cars': scenario.car_count(),
                           'n_axles': len(scenario.axle_positions()),
                           'speed_kmh': train['speed_kmh'] if speed_kmh is None
                           else float(speed_kmh)}
        for key in ('passenger_load',):
            if key in train:
                labels['train'][key] = train[key]
        labels['foundation'] = {'model': plain['foundation']['model'],
                                'piled_piers': plain['foundation'].get('piled_piers', [])}
        irr = plain['irregularity']
        labels['irregularity'] = {k: irr[k] for k in ('spectrum', 'seed', 'scale', 'file')
                                  if k in irr}
    labels['seeds'] = {'irregularity': scenario.irregularity.seed,
                       'sensors': {s.name: s.rng_seed for s in scenario.all_sensors}}
    return labels


def labels_json(labels: Mapping[str, Any]) -> str:
    """Return the labels as the JSON text of the bag's ``custom_data`` (keys sorted)."""
    return json.dumps(labels, sort_keys=True)
