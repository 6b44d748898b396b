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
V28 and V29: model updating recovers hidden parameters from a noisy simulated passage.

Each row records a passage of a scenario with a hidden value (its virtual sensors
with their noise), then identifies the key from that bag alone with
:func:`ttb_sim.twin.identify.identify` — the forward model with ideal sensors, a
Sobol' design, the surrogate, the likelihood of the sensors' noise model and emcee —
exactly as ``ttb-sim identify`` does.  A parameter passes when the truth lies inside
the posterior's 90 % interval and the median is within the stated error of it; a key
the data carry nothing about must be reported as not identified.

- V28, girder damage (``moving_force_beam``, span-1 layout, EI -30 % over 14-18 m):
  ``damage.girders[0].loss`` ~ U(0, 0.6); stated error 0.05 (17 % of the truth).  Beside it
  ``bridge.lateral_bending_stiffness`` ~ U(1e11, 1e12), which vertical gauges cannot
  see: its posterior must stay flat (90 % interval >= 70 % of the prior's).
- V28, bearing stiffness (``ten_span_train``, span-1 layout with the bearing LVDT, 2 s):
  ``bearings.vertical_stiffness`` ~ lognormal(ln 5e9, 0.5), hidden 3e9 N/m; stated
  error 15 %.
- V29, soil modulus (``live_coupled``, pier-7 layout: pile-head accelerometers,
  geophones and the pier-top level, 3 s): ``environment.soil_modulus_scale[0]`` (the top
  layer) ~ U(0.4, 1.6), hidden 0.7; stated error 15 %.  Each new soil value builds the
  reduced substructure again (about 15 s a run): about 4 min.
"""

from __future__ import annotations

from pathlib import Path
import tempfile
from typing import Any, Sequence

from ttb_sim.validation.rows import Case, Row

GIRDER = ('moving_force_beam', ['sensor_layouts=[span:1]', 'output.rate_hz=1000',
                                'solver.dt=0.0005'])
BEARING = ('ten_span_train', ['sensor_layouts=[span:1]', 'output.rate_hz=1000',
                              'solver.duration=2.0'])
SOIL = ('live_coupled', ['sensor_layouts=[pier:7]', 'output.rate_hz=1000',
                         'solver.duration=3.0', 'environment.soil_modulus_scale=[1.0, 1.0, 1.0]'])
LOSS_ERROR = 0.05 / 0.3
"""Stated error of the identified girder loss: 0.05 of 0.3."""
RELATIVE_ERROR = 0.15
"""Stated relative error of the identified bearing stiffness and soil modulus scale."""
FLAT = 0.7
"""A key without information must keep a 90 % interval of at least this much of its prior's."""


def identified(scenario: str, overrides: Sequence[str], hidden: Sequence[tuple[str, Any]],
               priors: dict[str, dict[str, list[float]]], sensors: Sequence[str] | None = None,
               design: int = 0) -> dict[str, Any]:
    """Record a passage with hidden values, identify ``priors``' keys from it; the summary."""
    from ttb_sim.config import load_scenario
    from ttb_sim.io.passage import run_to_bag
    from ttb_sim.twin.features import record_length, sensor_features
    from ttb_sim.twin.forward import ForwardModel
    from ttb_sim.twin.identify import data_grid, identify, IdentifySettings
    from ttb_sim.twin.priors import parse_prior
    truth = load_scenario(scenario, overrides, hidden)
    with tempfile.TemporaryDirectory(prefix='ttb-sim-identify-') as scratch:
        bag = Path(scratch) / 'observed'
        result = run_to_bag(truth, bag)
        if result.status != 'ok':
            raise RuntimeError(f'the observed passage {result.status}')
        chosen = [s for s in truth.all_sensors if sensors is None or s.name in sensors]
        record = record_length(bag, chosen)
        spec = data_grid(record, chosen)
        model = ForwardModel(scenario, list(priors), overrides=overrides, features=spec,
                             sensors=[s.name for s in chosen], noise=False)
        observed = sensor_features(bag, model.sensors, spec)
    fit = identify(model, [parse_prior(k, v) for k, v in priors.items()], observed, record,
                   IdentifySettings(design=design))
    return fit.summary()


def recovered_rows(case: str, label: str, summary: dict[str, Any], key: str, truth: float,
                   error: float) -> list[Row]:
    """Rows: the median within the stated relative error, the truth inside the 90 % interval."""
    p = summary['parameters'][key]
    miss = abs(p['median'] - truth) / abs(truth)
    inside = p['q05'] <= truth <= p['q95']
    return [Row(case, f'{label}: median of {key}', p['median'], truth, miss, error,
                miss <= error, ''),
            Row(case, f'{label}: truth inside [{p["q05"]:.4g}, {p["q95"]:.4g}]',
                1.0 if inside else 0.0, 1.0, 0.0 if inside else 1.0, 0.0, inside, '')]


def flat_row(case: str, label: str, summary: dict[str, Any], key: str) -> Row:
    """Row: a key the data cannot see is reported as not identified (a flat posterior)."""
    p = summary['parameters'][key]
    ratio = p['interval_vs_prior']
    ok = ratio >= FLAT and not p['identified']
    return Row(case, f'{label}: {key} reported not identified (90 % interval / prior)',
               ratio, 1.0, abs(1.0 - ratio), 1.0 - FLAT, ok, '')


def v28_rows() -> list[Row]:
    """Return the rows of V28 (see the module docstring)."""
    scenario, overrides = GIRDER
    base = [*overrides, 'damage.girders=[{span: 1, start: 14, length: 4, loss: 0.0}]']
    girder = identified(scenario, base, [('damage.girders[0].loss', 0.3)],
                        {'damage.girders[0].loss': {'uniform': [0.0, 0.6]},
                         'bridge.lateral_bending_stiffness': {'uniform': [1e11, 1e12]}},
                        sensors=['span01_strain_mid', 'span01_acc_mid'], design=16)
    rows = recovered_rows('V28', 'girder loss 0.3', girder, 'damage.girders[0].loss', 0.3,
                          LOSS_ERROR)
    rows.append(flat_row('V28', 'girder loss 0.3', girder, 'bridge.lateral_bending_stiffness'))
    scenario, overrides = BEARING
    bearing = identified(scenario, overrides, [('bearings.vertical_stiffness', 3e9)],
                         {'bearings.vertical_stiffness': {'lognormal': [22.33, 0.5]}},
                         sensors=['span01_bearing_end', 'span01_acc_mid'], design=10)
    rows += recovered_rows('V28', 'bearing 3e9 N/m', bearing, 'bearings.vertical_stiffness',
                           3e9, RELATIVE_ERROR)
    return rows


def v29_rows() -> list[Row]:
    """Return the rows of V29 (see the module docstring)."""
    scenario, overrides = SOIL
    soil = identified(scenario, overrides, [('environment.soil_modulus_scale[0]', 0.7)],
                      {'environment.soil_modulus_scale[0]': {'uniform': [0.4, 1.6]}},
                      design=10)
    return recovered_rows('V29', 'top soil layer E x 0.7', soil,
                          'environment.soil_modulus_scale[0]', 0.7, RELATIVE_ERROR)


TWIN_CASES: tuple[Case, ...] = (
    Case('V28', 'model updating: a hidden girder loss and bearing stiffness recovered from a '
                'noisy passage, a key without information reported flat', v28_rows),
    Case('V29', 'model updating: a hidden top-soil modulus recovered from pile and ground '
                'sensors (about 4 min)', v29_rows),
)
