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
Multi-rate Newmark: a fast partition at dt, the rest at ``ratio`` dt (``realtime`` variant).

The DOFs split into a *fast* partition F (the rails: light, stiff, carrying the
wheel-rail contact and its content up to kHz) and a *slow* one S (the slabs, base
plates, girders, bearings and piers under them: heavy, their bands below about
100 Hz), coupled only through spring-dashpots (the fasteners; no mass between
them; mass terms between them, where a reduced model has some, are exchanged as the
stiffness terms are). Each partition is advanced by Newmark's average-acceleration method with
its own constant effective matrix, F at dt and S at H = ratio * dt, staggered
fast-first over each macro step [T_N, T_N + H]:

1. at every fine step the F equation is solved implicitly with the S motion
   predicted from its state at T_N (u_S + tau v_S + tau^2 / 2 a_S; the coupling
   terms K_FS u_S + C_FS v_S + M_FS a_S moved to the right-hand side);
2. at the end of the macro step S is advanced by one step of H, the coupling terms
   of F's state at T_N + H (K_SF u_F + C_SF v_F + M_SF a_F) in its load, and its new state
   replaces the prediction.

Both partitions keep their own fastener terms on the diagonal (implicit), so the
exchange lags only through the prediction error of S, O(H^3). The scheme is not
the monolithic Newmark step (``reference``): what it changes is bounded by
``ttb-sim bench`` (docs/performance.md, the fidelity ladder).

The class offers the :class:`~ttb_sim.sim.integrators.protocol.Integrator` pieces on
full-size vectors, so that a coupling steps it as it steps :class:`Newmark`:
:meth:`solve` applies F's effective compliance to the F rows and returns the S rows
of the right-hand side as they are (its :meth:`effective_load` puts S's predicted
displacement there), and :meth:`finish` writes S's state into the step's result at
the end of each macro step.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ttb_sim.errors import ModelError
from ttb_sim.fe.compiled import sparse_arrays
from ttb_sim.sim.integrators.newmark import Newmark, SteppedIntegrator
from ttb_sim.sim.integrators.newmark_kernels import KERNELS

__all__ = ['check_coupling', 'coupling_gain', 'MAX_COUPLING_GAIN', 'MultiRateNewmark']

MAX_COUPLING_GAIN = 1e-3
"""Largest :func:`coupling_gain` the multi-rate step accepts. Measured on ``paper_ttbi`` (0.05 s
on the bridge, ``solver.rail_steps`` 5, dynamic wheel-rail force against the monolithic step) by
stiffening the slab-base layer: the default 1.5e9 N/m^2 has a gain of 1.1e-4 and 0.8 %; 1e10,
1.8e-3 and 3.3 %; 1e11, 0.038, and the exchange is unstable (480 %)."""


def coupling_gain(mass: sp.csr_matrix, damping: sp.csr_matrix, stiffness: sp.csr_matrix,
                  fast: slice, slow: np.ndarray, dt: float, ratio: int) -> float:
    """
    Return the largest gain of one coupling entry around the staggered exchange.

    For each entry between a fast DOF i and a slow DOF j: |A_ij(dt)| / A_ii(dt) times
    |A_ji(H)| / A_jj(H), A(h) = K + 2/h C + 4/h^2 M the effective matrix at step h: how much
    of a slow prediction error comes back to the slow DOF through the fast one in one
    exchange. Soft links between a light fast partition and a heavy slow one have a small
    gain; a stiff one (a rigid layer) a gain near 1, where the exchange diverges.
    """
    h = ratio * dt

    def effective(step: float) -> sp.csr_matrix:
        return (stiffness + 2.0 / step * damping + 4.0 / step**2 * mass).tocsr()

    fine, coarse = effective(dt), effective(h)
    cross_fine = fine[fast][:, slow].tocoo()
    if not cross_fine.nnz:
        return 0.0
    rows = cross_fine.row + fast.start
    cols = slow[cross_fine.col]
    back = np.asarray(coarse[cols, rows]).ravel()
    gain = (np.abs(cross_fine.data) / np.abs(fine.diagonal()[rows])
            * np.abs(back) / np.abs(coarse.diagonal()[cols]))
    return float(gain.max())


def check_coupling(mass: sp.csr_matrix, damping: sp.csr_matrix, stiffness: sp.csr_matrix,
                   fast: slice, slow: np.ndarray, dt: float, ratio: int) -> float:
    """
    Return :func:`coupling_gain`, or raise ModelError when it exceeds :data:`MAX_COUPLING_GAIN`.

    Raises
    ------
    ModelError
        Naming ``solver.variant``, ``solver.rail_steps`` and what is allowed instead.

    """
    gain = coupling_gain(mass, damping, stiffness, fast, slow, dt, ratio)
    if gain > MAX_COUPLING_GAIN:
        raise ModelError(
            "the multi-rate step of solver.variant = 'realtime' does not apply to this track: "
            'the link between the rails and slabs (at dt) and the structure under them (at '
            f'solver.rail_steps = {ratio} dt) is too stiff for the staggered exchange (gain '
            f'{gain:.2g}, allowed up to {MAX_COUPLING_GAIN:g}; usually track.layer_stiffness); '
            "a stiffer link needs the one-system step: allowed 'reduced' (the fastest), "
            "'qdldl', 'cholmod', 'superlu_sym', 'reference'")
    return gain


def _block(matrix: sp.csr_matrix, rows: np.ndarray | slice,
           cols: np.ndarray | slice) -> sp.csr_matrix:
    part = matrix[rows][:, cols].tocsr()
    part.eliminate_zeros()
    return part


class MultiRateNewmark(SteppedIntegrator):
    """
    Newmark at dt on a fast partition and at ``ratio`` dt on the rest (module docstring).

    Parameters
    ----------
    mass, damping, stiffness : sparse matrices
        The system's matrices (n x n, free DOFs).
    dt : float
        The fast partition's step (s), the step of the integrator's protocol.
    fast : array of int
        Free DOFs of the fast partition, one contiguous range (the track's DOFs are
        numbered after the girders', rails and slabs first).
    ratio : int
        Fast steps per slow step (1 steps both at dt, still staggered).
    method : str
        Factorisation of both effective matrices.
    check : bool
        Refuse a stiff link (:func:`check_coupling`); False where the caller checked the
        same links already (each window of a moving one).

    """

    lean = True
    """The couplings take their lean (single-solve) step with it."""

    def __init__(self, mass: sp.spmatrix, damping: sp.spmatrix, stiffness: sp.spmatrix,
                 dt: float, fast: np.ndarray, ratio: int, *, method: str = 'qdldl',
                 check: bool = True) -> None:
        self.dt = float(dt)
        self.a0 = 4.0 / self.dt**2
        self.a1 = 2.0 / self.dt
        self.mass = sp.csr_matrix(mass)
        self.damping = sp.csr_matrix(damping)
        self.stiffness = sp.csr_matrix(stiffness)
        n = self.mass.shape[0]
        fast = np.unique(np.asarray(fast, dtype=np.int64))
        if not 0 < fast.size < n or fast[-1] - fast[0] + 1 != fast.size:
            raise ModelError('multi-rate Newmark needs one contiguous range of fast DOFs and '
                             f'some slow ones ({fast.size} fast of {n})')
        self.fast = slice(int(fast[0]), int(fast[-1]) + 1)
        self.slow = np.concatenate([np.arange(fast[0]), np.arange(fast[-1] + 1, n)])
        self.n_fast, self.n_slow = fast.size, self.slow.size
        f, s = self.fast, self.slow
        self.ratio = int(ratio)
        self.gain = (check_coupling(self.mass, self.damping, self.stiffness, f, s, self.dt,
                                    self.ratio) if check else math.nan)
        """The exchange's :func:`coupling_gain` (NaN when not checked here)."""
        m_ff, c_ff = _block(self.mass, f, f), _block(self.damping, f, f)
        # each factorised whole, solved on one thread (split halves on two threads collapse
        # on a shared machine: 3.05 against 0.58 ms a fast solve of paper_ttbi beside a run)
        self._fine = Newmark(m_ff, c_ff, _block(self.stiffness, f, f), self.dt,
                             method=method, lean=True, fused=True)
        self._coarse = Newmark(_block(self.mass, s, s), _block(self.damping, s, s),
                               _block(self.stiffness, s, s), self.ratio * self.dt,
                               method=method, lean=True, fused=True)
        self.method = self._fine.method
        # F rows: [M_FF | C_FF | K_FS | C_FS | M_FS] against [h_a_F | h_v_F | u_S | v_S | a_S]
        stacked = sp.hstack([m_ff, c_ff, _block(self.stiffness, f, s),
                             _block(self.damping, f, s), _block(self.mass, f, s)], format='csr')
        stacked.eliminate_zeros()
        self._fine_matrix = stacked
        self._fine_rows = sparse_arrays(stacked)
        nf, ns = self.n_fast, self.n_slow
        self._operand = np.zeros(2 * nf + 3 * ns)
        self._h_a_f, self._h_v_f = self._operand[:nf], self._operand[nf:2 * nf]
        self._u_p, self._v_p, self._a_p = (self._operand[2 * nf + k * ns:2 * nf + (k + 1) * ns]
                                           for k in range(3))
        # S rows: [K_SF | C_SF | M_SF] against [u_F | v_F | a_F] (the fast end state)
        slow_rows = sp.hstack([_block(self.stiffness, s, f), _block(self.damping, s, f),
                               _block(self.mass, s, f)], format='csr')
        slow_rows.eliminate_zeros()
        self._slow_matrix = slow_rows
        self._slow_rows = sparse_arrays(slow_rows)
        self._slow_index = np.full(n, -1, dtype=np.int64)
        self._slow_index[s] = np.arange(s.size)
        """Position of each free DOF among the slow ones (-1: fast)."""
        self._fast_state = np.zeros(3 * nf)
        self.external: tuple[np.ndarray, np.ndarray] | None = None
        """Load on the slow partition at the end of the step, (DOFs, values) (see
        :class:`Newmark`); taken by the slow step at the end of each macro step."""
        self._phase = 0
        self._start: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        self._history = np.zeros(2 * n)
        self._h_a, self._h_v = self._history[:n], self._history[n:]
        self._force_slow = np.zeros(self.n_slow)
        self._history_kernel = KERNELS.compiled('history')
        self._finish_kernel = KERNELS.compiled('finish')
        self._load_kernel = KERNELS.compiled('effective_load')

    @property
    def at_slow_step(self) -> bool:
        """Tell whether the last step closed a slow step (the state is whole: S corrected)."""
        return self._phase == 0

    # -- the integrator protocol ---------------------------------------------------------

    def fused_arrays(self) -> tuple[np.ndarray, ...] | None:
        """Return None: the compiled single-partition loops do not apply."""
        return None

    @property
    def history_buffer(self) -> np.ndarray:
        """The history vector [h_a | h_v] of the last :meth:`history` (fast rows only)."""
        return self._history

    def history(self, u: np.ndarray, v: np.ndarray,
                a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return (h_v, h_a) of the fine step; at a macro step's start, take S's state.

        Only the fast rows are filled (S's motion is its prediction, :meth:`finish`).
        Both are views of one work vector, overwritten by the next call.
        """
        s, f = self.slow, self.fast
        if self._phase == 0:
            self._start = (u[s], v[s], a[s])   # copies (fancy indexing)
        assert self._start is not None
        u_s, v_s, a_s = self._start
        tau = (self._phase + 1) * self.dt
        np.multiply(a_s, 0.5 * tau * tau, out=self._u_p)
        self._u_p += u_s
        self._u_p += tau * v_s
        np.multiply(a_s, tau, out=self._v_p)
        self._v_p += v_s
        self._a_p[:] = a_s
        if self._history_kernel is not None:
            self._history_kernel(u[f], v[f], a[f], self.a0, self.a1, self._h_v_f, self._h_a_f)
        else:
            self._h_v_f[:] = u[f] * -self.a1 - v[f]
            self._h_a_f[:] = u[f] * -self.a0 - v[f] * (2.0 * self.a1) - a[f]
        self._h_v[f] = self._h_v_f
        self._h_a[f] = self._h_a_f
        return self._h_v, self._h_a

    def effective_load(self, force: np.ndarray, h_v: np.ndarray, h_a: np.ndarray) -> np.ndarray:
        """
        Return the right-hand side: F rows of the fine step, S rows S's predicted displacement.

        The F rows carry the fasteners' S-side terms at S's predicted motion; ``h_v`` and
        ``h_a`` must be those of the last :meth:`history`.
        """
        f = self.fast
        rhs = np.empty(force.shape[0])
        force_f = np.ascontiguousarray(force[f], dtype=np.float64)
        if self._load_kernel is not None:
            self._load_kernel(*self._fine_rows, self._operand, force_f, rhs[f])
        else:
            rhs[f] = force_f - self._fine_matrix @ self._operand
        rhs[self.slow] = self._u_p
        if self._phase == self.ratio - 1:   # the slow step's own load, at its end
            self._force_slow = force[self.slow]
        return rhs

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Apply the fast partition's effective compliance to the F rows; keep the S rows."""
        out = np.array(rhs, dtype=np.float64, copy=True)
        out[self.fast] = self._fine.solve(out[self.fast])
        return out

    def finish(self, u_new: np.ndarray, h_v: np.ndarray,
               h_a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """
        Return the end-of-step velocity and acceleration; close a macro step when it is due.

        The S rows are S's prediction; at the end of a macro step S is advanced by one
        slow step and its state written into ``u_new`` (in place) and the returned v, a.
        """
        assert self._start is not None
        f, s, n = self.fast, self.slow, u_new.shape[0]
        v, a = np.empty(n), np.empty(n)
        if self._finish_kernel is not None:
            v[f], a[f] = self._finish_kernel(u_new[f], self.a0, self.a1, self._h_v_f,
                                             self._h_a_f)
        else:
            v[f] = self.a1 * u_new[f] + self._h_v_f
            a[f] = self.a0 * u_new[f] + self._h_a_f
        v[s] = self._v_p
        a[s] = self._a_p
        self._phase += 1
        if self._phase == self.ratio:
            u_s, v_s, a_s = self._coarse.step(*self._start, self._slow_load(u_new, v, a))
            u_new[s], v[s], a[s] = u_s, v_s, a_s
            self._phase = 0
        return v, a

    def _slow_load(self, u_new: np.ndarray, v: np.ndarray, a: np.ndarray) -> np.ndarray:
        """Return S's load at the macro step's end: its own, the coupling terms of F's state."""
        nf = self.n_fast
        self._fast_state[:nf] = u_new[self.fast]
        self._fast_state[nf:2 * nf] = v[self.fast]
        self._fast_state[2 * nf:] = a[self.fast]
        load = np.empty(self.n_slow)
        if self._load_kernel is not None:
            self._load_kernel(*self._slow_rows, self._fast_state,
                              np.ascontiguousarray(self._force_slow), load)
        else:
            load = self._force_slow - self._slow_matrix @ self._fast_state
        if self.external is not None:   # the bearing forces of partitioned piled piers
            dofs, values = self.external
            where = self._slow_index[dofs]
            np.add.at(load, where[where >= 0], np.asarray(values)[where >= 0])
        return load
