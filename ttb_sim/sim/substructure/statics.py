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
The static solution of a pile-soil block under a load applied in increments.

:func:`static_solve` iterates each increment to equilibrium with the current
interface tangent and commits the Desai slip. Each iteration is solved by
conjugate gradients preconditioned with the exact inverse of the pile, cap and
interface block (the implicit DOFs of the mixed scheme) and the soil diagonal,
so the whole 3-D soil is never factorised; or, for models small enough, by a
direct factorisation of the whole tangent (the reference path).
"""

from __future__ import annotations

from dataclasses import replace
import inspect

import numpy as np
import scipy.sparse.linalg as sla

from ttb_sim.errors import SimulationError
from ttb_sim.fe.factorization import factorize
from ttb_sim.model.foundation.substructure import PileSoilModel
from ttb_sim.sim.substructure.stable_step import implicit_dofs
from ttb_sim.sim.substructure.state import initial_state, interface_response, State

_CG_TOLERANCE = 'rtol' if 'rtol' in inspect.signature(sla.cg).parameters else 'tol'
"""The relative-tolerance argument of scipy's cg: 'rtol' from scipy 1.12, 'tol' before (the
Debian bookworm scipy 1.10 that a ROS 2 Jazzy build uses)."""


def static_solve(model: PileSoilModel, force: np.ndarray, increments: int = 5,
                 tolerance: float = 1e-6, max_iterations: int = 50,
                 cg_tolerance: float = 1e-10, direct: bool = False,
                 factorization: str = 'cholmod') -> State:
    """
    Return the static state under ``force`` (N), applied in equal increments.

    [P] section 2.4: each increment is iterated to equilibrium and the slip
    committed. Each Newton iteration (current interface tangent) is solved by
    preconditioned conjugate gradients: the preconditioner inverts the pile,
    cap and interface block exactly (factorised once, by ``factorization`` as
    in :class:`~ttb_sim.sim.substructure.stepping.PartitionedNewmark`) and
    the soil diagonal, so the stiffness contrast between piles and soil costs
    nothing and the whole 3-D soil is never factorised. ``direct=True``
    instead solves each iteration with a direct factorisation of the whole
    initial tangent (modified Newton, the current tangent refactorised when an
    increment needs more than 15 iterations, as
    :class:`~ttb_sim.sim.substructure.stepping.PartitionedNewmark`): the
    reference path, for models small enough.

    Raises
    ------
    SimulationError
        If the boundary leaves rigid-body motion (dashpots only) or the
        iterations do not converge.

    """
    if model.spec.soil.boundary == 'lysmer':
        raise SimulationError("a static load needs soil.boundary 'viscoelastic', 'fixed' or "
                              "'rigid_base'; 'lysmer' (dashpots only) leaves the block floating")
    free = np.flatnonzero(model.free)
    k_lin = model.linear_stiffness()
    k_lin_free = k_lin[free][:, free]
    k0 = (k_lin + model.initial_interface_stiffness()).tocsr()[free][:, free]
    block = np.flatnonzero(implicit_dofs(model)[free])
    diagonal = k0.diagonal()
    block_factor = (factorize(k0[block][:, block], method=factorization)
                    if len(block) and not direct else None)

    def precondition(r: np.ndarray) -> np.ndarray:
        x = r / diagonal
        if block_factor is not None:
            x[block] = block_factor.solve(r[block])
        return x

    preconditioner = sla.LinearOperator(k0.shape, matvec=precondition, dtype=float)
    state = initial_state(model)
    u = state.u.copy()
    slip = state.slip
    scale = max(float(np.linalg.norm(force)), 1e-30)
    # direct: modified Newton on the initial tangent, refactorised at the current tangent
    # when an increment needs more than 15 iterations (as PartitionedNewmark)
    direct_factor = factorize(k0, method=factorization) if direct else None
    for step in range(1, increments + 1):
        target = force * step / increments
        for it in range(max_iterations):
            f_ifc, tangent, _ = interface_response(model, u, slip)
            residual = target[free] - k_lin_free @ u[free] - f_ifc[free]
            if np.linalg.norm(residual) <= tolerance * scale:
                break
            k_t = k_lin_free
            if tangent is not None:
                assert model.interface is not None
                k_t = k_lin_free + model.interface.stiffness(tangent)[free][:, free]
            if direct_factor is not None:
                if it > 0 and it % 15 == 0:
                    direct_factor = factorize(k_t, method=factorization)
                du = direct_factor.solve(residual)
            else:
                du, info = sla.cg(k_t, residual, M=preconditioner, maxiter=20 * len(free),
                                  **{_CG_TOLERANCE: cg_tolerance})
                if info != 0:
                    raise SimulationError(f'static solve: conjugate gradients stopped ({info})')
            u[free] += du
            if model.interface is None:
                break
        else:
            raise SimulationError(f'static iterations did not converge in increment {step}')
        if model.interface is not None:
            slip = interface_response(model, u, slip)[2]
    return replace(state, u=u, slip=slip)
