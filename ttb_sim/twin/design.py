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
The forward runs of :func:`~ttb_sim.twin.identify.identify`'s surrogate: its designs.

The first design is a scrambled Sobol' sequence over the priors (probability scale,
:func:`design_size` runs by default); ``--refine`` adds a second one over the first
posterior's box (:func:`refined_design`).  :class:`DesignRuns` runs them through a
runner (:func:`~ttb_sim.twin.forward.evaluate_many`) and keeps what succeeded, in
design order whatever finished first.
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.twin.forward import DesignRun, evaluate_many, ForwardModel, Runner
from ttb_sim.twin.priors import Prior, unit_design

__all__ = ['design_size', 'DesignRuns', 'refined_design', 'shown_theta']


def design_size(design: int, n_keys: int) -> int:
    """Return the first design's runs: ``design``, or 8 d + 8 when it is 0."""
    return design or 8 * n_keys + 8


class DesignRuns:
    """The forward runs of the surrogate's designs, in design order, and their progress."""

    def __init__(self, model: ForwardModel, priors: Sequence[Prior], runner: Runner | None,
                 progress: Callable[[str], None] | None, total: int) -> None:
        self.model, self.priors, self.runner, self.progress = model, priors, runner, progress
        self.total = total
        self.finished = 0
        self.thetas: list[np.ndarray] = []
        self.vectors: list[np.ndarray] = []
        self.failed: list[str] = []

    def run(self, u_design: np.ndarray) -> None:
        """Run the design of ``u_design`` (probability scale); keep what succeeded."""
        design = np.array([[p.quantile(np.array([x]))[0] for p, x in zip(self.priors, u)]
                           for u in u_design])
        records = evaluate_many(self.model, design, self.runner, self._report,
                                first=len(self.thetas) + len(self.failed))
        for theta, record in zip(design, records):   # design order, whatever finished first
            if record['status'] == 'ok':
                self.vectors.append(np.asarray(record['vector']))
                self.thetas.append(theta)
            else:   # a case refused or diverged (or its worker lost): the others go on
                self.failed.append(f'{shown_theta(self.model.keys, theta)}: {record.get("error")}')

    def _report(self, run: DesignRun, record: dict[str, Any]) -> None:
        self.finished += 1
        if self.progress is not None:
            outcome = f'ok in {record.get("wall_time_s") or 0.0:.1f} s' \
                if record['status'] == 'ok' else f'{record["status"]}: {record.get("error")}'
            self.progress(f'design run {self.finished}/{self.total} ({run.name}) at '
                          f'{shown_theta(self.model.keys, np.array(run.theta))}: {outcome}')


REFINE_MARGIN = 0.25
"""The refined design's box: the posterior's 0.5-99.5 % range, widened by this share of it."""


def refined_design(flat_u: np.ndarray, n: int, seed: int) -> np.ndarray:
    """Return ``n`` Sobol' points (probability scale) over the posterior samples' box."""
    low, high = np.quantile(flat_u, [0.005, 0.995], axis=0)
    pad = REFINE_MARGIN * (high - low)
    low, high = np.clip(low - pad, 1e-6, 1 - 1e-6), np.clip(high + pad, 1e-6, 1 - 1e-6)
    return low + (high - low) * unit_design(n, flat_u.shape[1], 'sobol', seed + 1)


def shown_theta(keys: Sequence[str], theta: np.ndarray) -> str:
    """Return 'key=value, ...' for a parameter vector."""
    return ', '.join(f'{k}={v:.6g}' for k, v in zip(keys, theta))
