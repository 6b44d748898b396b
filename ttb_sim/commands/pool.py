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
Many cases in parallel: local worker processes or a Dask cluster, stoppable, with progress.

``sweep`` and ``dataset`` share this: each hands :func:`run_cases` its cases (picklable
records with a ``name``), the top-level function that runs one case and returns its
record (a mapping with a ``status``), and a function that makes the record of a case
whose worker died.  Local workers are spawned (each starts clean) with Ctrl-C ignored:
the parent handles it, terminates them and reports how far it got; a rerun resumes.
"""

from __future__ import annotations

from concurrent.futures import as_completed, Future, ProcessPoolExecutor
import logging
import multiprocessing
import os
import signal
import sys
import threading
import time
from typing import Any, Callable, Generic, Iterator, Protocol, Sequence, TypeVar

from ttb_sim.commands.signals import raise_stopped, SignalHandlers, Stopped
from ttb_sim.errors import ScenarioError

log = logging.getLogger(__name__)

__all__ = ['check_workers', 'make_pool', 'run_cases']

SCHEDULER_TIMEOUT_S = 10.0
"""How long to wait for a Dask scheduler before giving up (exit 2)."""
MAX_WORKERS = 1024
"""Most local worker processes."""
STOP_GRACE_S = 10.0
"""Seconds a terminated worker has to exit before the pool shuts down without it."""


class NamedCase(Protocol):
    """What a case must have: a name (unique in its run)."""

    @property
    def name(self) -> str:
        """Return the case's name."""


Case = TypeVar('Case', bound=NamedCase)
Record = dict[str, Any]


def check_workers(workers: int | None, scheduler: str | None) -> None:
    """Refuse ``--workers`` with ``--scheduler``, and a worker count out of range."""
    if workers is not None and scheduler is not None:
        raise ScenarioError('give either --workers (local processes) or --scheduler (Dask), '
                            'not both')
    if workers is not None and not 1 <= workers <= MAX_WORKERS:
        raise ScenarioError(f'--workers {workers} must be from 1 to {MAX_WORKERS}')


def _start_worker(workers: int) -> None:
    """
    Worker initializer: Ctrl-C is the parent's to handle (it terminates the workers).

    With several workers each runs its compiled kernels on one thread: the cores are
    already shared out by the processes, and a kernel's second thread would only
    contend with another case (the results do not depend on the thread count).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if workers > 1:
        os.environ['NUMBA_NUM_THREADS'] = '1'


class LocalPool(Generic[Case]):
    """Cases in local worker processes (spawned, so each starts clean)."""

    def __init__(self, workers: int, run: Callable[[Case], Record]) -> None:
        self.workers = workers
        self.run = run
        self.pool = ProcessPoolExecutor(max_workers=workers,
                                        mp_context=multiprocessing.get_context('spawn'),
                                        initializer=_start_worker, initargs=(workers,))
        self.futures: dict[Future[Record], Case] = {}

    @property
    def where(self) -> str:
        """Say where the cases run."""
        return f'{self.workers} local worker process(es)'

    def submit(self, cases: Sequence[Case]) -> None:
        """Queue the cases (this starts the worker processes)."""
        self.futures = {self.pool.submit(self.run, c): c for c in cases}

    def results(self) -> Iterator[tuple[Case, Record | BaseException]]:
        """Yield (case, record or the error that lost its worker) as cases finish."""
        for fut in as_completed(self.futures):
            error = fut.exception()
            yield self.futures[fut], fut.result() if error is None else error

    def close(self) -> None:
        """Wait for the workers to exit."""
        self.pool.shutdown(wait=True, cancel_futures=True)

    def stop(self) -> None:
        """Terminate the workers at once (their cases are unfinished: redone next time)."""
        processes = list(getattr(self.pool, '_processes', {}).values())
        for process in processes:
            process.terminate()
        for process in processes:   # reaped, so that their queues' semaphores are released
            process.join(STOP_GRACE_S)
        self.pool.shutdown(wait=True, cancel_futures=True)


class DaskPool(Generic[Case]):
    """Cases on a Dask distributed cluster (the workers need ttb_sim and the out folder)."""

    def __init__(self, address: str, run: Callable[[Case], Record]) -> None:
        try:
            from dask.distributed import Client
        except ImportError:
            raise ScenarioError("--scheduler needs Dask: pip install 'ttb_sim[dask]' (or "
                                "pip install 'dask[distributed]')") from None
        try:
            self.client = Client(address, timeout=SCHEDULER_TIMEOUT_S,
                                 set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise ScenarioError(f'--scheduler {address!r} is not reachable within '
                                f'{SCHEDULER_TIMEOUT_S:g} s ({type(exc).__name__}: {exc}); '
                                'give the address of a running dask scheduler, e.g. '
                                'tcp://host:8786') from None
        self.address = address
        self.run = run
        self.futures: list[Any] = []
        self.by_key: dict[Any, Case] = {}
        workers = self.client.scheduler_info().get('workers', {})
        log.info('Dask scheduler %s with %d workers', address, len(workers))

    @property
    def where(self) -> str:
        """Say where the cases run."""
        return f'Dask scheduler {self.address}'

    def submit(self, cases: Sequence[Case]) -> None:
        """Send the cases to the scheduler."""
        keys = [f'ttb-sim-{c.name}-{os.getpid()}-{time.time_ns()}' for c in cases]
        self.futures = self.client.map(self.run, list(cases), pure=False, key=keys)
        self.by_key = {f.key: c for f, c in zip(self.futures, cases)}

    def results(self) -> Iterator[tuple[Case, Record | BaseException]]:
        """Yield (case, record or the error that lost its worker) as cases finish."""
        from dask.distributed import as_completed as dask_completed
        for fut in dask_completed(self.futures, loop=self.client.loop):
            error = fut.exception()
            yield self.by_key[fut.key], fut.result() if error is None else error

    def close(self) -> None:
        """Disconnect from the scheduler."""
        self.client.close()

    def stop(self) -> None:
        """Cancel the cases still queued or running on the cluster, and disconnect."""
        if self.futures:
            self.client.cancel(list(self.futures))
        self.client.close()


def make_pool(run: Callable[[Case], Record], n_cases: int, workers: int | None,
              scheduler: str | None) -> LocalPool[Case] | DaskPool[Case]:
    """Return the pool the arguments ask for (local: at most one worker per case)."""
    if scheduler:
        return DaskPool(scheduler, run)
    return LocalPool(workers or max(1, min(n_cases, os.cpu_count() or 1)), run)


def _close_whole(pool: LocalPool[Any] | DaskPool[Any], main_thread: bool) -> None:
    """Close the pool with SIGINT/SIGTERM held back: a signal then arrives after it."""
    if not main_thread:
        pool.close()
        return
    held = {signal.SIGINT, signal.SIGTERM}
    signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        pool.close()
    finally:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, held)


def run_cases(pool: LocalPool[Case] | DaskPool[Case], cases: Sequence[Case],
              lost: Callable[[Case, BaseException], Record], verb: str,
              on_record: Callable[[Case, Record], None],
              case_lines: bool = True) -> Stopped | None:
    """
    Run the cases on the pool, handing each record to ``on_record`` as it comes.

    Prints a progress line per case to stderr (``[3/20] case ok in 12.5 s``), unless
    ``case_lines`` is False (``on_record`` prints its own).
    Returns the :class:`Stopped` of a SIGINT/SIGTERM (the pool is then stopped),
    or None when every case came back.
    """
    main_thread = threading.current_thread() is threading.main_thread()
    handlers = SignalHandlers()
    if main_thread:   # workers start with Ctrl-C ignored (inherited): the parent handles it
        handlers.install(signal.SIG_IGN, (signal.SIGINT,))
    try:
        print(f'ttb-sim: {verb}: running {len(cases)} cases on {pool.where}', file=sys.stderr)
        pool.submit(cases)
        if main_thread:
            handlers.install(raise_stopped)
        for i, (case, outcome) in enumerate(pool.results(), start=1):
            record = lost(case, outcome) if isinstance(outcome, BaseException) else outcome
            on_record(case, record)
            if not case_lines:
                continue
            detail = f'in {record.get("wall_time_s", 0.0) or 0.0:.1f} s' \
                if record['status'] == 'ok' else f'{record["status"]}: {record.get("error")}'
            print(f'ttb-sim: {verb}: [{i}/{len(cases)}] {case.name} {record["status"]} '
                  f'{detail}', file=sys.stderr, flush=True)
        _close_whole(pool, main_thread)
    except Stopped as stop:
        pool.stop()
        return stop
    finally:
        handlers.restore()
    return None
