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

"""Newmark average-acceleration time integration with a once-factorised matrix."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from ttb_sim.fe.compiled import sparse_arrays
from ttb_sim.fe.factorization import factorize
from ttb_sim.sim.integrators.newmark_kernels import KERNELS


class SteppedIntegrator:
    """
    What every integrator of the protocol derives from its pieces.

    :meth:`step` is history, effective load, solve and finish in turn;
    :meth:`initial_acceleration` solves with the mass matrix; :attr:`at_slow_step` tells a
    coupling that may rebuild its integrator (a moving window) that the state is whole.
    Subclasses give ``mass``, ``damping``, ``stiffness`` and the four pieces.
    """

    mass: sp.csr_matrix
    damping: sp.csr_matrix
    stiffness: sp.csr_matrix

    @property
    def at_slow_step(self) -> bool:
        """Tell whether the state is complete, so the integrator may be replaced (always here)."""
        return True

    def history(self, u: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return (h_v, h_a) (see :class:`~ttb_sim.sim.integrators.protocol.Integrator`)."""
        raise NotImplementedError

    def effective_load(self, force: np.ndarray, h_v: np.ndarray, h_a: np.ndarray) -> np.ndarray:
        """Return the effective right-hand side for the load at t_{n+1}."""
        raise NotImplementedError

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Apply the effective compliance."""
        raise NotImplementedError

    def finish(self, u_new: np.ndarray, h_v: np.ndarray,
               h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the end-of-step velocity and acceleration."""
        raise NotImplementedError

    def step(self, u: np.ndarray, v: np.ndarray, a: np.ndarray,
             force: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """
        Advance one step of an uncoupled system.

        Parameters
        ----------
        u, v, a : arrays
            State at t_n.
        force : array
            Load at t_{n+1}.

        Returns
        -------
        (u, v, a) at t_{n+1}.

        """
        h_v, h_a = self.history(u, v, a)
        u_new = self.solve(self.effective_load(force, h_v, h_a))
        v_new, a_new = self.finish(u_new, h_v, h_a)
        return u_new, v_new, a_new

    def initial_acceleration(self, u: np.ndarray, v: np.ndarray,
                             force: np.ndarray) -> np.ndarray:
        """Return M^-1 (f - C v - K u), the acceleration consistent with a start state."""
        rhs = force - self.damping @ v - self.stiffness @ u
        if not np.any(rhs):
            return np.zeros_like(rhs)
        return np.asarray(sla.spsolve(self.mass.tocsc(), rhs))


class Newmark(SteppedIntegrator):
    """
    Newmark's average-acceleration method (beta = 1/4, gamma = 1/2) for M a + C v + K u = f.

    The effective matrix K + 2/dt C + 4/dt^2 M is factorised once; each step is
    one sparse forward/back substitution (for any number of right-hand sides).
    The method is unconditionally stable, has no numerical damping and a
    relative period error of about (omega dt)^2 / 12.

    Parameters
    ----------
    mass, damping, stiffness : sparse matrices
        System matrices (n x n).
    dt : float
        Time step (s).
    method : str
        Factorisation of the effective matrix (:func:`ttb_sim.fe.factorization.factorize`);
        the default ``superlu`` is the validated reference.
    lean : bool
        Lean step: :meth:`history` writes into one preallocated vector (valid
        until its next call) and :meth:`effective_load` applies M and C as one
        stacked sparse matrix (one mat-vec); equal to round-off. With numba,
        history and finish are compiled loops (:mod:`ttb_sim.sim.integrators.newmark_kernels`)
        with the same arithmetic, and so is the stacked mat-vec (each row summed
        in scipy's order; unsigned indices make it twice as fast as scipy's).
        The lean step also solves a long effective matrix as two halves on two
        threads (``factorize(..., split=True)``; the same to round-off).
    fused : bool
        For the couplings' compiled loops (``realtime``, lean only): the effective
        matrix factorised whole, its QDLDL factors kept for :meth:`fused_arrays`.

    """

    def __init__(self, mass: sp.spmatrix, damping: sp.spmatrix, stiffness: sp.spmatrix,
                 dt: float, *, method: str = 'superlu', lean: bool = False,
                 fused: bool = False) -> None:
        self.dt = float(dt)
        self.a0 = 4.0 / dt**2
        self.a1 = 2.0 / dt
        self.mass = sp.csr_matrix(mass)
        self.damping = sp.csr_matrix(damping)
        self.stiffness = sp.csr_matrix(stiffness)
        effective = (self.stiffness + self.a1 * self.damping + self.a0 * self.mass).tocsc()
        self._lu = factorize(effective, method=method, split=lean and not fused)
        self.method = self._lu.method
        """The factorisation method in use (after any fallback)."""
        self.lean = lean
        if lean:
            n = self.mass.shape[0]
            # Without the stored zeros of the assembly (72 % of paper_ttbi's mass entries:
            # the beams' element blocks are stored whole): a zero adds nothing to a sum.
            self._stacked = sp.hstack([self.mass, self.damping], format='csr')
            self._stacked.eliminate_zeros()
            self._history = np.zeros(2 * n)
            self._h_a, self._h_v = self._history[:n], self._history[n:]
            self._work = np.zeros(n)
            self._stacked_csr = sparse_arrays(self._stacked)
        self.external: tuple[np.ndarray, np.ndarray] | None = None
        """Load added to every effective right-hand side, (DOFs (unique), values): the
        bearing forces of partitioned substructures on the girders, set before each step
        (None: none)."""
        self._ldl: tuple[np.ndarray, ...] | None = None
        factors = getattr(self._lu, 'factors', None)
        if fused and lean and factors is not None:
            lower, diagonal, permutation = factors()
            self._ldl = (*sparse_arrays(sp.csc_matrix(lower)),
                         1.0 / np.asarray(diagonal, dtype=np.float64),
                         np.asarray(permutation).astype(np.uint64))
        self._history_kernel = KERNELS.compiled('history') if lean else None
        self._finish_kernel = KERNELS.compiled('finish') if lean else None
        self._load_kernel = KERNELS.compiled('effective_load') if lean else None

    def fused_arrays(self) -> tuple[np.ndarray, ...] | None:
        """
        Return what :func:`~.newmark_kernels.newmark_ldl_step` reads, or None.

        (indptr, indices, data) of the stacked [M | C], then the effective
        matrix's QDLDL factors (column pointers, row indices and values of L,
        1 / D, the order p); None unless the integrator was made ``fused`` (lean,
        factorised whole by QDLDL), or with an :attr:`external` load.
        """
        if self._ldl is None or self.external is not None:
            return None
        return (*self._stacked_csr, *self._ldl)

    @property
    def history_buffer(self) -> np.ndarray:
        """The lean step's history vector [h_a | h_v] (the stacked mat-vec's operand)."""
        return self._history

    def history(self, u: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return (h_v, h_a) with v_{n+1} = a1 u_{n+1} + h_v and a_{n+1} = a0 u_{n+1} + h_a.

        These express the end-of-step velocity and acceleration through the
        unknown end-of-step displacement. With ``lean`` the two are views of one
        work vector, overwritten by the next call.
        """
        if self._history_kernel is not None:
            self._history_kernel(u, v, a, self.a0, self.a1, self._h_v, self._h_a)
            return self._h_v, self._h_a
        if self.lean:
            h_a, h_v, work = self._h_a, self._h_v, self._work
            np.multiply(u, -self.a1, out=h_v)
            h_v -= v
            np.multiply(u, -self.a0, out=h_a)
            np.multiply(v, 2.0 * self.a1, out=work)
            h_a -= work
            h_a -= a
            return h_v, h_a
        h_v = -self.a1 * u - v
        h_a = -self.a0 * u - 2.0 * self.a1 * v - a
        return h_v, h_a

    def effective_load(self, force: np.ndarray, h_v: np.ndarray, h_a: np.ndarray) -> np.ndarray:
        """Return f_{n+1} (+ :attr:`external`) - M h_a - C h_v, the effective right-hand side."""
        if self.lean and h_a is self._h_a and h_v is self._h_v:
            if self._load_kernel is not None:
                rhs = np.empty(force.shape[0])
                self._load_kernel(*self._stacked_csr, self._history,
                                  np.ascontiguousarray(force, dtype=np.float64), rhs)
            else:
                rhs = force - self._stacked @ self._history
        else:
            rhs = force - self.mass @ h_a - self.damping @ h_v
        if self.external is not None:
            dofs, values = self.external
            rhs[dofs] += values
        return rhs

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solve the effective system for one or several right-hand sides."""
        return self._lu.solve(rhs)

    def finish(self, u_new: np.ndarray, h_v: np.ndarray,
               h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Return the end-of-step velocity and acceleration."""
        if self._finish_kernel is not None:
            v, a = self._finish_kernel(u_new, self.a0, self.a1, h_v, h_a)
            return v, a
        return self.a1 * u_new + h_v, self.a0 * u_new + h_a
