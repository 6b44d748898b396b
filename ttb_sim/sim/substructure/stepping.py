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
Time stepping of the pile-soil substructure on its own.

Integrator: Newmark's average acceleration (beta = 1/4, gamma = 1/2) in the
implicit-explicit predictor-corrector form of Hughes & Liu (J. Appl. Mech. 45,
1978). Each element group is either *implicit* or *explicit*:

    u~ = u_n + dt v_n + dt^2/4 a_n,     v~ = v_n + dt/2 a_n
    M a + C_I (v~ + dt/2 a) + K_I (u~ + dt^2/4 a) + f_ifc(u~ + dt^2/4 a)
        = F_{n+1} - K_E u~ - C_E v~
    u_{n+1} = u~ + dt^2/4 a,            v_{n+1} = v~ + dt/2 a

with a lumped (diagonal) M. DOFs touched only by explicit elements get
a = (right-hand side) / m directly; the DOFs of implicit elements solve one
small system whose matrix M_I + dt/2 C_I + dt^2/4 (K_I + K_ifc,0) is
factorised once. With every group implicit this is the ordinary Newmark
method (unconditionally stable); explicit groups are stable for
omega_max dt <= 2 (reduced by their stiffness-proportional damping, see
:func:`~ttb_sim.sim.substructure.stable_step.stable_time_step`).

``scheme='mixed'`` makes the soil cells and the boundary explicit and the
piles, cap and interface implicit. The reason is the contrast of wave speeds:
the soft soil (Vs 28-40 m/s) needs a fine mesh but allows a large explicit
step (about h / Vp), while the piles (E = 1e11 Pa, Vp = 6600 m/s) would cut
that step a hundredfold; a direct factorisation of the whole fine 3-D mesh
would need several GiB. In the mixed scheme each step costs one sparse
product with the soil matrices plus a small solve on the pile DOFs.
``scheme='implicit'`` is the fully implicit method for small models.

Interface nonlinearity: inside each step the implicit equations are solved
by Newton iterations, either with the once-factorised initial tangent
(``newton='modified'``, the default: the Desai tangent only softens, so the
initial-stiffness iteration contracts; when a step needs more than 15
iterations, as under heavy slip, the current tangent is factorised afresh
every 15 iterations) or with the current tangent
refactorised at each iteration (``newton='full'``, for checking). The Desai
plastic slip is committed when the step has converged. Output is one
:class:`~ttb_sim.sim.substructure.state.PileSoilFrame` per output interval.

A step whose iterations do not converge is retried, and only such a step: the
steps that converge take the path above unchanged. First full Newton (current
tangent) with a backtracking line search on the residual norm starts from the
best iterate; if that stalls too, the step is cut in two halves (the load
interpolated linearly), each solved the same way and cut again if need be,
down to ``max_cuts`` halvings. The case that needs it: on a refined mesh the
shallowest shaft Gauss points carry a geostatic compression of a few hundred
Pa, so they reach separation under a small opening, and the law's shear
traction drops to zero at separation while the normal one is continuous. When
the step's equilibrium falls inside that jump the separated and the closed
states each lead the iterate into the other (both Newton variants cycle with
period two, the residual stuck above the tolerance); the shorter step, whose
matrix is dominated by 4 M / dt^2, moves the opening less per unit of shear
force and lets the iterations settle on one side. Cuts are logged as
warnings and counted (:meth:`PartitionedNewmark.report`).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
import math
from typing import Callable, Iterator, Literal, Optional

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import DivergenceError, SimulationError
from ttb_sim.fe.factorization import Factorization, factorize
from ttb_sim.model.foundation.substructure import PileSoilModel, rayleigh_coefficients
from ttb_sim.sim.substructure.stable_step import (choose_scheme, implicit_dofs, mixed_stable_step,
                                                  Scheme)
from ttb_sim.sim.substructure.state import initial_state, interface_response, State

LOG = logging.getLogger(__name__)


@dataclass(frozen=True)
class _Predictor:
    """The predicted state of one (sub-)step and the fixed terms of its implicit equations."""

    dt: float
    time: float
    """At the step end (s)."""
    u_p: np.ndarray
    v_p: np.ndarray
    a: np.ndarray
    """Accelerations: explicit DOFs solved, implicit ones set when the step converges."""
    r_i: np.ndarray
    u_i0: np.ndarray
    v_i0: np.ndarray
    scale: float
    """The residual norm the tolerance is relative to."""


class PartitionedNewmark:
    """
    Hughes-Liu implicit-explicit Newmark stepping of a :class:`PileSoilModel`.

    Parameters
    ----------
    model : PileSoilModel
        The substructure.
    dt : float
        Time step (s); in the mixed scheme it must not exceed the stable step.
    scheme : {'mixed', 'implicit'}
        Explicit soil with implicit piles, cap and interface; or all implicit.
    newton : {'modified', 'full'}
        Initial-tangent or current-tangent Newton iterations for the interface.
    tolerance : float
        Relative residual at which the Newton iterations stop.
    max_iterations : int
        Iterations per step before the fall-backs (full Newton with a line
        search, then cutting the step).
    factorization : str
        Method of :func:`ttb_sim.fe.factorization.factorize` for the implicit
        block (symmetric positive definite; CHOLMOD by default).
    max_cuts : int
        Most halvings of a step that does not converge (the shortest sub-step
        is dt / 2**max_cuts); beyond them a :class:`~ttb_sim.errors.SimulationError`.

    Attributes
    ----------
    iterations : int
        Linear solves of the interface iterations so far.
    line_searches : int
        (Sub-)steps that converged only by the full Newton line search.
    cut_steps : int
        Steps of ``dt`` that were cut into sub-steps.
    cuts : int
        Halvings made (a step cut twice over counts two or more).

    """

    def __init__(self, model: PileSoilModel, dt: float,
                 scheme: Literal['mixed', 'implicit'] = 'mixed',
                 newton: Literal['modified', 'full'] = 'modified',
                 tolerance: float = 1e-6, max_iterations: int = 100,
                 factorization: str = 'cholmod', max_cuts: int = 4) -> None:
        self.model = model
        self.factorization = factorization
        self.dt = float(dt)
        self.scheme = scheme
        self.newton = newton
        self.tolerance = tolerance
        self.max_iterations = max_iterations
        self.max_cuts = max_cuts
        self.refresh_after = 15
        self.line_search_iterations = 30
        """Full Newton iterations of the fall-back before the step is cut."""
        self.line_search_min_step = 1.0 / 64
        """Shortest step length of the backtracking before the line search is said to stall."""
        n = model.n_dofs
        free = model.free
        implicit = np.zeros(n, dtype=bool)
        if scheme == 'implicit':
            implicit[:] = True
            k_e = sp.csr_matrix((n, n))
            c_e = sp.csr_matrix((n, n))
            k_i = model.linear_stiffness()
            c_i = model.linear_damping()
        else:
            implicit |= implicit_dofs(model)
            k_e = (model.soil_stiffness + model.boundary_stiffness).tocsr()
            c_e = (model.soil_damping + model.boundary_damping).tocsr()
            k_i = model.structure_stiffness
            c_i = model.structure_damping
        implicit &= free
        self.implicit = np.flatnonzero(implicit)
        self.explicit = np.flatnonzero(free & ~implicit)
        self.has_explicit = k_e.nnz + c_e.nnz > 0
        # Uniform soil damping ratio: K_s u + C_s v = K_s (u + beta v) + alpha M_s v, one product.
        self._fused: Optional[tuple[sp.csr_matrix, float, np.ndarray, sp.csr_matrix]] = None
        self.explicit_operator: Optional[sp.csr_matrix] = None
        zeta = {layer.damping_ratio for layer in model.spec.soil.layers}
        if scheme == 'mixed' and len(zeta) == 1:
            _, beta = rayleigh_coefficients(np.array(list(zeta)),
                                            model.spec.rayleigh_frequencies)
            b = float(beta[0])
            alpha_m = model.soil_damping.diagonal() - b * model.soil_stiffness.diagonal()
            self._fused = (model.soil_stiffness, b, alpha_m,
                           sp.hstack([model.boundary_stiffness,
                                      model.boundary_damping]).tocsr())
        elif self.has_explicit:
            self.explicit_operator = sp.hstack([k_e, c_e]).tocsr()
        idx = self.implicit
        self.k_i = k_i.tocsr()[idx][:, idx]
        self.c_i = c_i.tocsr()[idx][:, idx]
        self.m_i = model.mass[idx]
        self.m_e = model.mass[self.explicit]
        k0 = model.initial_interface_stiffness()[idx][:, idx]
        self._k_ifc0 = k0
        self._factor = factorize(self._matrix(k0, self.dt), method=factorization)
        self._factors: dict[int, Factorization] = {0: self._factor}
        """The initial-tangent factor of each cut level (dt / 2**level), made when first cut."""
        self.iterations = 0
        self.line_searches = 0
        self.cut_steps = 0
        self.cuts = 0

    def _matrix(self, k_ifc: sp.spmatrix, dt: float) -> sp.csr_matrix:
        return (sp.diags(self.m_i) + 0.5 * dt * self.c_i
                + 0.25 * dt * dt * (self.k_i + k_ifc)).tocsr()

    def report(self) -> dict[str, int]:
        """Return the counts of the interface solve so far (iterations, fall-backs, cuts)."""
        return {'iterations': self.iterations, 'line_searches': self.line_searches,
                'cut_steps': self.cut_steps, 'cuts': self.cuts}

    def step(self, state: State, force: np.ndarray, load_factor: float = 1.0,
             start_factor: Optional[float] = None) -> State:
        """
        Advance the state by one step; the load at the step end is ``load_factor * force``.

        ``start_factor`` is the load factor at the step start, used only when
        the step has to be cut: the sub-steps' loads are interpolated linearly
        from it to ``load_factor`` (None: the load is held at ``load_factor``).

        Raises
        ------
        SimulationError
            When the interface iterations do not converge even in sub-steps
            of dt / 2**max_cuts.
        DivergenceError
            For a displacement that is not finite.

        """
        start = load_factor if start_factor is None else start_factor
        return self._advance(state, force, start, load_factor, 0, state.time + self.dt)

    def _advance(self, state: State, force: np.ndarray, start: float, end: float, level: int,
                 time: float) -> State:
        """Solve the (sub-)step of dt / 2**level ending at ``time``, cutting it if need be."""
        dt = math.ldexp(self.dt, -level)
        new = self._solve(state, force, end, dt, level, time)
        if new is not None:
            return new
        if level >= self.max_cuts:
            raise SimulationError(
                f'interface iterations did not converge at t = {time:g} s: neither modified '
                f'Newton ({self.max_iterations} iterations) nor full Newton with a line search, '
                f'in steps cut down to {dt:.3g} s ({self.max_cuts} halvings of {self.dt:.3g} s)')
        self.cuts += 1
        if level == 0:
            self.cut_steps += 1
        LOG.warning('interface iterations did not converge at t = %.6g s (step %.3g s): '
                    'the step is cut in two (cut %d of %d)', time, dt, level + 1, self.max_cuts)
        middle = 0.5 * (start + end)
        half = self._advance(state, force, start, middle, level + 1, time - 0.5 * dt)
        return self._advance(half, force, middle, end, level + 1, time)

    def _factor_at(self, level: int) -> Factorization:
        """Return the initial-tangent factor for steps of dt / 2**level."""
        if level not in self._factors:
            self._factors[level] = factorize(
                self._matrix(self._k_ifc0, math.ldexp(self.dt, -level)),
                method=self.factorization)
        return self._factors[level]

    def _predict(self, state: State, force: np.ndarray, load_factor: float, dt: float,
                 time: float) -> _Predictor:
        """Return the predictor of a step of ``dt`` and solve the explicit DOFs."""
        u_p = state.u + dt * state.v + 0.25 * dt * dt * state.a
        v_p = state.v + 0.5 * dt * state.a
        rhs = force * load_factor
        if self._fused is not None:
            k_s, b, alpha_m, boundary = self._fused
            rhs -= k_s @ (u_p + b * v_p) + alpha_m * v_p + boundary @ np.concatenate([u_p, v_p])
        elif self.explicit_operator is not None:
            rhs -= self.explicit_operator @ np.concatenate([u_p, v_p])
        a = np.zeros_like(state.a)
        a[self.explicit] = rhs[self.explicit] / self.m_e
        idx = self.implicit
        r_i = rhs[idx]
        u_i0 = u_p[idx]
        scale = max(float(np.linalg.norm(r_i)), abs(load_factor) * float(np.linalg.norm(force)),
                    float(np.linalg.norm(self.m_i * state.a[idx])),
                    float(np.linalg.norm(self.k_i @ u_i0)), 1e-30)
        return _Predictor(dt, time, u_p, v_p, a, r_i, u_i0, v_p[idx], scale)

    def _residual(self, p: _Predictor, a_i: np.ndarray, u_full: np.ndarray,
                  slip: Optional[np.ndarray]
                  ) -> tuple[np.ndarray, Optional[np.ndarray], Optional[np.ndarray]]:
        """Return (residual, interface tangent, trial slip) of the implicit accelerations."""
        dt = p.dt
        u_i = p.u_i0 + 0.25 * dt * dt * a_i
        residual = p.r_i - self.m_i * a_i - self.c_i @ (p.v_i0 + 0.5 * dt * a_i) \
            - self.k_i @ u_i
        if slip is None:
            return residual, None, None
        u_full[self.implicit] = u_i
        f_ifc, tangent, new_slip = interface_response(self.model, u_full, slip)
        residual -= f_ifc[self.implicit]
        return residual, tangent, new_slip

    def _tangent_factor(self, tangent: np.ndarray, dt: float) -> Factorization:
        """Return the factor of the step matrix with the current interface tangent."""
        assert self.model.interface is not None
        idx = self.implicit
        k_t = self.model.interface.stiffness(tangent)[idx][:, idx]
        return factorize(self._matrix(k_t, dt), method=self.factorization)

    def _solve(self, state: State, force: np.ndarray, load_factor: float, dt: float,
               level: int, time: float) -> Optional[State]:
        """Return the state after one (sub-)step of ``dt``, or None if it did not converge."""
        p = self._predict(state, force, load_factor, dt, time)
        a_i = state.a[self.implicit].copy()
        nonlinear = self.model.interface is not None and state.slip is not None
        slip = state.slip if nonlinear else None
        u_full = p.u_p.copy()
        limit = self.tolerance * p.scale
        factor = self._factor_at(level)
        new_slip = state.slip
        best, best_a = math.inf, a_i
        for it in range(self.max_iterations):
            residual, tangent, trial_slip = self._residual(p, a_i, u_full, slip)
            if nonlinear:
                new_slip = trial_slip
                norm = float(np.linalg.norm(residual))
                if norm <= limit:
                    break
                if norm < best:
                    best, best_a = norm, a_i
                refresh = self.newton == 'full' or (it > 0 and it % self.refresh_after == 0)
                if refresh and tangent is not None:
                    factor = self._tangent_factor(tangent, dt)
            a_i = a_i + factor.solve(residual)
            self.iterations += 1
            if not nonlinear:
                break
        else:
            LOG.info('t = %.6g s: %s Newton did not converge in %d iterations (best |r| = '
                     '%.3g times the tolerance); full Newton with a line search', time,
                     self.newton, self.max_iterations, best / limit)
            found = self._line_search(p, best_a, u_full, slip)
            if found is None:
                return None
            a_i, new_slip = found
            self.line_searches += 1
            LOG.info('t = %.6g s: the full Newton line search converged', time)
        a = p.a
        a[self.implicit] = a_i
        u = p.u_p + 0.25 * dt * dt * a
        v = p.v_p + 0.5 * dt * a
        if not np.all(np.isfinite(u)):
            raise DivergenceError(f'non-finite displacement at t = {time:g} s')
        return State(time, u, v, a, new_slip)

    def _line_search(self, p: _Predictor, a_i: np.ndarray, u_full: np.ndarray,
                     slip: Optional[np.ndarray]
                     ) -> Optional[tuple[np.ndarray, Optional[np.ndarray]]]:
        """
        Return (accelerations, slip) by full Newton from ``a_i``, or None if it stalls.

        Each iteration factorises the current tangent and backtracks (halving
        the step length) until the residual norm decreases by the Armijo
        fraction 1e-4 of the step length; below ``line_search_min_step``, or
        after ``line_search_iterations`` iterations, it has stalled.
        """
        limit = self.tolerance * p.scale
        residual, tangent, new_slip = self._residual(p, a_i, u_full, slip)
        norm = float(np.linalg.norm(residual))
        for it in range(self.line_search_iterations):
            if norm <= limit:
                return a_i, new_slip
            assert tangent is not None
            da = self._tangent_factor(tangent, p.dt).solve(residual)
            self.iterations += 1
            length = 1.0
            while True:
                trial = a_i + length * da
                r_t, t_t, s_t = self._residual(p, trial, u_full, slip)
                n_t = float(np.linalg.norm(r_t))
                if n_t <= (1.0 - 1e-4 * length) * norm:
                    break
                length *= 0.5
                if length < self.line_search_min_step:
                    LOG.info('t = %.6g s: the line search stalled at |r| = %.3g times the '
                             'tolerance (iteration %d)', p.time, norm / limit, it)
                    return None
            a_i, residual, tangent, new_slip, norm = trial, r_t, t_t, s_t, n_t
            LOG.debug('t = %.6g s: full Newton %d, step length %g, |r| = %.3g times the '
                      'tolerance', p.time, it, length, norm / limit)
        if norm <= limit:
            return a_i, new_slip
        LOG.info('t = %.6g s: full Newton did not converge in %d iterations (|r| = %.3g times '
                 'the tolerance)', p.time, self.line_search_iterations, norm / limit)
        return None


def states(model: PileSoilModel, force: np.ndarray, history: Callable[[float], float],
           duration: float, output_dt: float, scheme: Scheme = 'auto',
           newton: Literal['modified', 'full'] = 'modified',
           start: Optional[State] = None) -> Iterator[State]:
    """
    Yield the state every ``output_dt`` (s) from t = 0 to ``duration``.

    The load is ``force * history(t)``. In the mixed scheme each output
    interval is split into equal sub-steps no longer than the stable step.
    """
    resolved = choose_scheme(model, scheme)
    n_sub = 1
    if resolved == 'mixed':
        dt_stable = mixed_stable_step(model)
        n_sub = max(1, math.ceil(output_dt / dt_stable - 1e-9))
        LOG.info('mixed scheme: stable step %.4g s, %d sub-steps of %.4g s', dt_stable, n_sub,
                 output_dt / n_sub)
    integrator = PartitionedNewmark(model, output_dt / n_sub, resolved, newton)
    state = start if start is not None else initial_state(model)
    yield state
    n_out = int(round(duration / output_dt))
    previous = history(0.0)
    for k in range(n_out):
        for s in range(n_sub):
            t = (k * n_sub + s + 1) * integrator.dt
            factor = history(t)
            state = integrator.step(state, force, factor, start_factor=previous)
            previous = factor
        yield state
