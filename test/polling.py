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

"""Polling with a bound against hangs, shared by the tests that wait on threads or processes."""

import time
from typing import Any, Callable

import pytest


def poll_until(condition: Callable[[], Any], timeout: float, interval: float = 0.01,
               abort: Callable[[], str] | None = None,
               detail: Callable[[], str] | None = None) -> Any:
    """
    Poll until ``condition()`` is truthy and return its value; fail after ``timeout`` s.

    The timeout bounds a hang; it is not a timing check. ``abort`` is asked every
    round and ends the wait with its message when it returns one (a process that
    ended early); ``detail`` adds context to the timeout message.
    """
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        reason = abort() if abort is not None else ''
        if reason:
            pytest.fail(reason)
        time.sleep(interval)
    pytest.fail(f'condition not met within {timeout} s'
                + (f':\n{detail()}' if detail is not None else ''))
