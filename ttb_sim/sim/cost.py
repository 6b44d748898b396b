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
What a run will cost, told before it starts: steps, DOFs, frames and a wall-time estimate.

The estimate is a model, not a measurement: wall time = fixed overhead + steps x
per-step cost + messages x per-message cost. The per-step cost grows with the
free DOFs of the structure (sparse triangular solves) and with the multibody
cars (wheel-rail contact), times a factor for the solver variant; the
per-message cost is the bag writer's. The constants were fitted to
``ttb-sim run`` and ``ttb-sim bench`` on the project's 2-core machine at a load
average of about 1.7 (ten_span_train, live_train with qdldl and realtime,
paper_ttbi with qdldl, reduced and reference; docs/performance.md for the
variant factors): expect the real time within a factor of about 2 either way,
more on a busy or very different machine.
``ttb-sim bench`` measures the real numbers.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Sequence

__all__ = ['CostEstimate', 'estimate_cost', 'STEP_BUDGET']

STEP_BUDGET = 20_000_000
"""Most time steps a run may plan without ``--force`` (about 1-10 h of wall time)."""

OVERHEAD_S = 0.3
"""Opening and closing the bag, first-step set-up (s)."""
STEP_BASE_MS = 0.02
"""Per-step cost independent of the model size (ms)."""
STEP_PER_DOF_MS = 1.2e-5
"""Per-step cost per free structural DOF (ms)."""
CONTACT_BASE_MS = 0.4
"""Per-step cost of wheel-rail contact for the first multibody car (ms)."""
CONTACT_PER_CAR_MS = 0.18
"""Per-step cost of wheel-rail contact per multibody car (ms)."""
MESSAGE_MS = 0.005
"""Cost of writing one message to the bag (ms)."""
VARIANT_FACTOR = {'qdldl': 1.0, 'cholmod': 1.3, 'superlu_sym': 2.2, 'reference': 5.0,
                  'reduced': 0.45, 'realtime': 0.55}
"""Per-step cost of the structure's solves and mat-vecs for each solver variant relative to
qdldl (docs/performance.md); ``reduced`` only with multibody cars (else it is qdldl)."""
REFERENCE_GROWTH_DOFS = 5000.0
"""The reference's general LU fills in faster than the symmetric orders: its factor above
grows by 1 + free DOFs / this (measured 5x qdldl's step at 1 290 DOFs, 43x at 48 594)."""


@dataclass(frozen=True)
class CostEstimate:
    """The planned work of one run and its estimated wall time."""

    steps: int
    """Time steps planned."""
    dt: float
    """Time step (s)."""
    duration: float
    """Simulated time (s)."""
    free_dofs: int
    """Free DOFs of the structure."""
    cars: int
    """Multibody cars (0 for moving forces and quarter cars)."""
    frames: int
    """Frames written."""
    messages: int
    """Messages written (frames x topics)."""
    per_step_ms: float
    """Estimated cost of one step (ms)."""
    wall_time: float
    """Estimated wall time of the stepping and writing (s), set-up not included; with
    kernels still to compile, their compilation included."""
    threads: str = ''
    """The threads of the parallel kernels and why (:func:`.resolve_threads`)."""
    compiling: tuple[str, ...] = ()
    """Kernels the run will compile on first use (not in numba's disk cache)."""
    compile_time: float = 0.0
    """Estimated CPU time of compiling them (s)."""

    def as_dict(self) -> dict[str, Any]:
        """Return the estimate as plain data (for ``summary.json``)."""
        return asdict(self)

    def describe(self) -> str:
        """Return one line for the user: the plan and the estimated time."""
        line = (f'{self.steps} steps of {self.dt:.3g} s ({self.duration:.4g} s simulated), '
                f'{self.free_dofs} free DOFs, {self.frames} frames x '
                f'{self.messages // max(self.frames, 1)} topics')
        if self.threads:
            line += f', {self.threads}'
        if self.compiling:
            count = len(self.compiling)
            line += (f'; compiling {count} kernel{"s" if count > 1 else ""} on first use '
                     f'(about {_duration(self.compile_time)}, once)')
        return (f'{line}; estimated {_duration(self.wall_time)} (a model: within about 2x)')


COMPILE_S = {'contact_newton': 4.0, 'rail_rows': 1.5, 'rail_predictor': 1.5, 'history': 0.3,
             'finish': 0.3, 'effective_load': 0.3, 'moving_load': 0.3}
"""CPU time (s) of compiling a kernel with numba, where it is far from the typical one
(measured with an empty cache: moving forces' four kernels 0.8 s, the quarter cars' four
6.2 s, the multibody cars' eight 8-12 s)."""
COMPILE_DEFAULT_S = 1.2
"""CPU time (s) of compiling a typical kernel (a loop nest of a few dozen lines)."""


def compile_time(kernels: Sequence[str]) -> float:
    """Return the estimated CPU time (s) of compiling ``kernels`` (names)."""
    return float(sum(COMPILE_S.get(name, COMPILE_DEFAULT_S) for name in kernels))


def estimate_cost(*, steps: int, dt: float, free_dofs: int, cars: int, frames: int,
                  messages_per_frame: int, variant: str, threads: str = '',
                  compiling: Sequence[str] = ()) -> CostEstimate:
    """
    Estimate the wall time of a planned run.

    Parameters
    ----------
    steps : int
        Time steps planned.
    dt : float
        Time step (s).
    free_dofs : int
        Free DOFs of the structure.
    cars : int
        Multibody cars on wheel-rail contact.
    frames : int
        Frames to write.
    messages_per_frame : int
        Messages per frame (topics).
    variant : str
        ``solver.variant``.
    threads : str
        The threads of the parallel kernels and why, for the plan line.
    compiling : sequence of str
        Kernels the run will compile on first use (their compilation joins the
        estimate).

    Returns
    -------
    CostEstimate

    """
    per_step = STEP_BASE_MS + STEP_PER_DOF_MS * free_dofs
    if cars or variant != 'reduced':
        per_step *= VARIANT_FACTOR.get(variant, 1.0)
    if variant == 'reference':
        per_step *= 1.0 + free_dofs / REFERENCE_GROWTH_DOFS
    if cars:
        per_step += CONTACT_BASE_MS + CONTACT_PER_CAR_MS * (cars - 1)
    messages = frames * messages_per_frame
    compiling_s = compile_time(compiling)
    wall = OVERHEAD_S + compiling_s + (steps * per_step + messages * MESSAGE_MS) / 1000.0
    return CostEstimate(steps=steps, dt=dt, duration=steps * dt, free_dofs=free_dofs,
                        cars=cars, frames=frames, messages=messages, per_step_ms=per_step,
                        wall_time=wall, threads=threads, compiling=tuple(compiling),
                        compile_time=compiling_s)


def _duration(seconds: float) -> str:
    if seconds < 120.0:
        return f'{seconds:.2g} s'
    if seconds < 7200.0:
        return f'{seconds / 60.0:.3g} min'
    return f'{seconds / 3600.0:.3g} h'
