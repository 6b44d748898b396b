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

"""Tests of the node's BLAS thread hold (ttb_sim.node.threads)."""

import numpy  # noqa: F401 - loads the BLAS whose threads are held
import pytest
from ttb_sim.node.threads import hold_blas_threads

threadpoolctl = pytest.importorskip('threadpoolctl', reason='threadpoolctl is not installed')


def _blas_threads() -> list[int]:
    return [p['num_threads'] for p in threadpoolctl.threadpool_info() if p['user_api'] == 'blas']


def test_blas_is_held_at_one_thread_until_restored():
    before = _blas_threads()
    restore = hold_blas_threads()
    try:
        assert restore is not None
        assert _blas_threads() and set(_blas_threads()) == {1}
    finally:
        restore()
    assert _blas_threads() == before
