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
BLAS threads of the node: held at one for the node's life.

The node's numpy work is small (a frame's few hundred values, sparse solves whose dense
parts are tiny), so a second BLAS thread gains nothing and costs a worker that spins
after every call (OpenBLAS's pthreads pool busy-waits before it sleeps). The solver
variants already limit BLAS inside their stepping; :func:`hold_blas_threads` holds the
whole process at one thread from the node's start, before any numpy work of the model
(the build, the passage restarts, publishing), with ``threadpoolctl``. Measured on a real
Jazzy: docs/ros.md, Threads.
"""

from __future__ import annotations

import logging
from typing import Callable

__all__ = ['hold_blas_threads']

log = logging.getLogger(__name__)


def hold_blas_threads(limit: int = 1) -> Callable[[], None] | None:
    """
    Limit every BLAS thread pool of the process to ``limit`` threads until undone.

    Returns
    -------
    callable or None
        Restores the original limits; None when ``threadpoolctl`` is not
        installed (then nothing is limited, logged at debug level).

    """
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        log.debug('threadpoolctl is not installed; BLAS threads are not limited')
        return None
    limiter = threadpool_limits(limits=limit, user_api='blas')
    return limiter.restore_original_limits
