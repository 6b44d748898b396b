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
The compile-on-first-use registry of the stepping core's kernels.

A kernel module lists its plain-Python kernel sources in a :class:`KernelTable`
of its own; ``table.compiled(name)`` returns the source compiled by numba
(:func:`ttb_sim.fe.compiled.jit`, on first call, cached on disk where the
package directory is writable), or None when numba is not installed or
:data:`ENABLED` is False. The caller then takes the kernel's numpy twin, which
computes the same numbers. A kernel is used only where a measurement showed it
wins (docs/performance.md). This module imports no kernel module: each registers
its own.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping

from ttb_sim.fe.compiled import jit

ENABLED = True
"""False makes every :meth:`KernelTable.compiled` return None (the numpy twins run)."""


class KernelTable:
    """
    The kernels of one module, by name.

    Parameters
    ----------
    sources : mapping of str to callable
        Each kernel's plain-Python source.
    parallel : iterable of str, optional
        Kernels compiled ``parallel`` (their ``prange`` loops on numba's threads;
        each iteration's arithmetic is the same on any thread, so the results do
        not depend on the thread count).

    """

    def __init__(self, sources: Mapping[str, Callable[..., Any]], *,
                 parallel: frozenset[str] = frozenset()) -> None:
        unknown = sorted(parallel - set(sources))
        assert not unknown, f'parallel kernels without a source: {unknown}'
        self._sources = dict(sources)
        self._parallel = parallel

    def __contains__(self, name: object) -> bool:
        return name in self._sources

    def source(self, name: str) -> Callable[..., Any]:
        """Return the plain-Python source of kernel ``name``."""
        return self._sources[name]

    def compiled(self, name: str) -> Callable[..., Any] | None:
        """Return the kernel of a name, compiled on its first call; None: see the module."""
        if not ENABLED:
            return None
        return jit(self._sources[name], parallel=name in self._parallel)
