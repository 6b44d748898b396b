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
A data-set spec: the base scenario, the priors over its keys, the design and the features.

.. code-block:: yaml

    scenario: live_coupled          # a built-in or a YAML path (relative to this file)
    n: 200                          # cases
    sampler: sobol                  # sobol | lhs | random
    seed: 1                         # of the design (the scenario keeps its own seeds)
    priors:
      train.speed_kmh: {uniform: [200, 350]}
      environment.temperature: {normal: [15, 8]}
      soil.layers[0].E: {lognormal: [15.2, 0.3]}
      damage.girders[0].loss: {choice: [0.0, 0.2, 0.4]}
    set: ['sensor_layouts=[span:7, pier:7]']   # overrides applied to every case first
    duration: 2.0                   # solver.duration of every case (s); default the scenario's
    keep_bags: true                 # keep each case's bag (false: features and labels only)
    features: {psd_fmin_hz: 0.5, psd_fmax_hz: 50, psd_points: 64, truth: true}

Every key is checked before any case runs: the priors' families and parameters, and
the scenario at each prior's extreme drawn values (and at every choice), so a prior
reaching outside a key's range is refused with the key, the value and the range.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

from ttb_sim.config import load_scenario, read_yaml
from ttb_sim.declarations import param
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import read_user_file, shown
from ttb_sim.twin.features import FeatureSpec
from ttb_sim.twin.priors import draw_cases, parse_prior, Prior, SAMPLERS

__all__ = ['DatasetSpec', 'MAX_CASES', 'read_spec']

MAX_CASES = 100_000
"""Most cases one data set accepts."""
MAX_SPEC_BYTES = 1 << 20
"""Largest spec file read."""
CONTRACT = ('scenario', 'n', 'sampler', 'seed', 'priors')
"""The keys every spec may give (``scenario``, ``n`` and ``priors`` it must give)."""
KEYS = (*CONTRACT, 'set', 'duration', 'keep_bags', 'storage', 'features')
"""Every key of a spec."""


@dataclass(frozen=True)
class DatasetSpec:
    """A validated data-set spec."""

    scenario: str = param('', '-', 'The base scenario: a built-in name or a YAML path.')
    n: int = param(0, '-', 'Number of cases.', low=1, high=MAX_CASES)
    sampler: str = param('sobol', '-', 'The design over the priors (scipy.stats.qmc: scrambled '
                         'Sobol points, Latin hypercube, or independent uniforms).',
                         choices=SAMPLERS)
    seed: int = param(0, '-', 'Seed of the design.', low=0, high=2 ** 63 - 1)
    priors: tuple[Prior, ...] = field(default=())
    overrides: tuple[str, ...] = param((), '-', 'KEY=VALUE overrides applied to every case '
                                       'first (the spec key ``set``).')
    duration: float = param(0.0, 's', "solver.duration of every case (0: the scenario's).",
                            low=0.0, high=1e5)
    keep_bags: bool = param(True, '-', "Keep each case's bag (false: labels and features).")
    storage: str = param('mcap', '-', 'Bag storage of each case.', choices=('mcap', 'sqlite3'))
    features: FeatureSpec = field(default_factory=FeatureSpec)

    def to_dict(self) -> dict[str, Any]:
        """Return the spec as plain data, priors as given (saved with the data set)."""
        from dataclasses import asdict
        plain = {k: v for k, v in asdict(self).items() if k not in ('priors', 'overrides')}
        plain['set'] = list(self.overrides)
        plain['priors'] = {p.key: p.describe() for p in self.priors}
        return plain

    def case_values(self, values: Mapping[str, Any]) -> list[tuple[str, Any]]:
        """Return the ``(key, value)`` settings of a case: its drawn values, then the duration."""
        out = list(values.items())
        if self.duration:
            out.append(('solver.duration', self.duration))
        return out

    def draw(self) -> list[dict[str, Any]]:
        """Return the ``n`` cases' drawn values (bit for bit the same for the same spec)."""
        return draw_cases(self.priors, self.n, self.sampler, self.seed)


def read_spec(path: str | Path, n: int | None = None) -> DatasetSpec:
    """
    Read and check a spec file; ``n`` (``--n``) replaces its ``n``.

    Raises
    ------
    ScenarioError
        Naming the key, the value and what is allowed, before any case runs.

    """
    import yaml
    from ttb_sim.config.loader import yaml_problem
    path = Path(path)
    text = read_user_file(path, 'dataset spec', MAX_SPEC_BYTES)
    try:
        data = read_yaml(text, str(path))
    except yaml.YAMLError as exc:
        raise ScenarioError(f'dataset spec {shown(str(path))} is not valid YAML: '
                            f'{yaml_problem(exc)} (in a flow mapping {{...}} a key with '
                            "[index] must be quoted: {'soil.layers[0].E': ...})") from None
    if not isinstance(data, Mapping):
        raise ScenarioError(f'dataset spec {shown(str(path))} must be a mapping of keys '
                            f'({", ".join(CONTRACT)}, ...), got {shown(data)}')
    data = dict(data)
    _refuse_unknown(data)
    if n is not None:
        data['n'] = n
    for key in ('scenario', 'n', 'priors'):
        if key not in data:
            raise ScenarioError(f'dataset spec {shown(str(path))} has no {key!r}; it needs '
                                'scenario, n and priors (see docs/twin.md)')
    return spec_from_mapping(data, path.parent)


def spec_from_mapping(data: Mapping[str, Any], base: Path = Path('.')) -> DatasetSpec:
    """Build and check a spec from plain data (a scenario path is relative to ``base``)."""
    from ttb_sim.config.schema import from_mapping
    data = dict(data)
    _refuse_unknown(data)
    priors = data.pop('priors', None)
    features = data.pop('features', None) or {}
    if not isinstance(priors, Mapping) or not priors:
        raise ScenarioError(f'priors = {shown(priors)}: give a mapping of scenario keys to '
                            'priors, e.g. {train.speed_kmh: {uniform: [200, 350]}}')
    if 'set' in data:
        given = data.pop('set')
        data['overrides'] = [given] if isinstance(given, str) else given
    scenario = data.get('scenario')
    if isinstance(scenario, str) and scenario.endswith(('.yaml', '.yml')) and \
            not Path(scenario).is_absolute() and (base / scenario).is_file():
        data['scenario'] = str((base / scenario).resolve())
    spec: DatasetSpec = from_mapping(data, DatasetSpec)
    spec = _with(spec, priors=tuple(parse_prior(str(k), v) for k, v in priors.items()),
                 features=from_mapping(features, FeatureSpec, 'features.'))
    _check_cases(spec)
    return spec


def _refuse_unknown(data: Mapping[str, Any]) -> None:
    unknown = sorted(str(k) for k in data if k not in KEYS)
    if unknown:
        raise ScenarioError(f'unknown key {shown(unknown[0])} in the dataset spec; allowed: '
                            f'{", ".join(KEYS)}')


def _with(spec: DatasetSpec, **changes: Any) -> DatasetSpec:
    from dataclasses import replace
    return replace(spec, **changes)


def _check_cases(spec: DatasetSpec) -> None:
    """
    Load the scenario at every prior's extremes and choices (ScenarioError naming the key).

    The scenario is loaded with the spec's overrides alone, then with each prior's
    probes alone (the other keys as the scenario has them), then at the first case.
    Each case is loaded again by its worker before it runs (a rule joining two keys
    can still refuse one case; it is recorded as failed, not fatal).
    """
    if not spec.scenario:
        raise ScenarioError("scenario = '': give a built-in name or a YAML path")
    base = load_scenario(spec.scenario, spec.overrides, spec.case_values({}))
    if base.substructure_only:
        raise ScenarioError(f'scenario = {shown(spec.scenario)} runs the pile-soil substructure '
                            'alone (load.type is not none); a data set needs passages')
    cases = spec.draw()
    for prior in spec.priors:
        column = [c[prior.key] for c in cases]
        if prior.is_numeric:
            probes = sorted({min(column), max(column)} | set(
                prior.parameters if prior.kind == 'choice' else ()))
        else:
            probes = list(prior.parameters)
        for value in probes:
            try:
                load_scenario(spec.scenario, spec.overrides, spec.case_values({prior.key: value}))
            except ScenarioError as exc:
                raise ScenarioError(f'priors.{prior.key} = {shown(prior.describe())} draws '
                                    f'{shown(value)}, which the scenario refuses: {exc}') \
                    from None
    try:
        load_scenario(spec.scenario, spec.overrides, spec.case_values(cases[0]))
    except ScenarioError as exc:
        raise ScenarioError(f'the first case ({shown(cases[0])}) is refused by the scenario: '
                            f'{exc}') from None
