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
Priors over scenario keys, and the designs that draw cases from them.

A prior is one of ``{uniform: [a, b]}``, ``{normal: [mean, sd]}``,
``{lognormal: [mu, sigma]}`` (of the logarithm, as numpy and scipy take it) or
``{choice: [v1, v2, ...]}``.  :func:`draw_cases` maps a design on the unit cube
through each prior's quantile function: ``sobol`` (scrambled Sobol' points, the
design of choice for smooth responses and sensitivity studies), ``lhs`` (Latin
hypercube) or ``random`` (independent uniforms), all from :mod:`scipy.stats.qmc`
and seeded, so the same spec draws the same cases bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
import math
from typing import Any, Mapping, Sequence

import numpy as np

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown

__all__ = ['draw_cases', 'parse_prior', 'Prior', 'SAMPLERS']

SAMPLERS = ('sobol', 'lhs', 'random')
"""The designs ``sampler`` may name."""
KINDS = ('uniform', 'normal', 'lognormal', 'choice')
"""The prior families."""
MAX_CHOICES = 1000
"""Most values a ``choice`` prior may list."""


@dataclass(frozen=True)
class Prior:
    """One scenario key's prior: a family and its parameters (or its choices)."""

    key: str
    kind: str
    parameters: tuple[Any, ...]

    def quantile(self, u: np.ndarray) -> list[Any]:
        """Return the values at probabilities ``u`` (each in [0, 1)), as plain Python."""
        from scipy import stats
        u = np.asarray(u, dtype=float)
        if self.kind == 'choice':
            picks = np.minimum((u * len(self.parameters)).astype(int), len(self.parameters) - 1)
            return [self.parameters[i] for i in picks]
        if self.kind == 'uniform':
            a, b = self.parameters
            values = a + (b - a) * u
        elif self.kind == 'normal':
            values = stats.norm.ppf(u, loc=self.parameters[0], scale=self.parameters[1])
        else:
            mu, sigma = self.parameters
            values = np.exp(stats.norm.ppf(u, loc=mu, scale=sigma))
        return [float(v) for v in values]

    def describe(self) -> dict[str, Any]:
        """Return the prior as the spec gives it (``{'uniform': [a, b]}``)."""
        return {self.kind: list(self.parameters)}

    @property
    def is_numeric(self) -> bool:
        """Return True when the prior draws numbers (every family but a choice of others)."""
        return self.kind != 'choice' or all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in self.parameters)


def parse_prior(key: str, value: Any) -> Prior:
    """
    Read one prior of a spec (``{uniform: [a, b]}`` ...) for scenario key ``key``.

    Raises
    ------
    ScenarioError
        Naming the key, the value and what is allowed.

    """
    where = f'priors.{key} = {shown(value)}'
    if not isinstance(value, Mapping) or len(value) != 1:
        raise ScenarioError(f'{where}: give one family, e.g. {{uniform: [a, b]}}; families: '
                            f'{", ".join(KINDS)}')
    kind, args = next(iter(value.items()))
    if kind not in KINDS:
        raise ScenarioError(f'{where}: unknown family {shown(kind)}; allowed: {", ".join(KINDS)}')
    if not isinstance(args, (list, tuple)):
        raise ScenarioError(f'{where}: the parameters of {kind} must be a list')
    if kind == 'choice':
        if not 1 <= len(args) <= MAX_CHOICES:
            raise ScenarioError(f'{where}: a choice lists 1 to {MAX_CHOICES} values')
        return Prior(key, kind, tuple(args))
    if len(args) != 2 or not all(_is_number(a) for a in args):
        raise ScenarioError(f'{where}: {kind} takes two finite numbers, [{_NAMES[kind]}]')
    first, second = (float(a) for a in args)
    if kind == 'uniform' and not first < second:
        raise ScenarioError(f'{where}: a uniform prior needs a < b')
    if kind in ('normal', 'lognormal') and not second > 0:
        raise ScenarioError(f'{where}: the {_NAMES[kind].split(", ")[1]} must be positive')
    return Prior(key, kind, (first, second))


_NAMES = {'uniform': 'a, b', 'normal': 'mean, sd', 'lognormal': 'mu, sigma'}


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and \
        math.isfinite(value)


def unit_design(n: int, dimensions: int, sampler: str, seed: int) -> np.ndarray:
    """
    Return an (n, dimensions) design on [0, 1)^d.

    Sobol' points are scrambled (Owen) and seeded; an ``n`` that is not a power of
    two loses the balance property only in part (scipy warns; the warning is
    silenced here and the docs say so).
    """
    if sampler not in SAMPLERS:
        raise ScenarioError(f'sampler = {shown(sampler)}: allowed {", ".join(SAMPLERS)}')
    if dimensions == 0:
        return np.zeros((n, 0))
    from scipy.stats import qmc
    if sampler == 'random':
        return np.random.default_rng(seed).random((n, dimensions))
    if sampler == 'lhs':
        return qmc.LatinHypercube(d=dimensions, seed=np.random.default_rng(seed)).random(n)
    import warnings
    engine = qmc.Sobol(d=dimensions, scramble=True, seed=np.random.default_rng(seed))
    with warnings.catch_warnings():
        warnings.simplefilter('ignore', UserWarning)   # balance needs n = 2^m
        return engine.random(n)


def draw_cases(priors: Sequence[Prior], n: int, sampler: str, seed: int
               ) -> list[dict[str, Any]]:
    """Return ``n`` cases, each a mapping of every prior's key to its drawn value."""
    design = unit_design(n, len(priors), sampler, seed)
    columns = [p.quantile(design[:, j]) for j, p in enumerate(priors)]
    return [{p.key: columns[j][i] for j, p in enumerate(priors)} for i in range(n)]
