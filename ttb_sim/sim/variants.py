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
Solver variants (the scenario key ``solver.variant``) and the BLAS thread limit.

A variant names how the stepping core solves: which factorisation of the
constant matrices (:mod:`ttb_sim.fe.factorization`), whether the lean step is
taken, and how many BLAS threads the run may use. ``reference`` is the
validated path as it was written, with the process's BLAS threads untouched:
general SuperLU, the plain Newmark step, two track solves per step of the
multibody cars (whose contact step every variant takes compiled; it agrees with
the numpy step it replaced to round-off, ``test/sim/contact_oracle.py``).
``reduced`` changes the model, not only how it is solved: the track away from
the train rides on the girder (an approximation with a stated range,
docs/performance.md); it is opt-in. ``realtime`` steps moving forces and quarter
cars in one compiled loop (the frames of ``qdldl`` bit for bit) and multibody cars
on the window of ``reduced`` with its rails and slabs at dt and the structure under
them at ``solver.rail_steps`` dt (:mod:`ttb_sim.sim.integrators.multirate`, an
approximation within issue #27's budget, measured by ``ttb-sim bench``).
A pile-soil substructure on its own (``scenario.substructure_only``,
:mod:`ttb_sim.sim.substructure.standalone`) reads the same table: ``reference`` steps
it fully implicit (one factorisation of every DOF, the validated Newmark
method; a static load by a direct solve of each Newton iteration) and every
other variant in the mixed scheme (explicit soil, implicit piles, cap and
interface; a static load by preconditioned conjugate gradients), the pile block
factorised by the variant's method.
The other variants run the BLAS single-threaded: the small dense solves of the
contact iteration (32 x 32 per car) only spin a second thread (measured 9x
slower with two threads on two cores), and one thread makes the results
independent of the machine's core count.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
import logging
import os
from typing import Iterator, TYPE_CHECKING

if TYPE_CHECKING:
    from ttb_sim.config import Scenario

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SolverVariant:
    """One value of ``solver.variant``."""

    name: str
    factorization: str
    """Method of :func:`ttb_sim.fe.factorization.factorize`."""
    lean: bool
    """True for the lean step (fused mat-vecs, preallocated work vectors)."""
    blas_threads: int | None
    """BLAS threads while building and stepping; None leaves the process setting."""
    reduced: bool = False
    """True to solve the slab track in detail only in a window around the train
    (:mod:`ttb_sim.sim.coupling.train_track.reduced_track`); models without a slab track
    run as without."""
    pile_soil_scheme: str = 'mixed'
    """Scheme of a pile-soil substructure run (:mod:`ttb_sim.sim.substructure.stepping`):
    'implicit' or 'mixed'."""
    fused: bool = False
    """True to take the steps between frames in the coupling's compiled loop
    (:class:`~ttb_sim.sim.coupling.base.FusedCoupling`), one thread, the effective
    matrix factorised whole (not split)."""

    def rail_steps(self, scenario: Scenario) -> int:
        """
        Return the multi-rate ratio of a scenario's multibody cars under this variant.

        ``solver.rail_steps`` for ``realtime`` with multibody cars (the window of
        ``reduced`` with its rails and slabs at dt, the rest at rail_steps dt); 0 (one
        system) otherwise.
        """
        if self.fused and scenario.train.vehicle == 'car':
            return int(scenario.solver.rail_steps)
        return 0

    @property
    def pile_soil_factorization(self) -> str:
        """
        Method of :func:`ttb_sim.fe.factorization.factorize` for the pile-soil matrices.

        The variant's own symmetric method; the reference's general SuperLU would only
        add fill to these symmetric positive definite 3-D matrices, so it takes CHOLMOD.
        """
        return 'cholmod' if self.factorization == 'superlu' else self.factorization


VARIANTS = {
    'reference': SolverVariant('reference', 'superlu', lean=False, blas_threads=None,
                               pile_soil_scheme='implicit'),
    'cholmod': SolverVariant('cholmod', 'cholmod', lean=True, blas_threads=1),
    'qdldl': SolverVariant('qdldl', 'qdldl', lean=True, blas_threads=1),
    'superlu_sym': SolverVariant('superlu_sym', 'superlu_sym', lean=True, blas_threads=1),
    'reduced': SolverVariant('reduced', 'qdldl', lean=True, blas_threads=1, reduced=True),
    'realtime': SolverVariant('realtime', 'qdldl', lean=True, blas_threads=1, fused=True),
}
"""Every variant by name (the choices of ``solver.variant``)."""


PARALLEL_WIDTH = 2
"""Threads a parallel kernel can use: the split solve runs two halves."""
AUTO_FREE_CORES = 1.5
"""Cores the 1-minute load average must leave free for ``solver.threads = 0`` to take two."""


@dataclass(frozen=True)
class Threads:
    """The threads a run's parallel kernels take, and why."""

    count: int
    reason: str

    def describe(self) -> str:
        """Return the choice for the plan line, e.g. '1 thread (auto: load 3.2 on 2 cores)'."""
        return f'{self.count} thread{"s" if self.count > 1 else ""} ({self.reason})'


def resolve_threads(requested: int, variant: SolverVariant | None = None) -> Threads:
    """
    Return the threads of a run's parallel kernels for ``solver.threads``.

    A positive value is taken as it is. 0 (auto) takes two threads only when the
    cores this process may run on, less the 1-minute load average, leave at
    least :data:`AUTO_FREE_CORES` free, else one: two threads that wait for each
    other on a busy machine made a step 3.5-11x slower than one thread (issue
    #28). ``realtime`` takes one thread at 0 (issue #27: single-threaded by default,
    threads an opt-in). The results do not depend on the count.
    """
    if requested > 0:
        return Threads(int(requested), 'solver.threads')
    if variant is not None and variant.fused:
        return Threads(1, f'{variant.name}: one thread unless solver.threads asks')
    try:
        cores = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cores = os.cpu_count() or 1
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):
        return Threads(1, f'auto: load unknown on {cores} cores')
    count = PARALLEL_WIDTH if cores - load >= AUTO_FREE_CORES else 1
    return Threads(count, f'auto: load {load:.1f} on {cores} cores')


def solver_variant(name: str) -> SolverVariant:
    """
    Return the variant of a name.

    Raises
    ------
    ValueError
        For an unknown name (the message lists the allowed ones).

    """
    try:
        return VARIANTS[name]
    except KeyError:
        message = f'unknown solver variant {name!r}; allowed: {", ".join(VARIANTS)}'
        raise ValueError(message) from None


@contextmanager
def blas_threads(limit: int | None) -> Iterator[None]:
    """
    Limit the BLAS thread pools of the process inside a ``with`` block.

    Parameters
    ----------
    limit : int or None
        Threads allowed; None changes nothing. Without the ``threadpoolctl``
        package the limit is skipped (logged once at debug level).

    """
    if limit is None:
        yield
        return
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        log.debug('threadpoolctl is not installed; BLAS threads are not limited')
        yield
        return
    with threadpool_limits(limits=limit, user_api='blas'):
        yield
