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
The integrator protocol: what a time integrator offers the couplings and the driver.

A coupling advances a structure together with what rides on it. It needs, of
the structure's integrator, the pieces of one implicit step that it can
interleave with its own unknowns: the history terms that express the end-of-step
velocity and acceleration through the unknown displacement, the effective load,
the action of the effective compliance on any right-hand side (the query the
wheel-rail and quarter-car couplings use for unit wheel loads), and the
finishing update. An uncoupled step is :meth:`Integrator.step`.
:class:`~ttb_sim.sim.integrators.newmark.Newmark` is the first implementation;
a sub-cycled or reduced-order substructure integrator implements the same.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
import scipy.sparse as sp

__all__ = ['Integrator']


class Integrator(Protocol):
    """One implicit time integrator with a constant effective matrix."""

    dt: float
    """Time step (s)."""
    a0: float
    """Coefficient of u_{n+1} in the end-of-step acceleration (1/s^2)."""
    a1: float
    """Coefficient of u_{n+1} in the end-of-step velocity (1/s)."""
    mass: sp.csr_matrix
    """Mass matrix of the integrated system (free DOFs)."""
    damping: sp.csr_matrix
    """Damping matrix."""
    stiffness: sp.csr_matrix
    """Stiffness matrix."""
    method: str
    """Sparse factorisation in use (:func:`ttb_sim.fe.factorization.factorize`)."""
    external: tuple[np.ndarray, np.ndarray] | None
    """Load at t_{n+1} that :meth:`effective_load` adds to the coupling's own, as (DOFs
    (unique), values): the substructures' bearing forces on the girders, set through
    :meth:`~ttb_sim.sim.coupling.base.Coupling.load_bridge` before each step."""

    @property
    def at_slow_step(self) -> bool:
        """Tell whether the state is complete, so that the integrator may be replaced."""

    def fused_arrays(self) -> tuple[np.ndarray, ...] | None:
        """Return the arrays a compiled multi-step loop reads, or None (it does not apply)."""

    @property
    def history_buffer(self) -> np.ndarray:
        """The history vector [h_a | h_v] that :meth:`history` fills (the lean step)."""

    def history(self, u: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return (h_v, h_a): v_{n+1} = a1 u_{n+1} + h_v, a_{n+1} = a0 u_{n+1} + h_a."""

    def effective_load(self, force: np.ndarray, h_v: np.ndarray, h_a: np.ndarray) -> np.ndarray:
        """Return the right-hand side of the effective system for the load at t_{n+1}."""

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Apply the effective compliance to one or several right-hand sides."""

    def finish(self, u_new: np.ndarray, h_v: np.ndarray,
               h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the end-of-step velocity and acceleration."""

    def step(self, u: np.ndarray, v: np.ndarray, a: np.ndarray,
             force: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Advance an uncoupled system by one step."""

    def initial_acceleration(self, u: np.ndarray, v: np.ndarray,
                             force: np.ndarray) -> np.ndarray:
        """Return the acceleration consistent with a start state and load."""
