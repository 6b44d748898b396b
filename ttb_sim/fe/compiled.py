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
numba compilation of the package's kernels, on first use and only where numba imports.

A kernel's source is a plain Python function (it runs, slowly, without
numba); :func:`jit` compiles it once, with the helpers its module lists in
``HELPERS``, cached on disk where the package directory is writable. A kernel
compiled ``parallel`` runs the ``prange`` loops of its module on numba's
threads: the module binds ``prange = range`` for the plain function, and
:func:`jit` rebinds it to ``numba.prange`` before compiling. One thread of the
process at a time runs a parallel kernel (not every numba thread pool allows
concurrent launches); another thread calling meanwhile runs the kernel's serial
compilation, which computes the same bits. :func:`parallel_threads` limits the
threads a parallel kernel may take; with one, every parallel kernel runs its
serial compilation (no thread pool is started, nothing spins). numba is
imported only here, so the package imports without it and quickly.
:func:`pending` tells which of the kernels made so far are neither compiled nor
in numba's disk cache: the ones the next steps will compile; :func:`compile_clock`
measures the time spent in numba's compiler (compiling, or loading a kernel from
the disk cache) inside a ``with`` block.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
import importlib.util
import logging
import sys
import threading
import time
from typing import Any, Callable, Iterator

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

_CACHE: dict[tuple[Callable[..., Any], bool], Callable[..., Any] | None] = {}
PARALLEL_LOCK = threading.Lock()
"""Held while a parallel kernel runs (module docstring)."""
_THREADS = [0]
"""Threads a parallel kernel may take: 0 = numba's own count, 1 = the serial compilation."""


@contextmanager
def parallel_threads(threads: int) -> Iterator[None]:
    """
    Let parallel kernels take at most ``threads`` threads inside a ``with`` block.

    One thread runs each parallel kernel's serial compilation (the same bits,
    module docstring); more lets numba take up to that many (and at most
    ``NUMBA_NUM_THREADS``). 0 leaves numba's own count.
    """
    previous = _THREADS[0]
    _THREADS[0] = int(threads)
    try:
        yield
    finally:
        _THREADS[0] = previous


class _OneAtATime:
    """A parallel kernel that falls back to its serial compilation while another runs."""

    def __init__(self, parallel: Callable[..., Any], serial: Callable[..., Any]) -> None:
        self.parallel = parallel
        self.serial = serial
        self.py_func = getattr(serial, 'py_func')

    def __call__(self, *args: Any) -> Any:
        threads = _THREADS[0]
        if threads == 1:
            return self.serial(*args)
        if PARALLEL_LOCK.acquire(blocking=False):
            if threads > 1:
                _set_numba_threads(threads)
            try:
                return self.parallel(*args)
            finally:
                PARALLEL_LOCK.release()
        return self.serial(*args)


def available() -> bool:
    """Tell whether numba is installed (without importing it)."""
    return importlib.util.find_spec('numba') is not None


def sparse_arrays(matrix: sp.csr_matrix | sp.csc_matrix) -> tuple[np.ndarray, ...]:
    """
    Return a CSR or CSC matrix as a kernel reads it: (indptr, indices, data).

    Indices sorted within each row (column) and unsigned, so that the compiled
    loops carry no negative-index checks (measured twice as fast in the mat-vec).
    """
    matrix = matrix.copy()
    matrix.sort_indices()
    return (matrix.indptr.astype(np.uint64), matrix.indices.astype(np.uint64),
            np.ascontiguousarray(matrix.data, dtype=np.float64))


def jit(kernel: Callable[..., Any], *, parallel: bool = False) -> Callable[..., Any] | None:
    """
    Return ``kernel`` compiled by numba (on first call, with its module's helpers), or None.

    Parameters
    ----------
    kernel : callable
        The plain function.
    parallel : bool
        Compile with numba's ``parallel=True`` (its module's ``prange`` loops run
        on several threads), one caller at a time (module docstring).

    Returns
    -------
    callable or None
        None when numba is not installed.

    """
    key = (kernel, parallel)
    if key not in _CACHE:
        try:
            import numba
        except ImportError:  # pragma: no cover - depends on the installation
            log.debug('numba is not installed; kernels run their numpy twins')
            _CACHE[key] = None
        else:
            module = sys.modules[kernel.__module__]
            _jit_helpers(numba, module)
            made = getattr(module, kernel.__name__, None)
            if not parallel and getattr(made, 'py_func', None) is kernel:
                # The kernel is also a helper of its module's other kernels: one compilation.
                _CACHE[key] = made
            elif parallel:
                setattr(module, 'prange', numba.prange)
                serial = jit(kernel)
                assert serial is not None
                _CACHE[key] = _OneAtATime(
                    numba.njit(cache=True, nogil=True, parallel=True)(kernel), serial)
            else:
                _CACHE[key] = numba.njit(cache=True, nogil=True)(kernel)
    return _CACHE[key]


def _jit_helpers(numba: Any, module: Any) -> None:
    """
    Compile the helpers a module's kernels call (its ``HELPERS``) in place, once.

    A helper taken from another kernel module has that module's helpers compiled
    first (in its own namespace), so a kernel may call another module's kernel.
    """
    for helper in getattr(module, 'HELPERS', ()):
        function = getattr(module, helper)
        if hasattr(function, 'py_func'):
            continue
        home = sys.modules[function.__module__]
        if home is not module:
            _jit_helpers(numba, home)
            made = getattr(home, function.__name__, None)
            if getattr(made, 'py_func', None) is function:
                setattr(module, helper, made)
                continue
        setattr(module, helper, numba.njit(cache=True, nogil=True)(function))


def _set_numba_threads(threads: int) -> None:
    """Set numba's thread count of this thread to ``threads`` (at most its pool's size)."""
    import numba
    numba.set_num_threads(min(threads, int(getattr(numba.config, 'NUMBA_NUM_THREADS'))))


def pending() -> list[str]:
    """
    Return the names of the kernels made so far that the next calls will compile.

    A kernel is pending when it has not been compiled in this process and numba's
    disk cache holds no compilation of its current source. Without numba, or
    where numba's cache cannot be read, the answer errs towards pending.
    """
    names = []
    for (kernel, _parallel), dispatcher in _CACHE.items():
        if dispatcher is None:
            continue
        serial = dispatcher.serial if isinstance(dispatcher, _OneAtATime) else dispatcher
        if getattr(serial, 'signatures', None) or _in_disk_cache(kernel):
            continue
        names.append(kernel.__name__)
    return sorted(set(names))


def _in_disk_cache(kernel: Callable[..., Any]) -> bool:
    """Tell whether numba's disk cache holds a compilation of ``kernel``'s current source."""
    try:
        from numba.core.caching import FunctionCache
        index = FunctionCache(kernel)._cache_file._load_index()
    except Exception:  # noqa: B902 - numba's cache layout is internal; any failure: not cached
        return False
    return bool(index)


@dataclass
class CompileClock:
    """The time numba's compiler took inside a :func:`compile_clock` block, so far."""

    seconds: float = 0.0
    """Wall seconds inside the compiler (compiling, or loading from the disk cache)."""
    entries: int = 0
    """How many times the compiler was entered (outermost entries only)."""
    _depth: int = 0
    _since: float = 0.0

    def enter(self) -> None:
        """Note an entry into the compiler (nested entries are not counted again)."""
        if self._depth == 0:
            self._since = time.perf_counter()
            self.entries += 1
        self._depth += 1

    def leave(self) -> None:
        """Note a return from the compiler."""
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._since


@contextmanager
def compile_clock() -> Iterator[CompileClock]:
    """
    Measure the time spent in numba's compiler inside a ``with`` block.

    Every kernel's first call in a process enters the compiler (numba's global
    compiler lock), whether it compiles or loads the kernel from the disk cache;
    the clock sums those entries' wall time. Without numba it stays at zero.
    Use: ``with compile_clock() as clock: ...``, then read ``clock.seconds``.
    """
    clock = CompileClock()
    if not available():
        yield clock
        return
    from numba.core import event

    class _Listener(event.Listener):

        def on_start(self, _event: Any) -> None:
            clock.enter()

        def on_end(self, _event: Any) -> None:
            clock.leave()

    with event.install_listener('numba:compiler_lock', _Listener()):
        yield clock
