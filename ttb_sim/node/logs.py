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
The library's log records, forwarded to the node's ROS logger: each warning once.

The model code logs with :mod:`logging` (``logging.getLogger(__name__)``); in the
node, :class:`ForwardingHandler` hands those records to the ROS logger (a sink
``sink(level, message)``; the node's ``get_logger()``), so that they reach the console
and ``/rosout`` like the node's own lines instead of plain stderr. Every passage builds
its model again, so the same lines would come at every loop restart:

- a warning or error (e.g. "qdldl ... not installed; factorising with superlu_sym", the
  scenario's time-step warning) is forwarded once per node life (the same text again
  is dropped);
- an information line is forwarded once per text, and lines of one template
  (``record.msg``, e.g. a build's progress "... %.0f s so far") at most every
  ``throttle`` seconds.

:func:`install` puts a handler on the package's logger (``ttb_sim``) and returns the
function that takes it off again.
"""

from __future__ import annotations

import logging
import sys
import threading
import time
from typing import Callable

__all__ = ['ForwardingHandler', 'install', 'level_name', 'Sink', 'THROTTLE']

Sink = Callable[[str, str], bool]
"""``sink(level, message)`` logs a line ('debug' .. 'fatal'); False: it could not (shut down)."""

THROTTLE = 10.0
"""Seconds between two information lines of one template (progress lines)."""


def level_name(levelno: int) -> str:
    """Return the ROS logger method of a :mod:`logging` level ('debug' .. 'fatal')."""
    if levelno >= logging.CRITICAL:
        return 'fatal'
    if levelno >= logging.ERROR:
        return 'error'
    if levelno >= logging.WARNING:
        return 'warning'
    if levelno >= logging.INFO:
        return 'info'
    return 'debug'


class ForwardingHandler(logging.Handler):
    """
    Forward log records to a ROS logger, each warning once and progress lines throttled.

    Parameters
    ----------
    sink : callable
        ``sink(level, message)``; returns False when it could not log (then a
        warning or error goes to stderr instead, an information line is dropped).
    throttle : float
        Seconds between two information lines of one template.
    clock : callable
        Monotonic clock in seconds (injectable for tests).

    """

    def __init__(self, sink: Sink, *, throttle: float = THROTTLE,
                 clock: Callable[[], float] = time.monotonic) -> None:
        super().__init__(logging.DEBUG)
        self._sink = sink
        self._throttle = throttle
        self._clock = clock
        self._seen: set[str] = set()
        self._last: dict[tuple[str, str], float] = {}
        self._guard = threading.Lock()
        self.dropped = 0
        """Records not forwarded (repeats and throttled lines)."""

    def admit(self, record: logging.LogRecord, message: str) -> bool:
        """Tell whether a record is forwarded (and remember it)."""
        with self._guard:
            if record.levelno >= logging.INFO:
                if message in self._seen:
                    self.dropped += 1
                    return False
            if record.levelno < logging.WARNING:
                key = (record.name, str(record.msg))
                now = self._clock()
                last = self._last.get(key)
                if last is not None and now - last < self._throttle:
                    self.dropped += 1
                    return False
                self._last[key] = now
            if record.levelno >= logging.INFO:
                self._seen.add(message)
            return True

    def emit(self, record: logging.LogRecord) -> None:
        """Forward one record (never raises)."""
        try:
            message = record.getMessage()
            if record.exc_info:
                message = f'{message}\n{logging.Formatter().formatException(record.exc_info)}'
            if not self.admit(record, message):
                return
            if not self._sink(level_name(record.levelno), message) \
                    and record.levelno >= logging.WARNING:
                sys.stderr.write(f'[{logging.getLevelName(record.levelno)}] {message}\n')
        except Exception:  # noqa: B902 - logging must never break the caller
            self.handleError(record)


PROGRESS_FIELD = 'build_progress'
"""The attribute a long build's progress records carry (``reduction.PROGRESS_FIELD``)."""


class ProgressWatcher(logging.Handler):
    """
    Keep the last progress record of a long build: (fraction, seconds left, message).

    The pile-soil reduction logs one per shift with ``build_progress`` attached
    (:class:`ttb_sim.model.foundation.reduction.BuildProgress`); the node shows the
    last one on ``/diagnostics`` while it builds.
    """

    def __init__(self) -> None:
        super().__init__(logging.DEBUG)
        self.latest: tuple[float, float | None, str] | None = None

    def emit(self, record: logging.LogRecord) -> None:
        """Remember a progress record (others are ignored)."""
        progress = getattr(record, PROGRESS_FIELD, None)
        if progress is not None:
            self.latest = (float(progress[0]), progress[1], record.getMessage())


def install(handler: logging.Handler, name: str = 'ttb_sim',
            level: int = logging.INFO) -> Callable[[], None]:
    """
    Put a handler on a logger (and stop propagation to the root's), return the undo.

    Parameters
    ----------
    handler : logging.Handler
        The handler (a :class:`ForwardingHandler`).
    name : str
        The logger (the package's, so every module's records reach it).
    level : int
        The logger's level while the handler is on.

    Returns
    -------
    callable
        Takes the handler off and restores the logger's level and propagation.

    """
    logger = logging.getLogger(name)
    saved = (logger.level, logger.propagate)
    logger.addHandler(handler)
    logger.setLevel(level)
    logger.propagate = False

    def uninstall() -> None:
        logger.removeHandler(handler)
        if not any(isinstance(h, ForwardingHandler) for h in logger.handlers):
            logger.setLevel(saved[0])
            logger.propagate = saved[1]

    return uninstall
