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
The run interface that the bag writer and the node step, and the one place that picks the model.

:class:`Runner` is what :class:`~ttb_sim.sim.simulation.Simulation` (a train on
the bridge) and :class:`~ttb_sim.sim.substructure.standalone.SubstructureRun` (a
pile-soil substructure alone under its load) both offer; :func:`make_runner`
builds the right one for a scenario.
"""

from __future__ import annotations

from typing import Any, Iterator, Protocol

from ttb_sim.config import Scenario
from ttb_sim.sim.cost import CostEstimate, STEP_BUDGET
from ttb_sim.sim.frames import Frame, Layout
from ttb_sim.sim.simulation import Simulation
from ttb_sim.sim.substructure.standalone import SubstructureRun

__all__ = ['make_runner', 'Runner']


class Runner(Protocol):
    """A built model that steps a scenario to frames."""

    scenario: Scenario
    layout: Layout
    dt: float
    duration: float
    n_steps: int
    output_every: int

    @property
    def n_free(self) -> int:
        """Free DOFs of the model."""

    @property
    def n_frames(self) -> int:
        """Frames the run will write."""

    def plan(self, messages_per_frame: int) -> CostEstimate:
        """Return the cost estimate of the run (before it runs)."""

    def describe(self) -> dict[str, Any]:
        """Return model sizes and stepping details for ``summary.json``."""

    def frames(self) -> Iterator[Frame]:
        """Yield the frames of the run."""


def make_runner(scenario: Scenario, max_steps: float | None = STEP_BUDGET) -> Runner:
    """Build the model of a scenario: the substructure alone when ``load.type`` is set."""
    if scenario.substructure_only:
        return SubstructureRun(scenario, max_steps)
    return Simulation(scenario, max_steps)
