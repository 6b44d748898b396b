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
SIGINT and SIGTERM in ``ttb-sim``: one line and exit 128 + signal, never half a file.

The command line and the verbs install one of three handlers, always through
:class:`SignalHandlers`, which restores the handlers it replaced:

- :func:`stop_now` before a verb takes over, and whenever nothing is being
  written: one line on stderr and the process ends at once (``os._exit``), with
  no exception unwinding through half-imported extension modules;
- :class:`StopFlag` while ``run`` records: during set-up it ends the process as
  :func:`stop_now` does, then it only sets a flag that the run loop polls between
  frames, so the bag is closed with whole messages;
- :func:`raise_stopped` while ``sweep`` waits for its cases: it raises
  :class:`Stopped`, so the sweep can stop its workers and say how far it got.
"""

from __future__ import annotations

import os
import signal
from types import TracebackType
from typing import Any, Callable, NoReturn, Sequence, Union

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)
"""The signals that stop ``ttb-sim``."""

Handler = Union[Callable[[int, Any], Any], int, signal.Handlers, None]
"""What :func:`signal.signal` takes and returns: a function, SIG_IGN, SIG_DFL or None."""


def signal_name(signum: int | None) -> str:
    """Return 'SIGINT', 'SIGTERM', ... for a signal number."""
    try:
        return signal.Signals(signum).name if signum else 'a signal'
    except ValueError:
        return f'signal {signum}'


def exit_on_signal(signum: int, detail: str = '') -> NoReturn:
    """Write 'ttb-sim: stopped by SIGNAME[ detail]' to stderr; end the process (128 + signum)."""
    suffix = f' {detail}' if detail else ''
    os.write(2, f'ttb-sim: stopped by {signal_name(signum)}{suffix}\n'.encode())
    os._exit(128 + signum)


def stop_now(signum: int, frame: object) -> None:
    """Before a verb takes over the signals nothing is written: end at once, one line."""
    exit_on_signal(signum)


class StopFlag:
    """
    Signal handler for SIGINT / SIGTERM, installed before set-up.

    During set-up (:attr:`setup` True) nothing has been written, so a signal
    ends the process at once with one line on stderr and exit 128 + signal
    (:func:`exit_on_signal`): no exception has to unwind through half-imported
    extension modules or a factorisation. Once recording starts (:attr:`setup`
    False) a signal only sets the flag, which the run loop polls between
    frames, so that no message is ever half-written.
    """

    def __init__(self) -> None:
        self.signal: int | None = None
        self.setup = True

    def __call__(self, signum: int, frame: object) -> None:
        if self.setup:
            exit_on_signal(signum, 'during set-up; nothing written')
        self.signal = signum

    def __bool__(self) -> bool:
        return self.signal is not None


class Stopped(Exception):
    """SIGINT or SIGTERM arrived (raised by :func:`raise_stopped`)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def raise_stopped(signum: int, frame: object) -> None:
    """Raise :class:`Stopped` for the signal."""
    raise Stopped(signum)


class SignalHandlers:
    """
    Handlers installed for a while; :meth:`restore` puts back the ones found first.

    Installing twice for one signal replaces the handler, and :meth:`restore`
    still restores the handler from before the first :meth:`install`.  As a
    context manager it restores on exit.
    """

    def __init__(self) -> None:
        self._previous: dict[int, Handler] = {}

    def install(self, handler: Handler, signals: Sequence[int] = STOP_SIGNALS) -> None:
        """Install ``handler`` for ``signals`` (default SIGINT and SIGTERM)."""
        for sig in signals:
            previous = signal.signal(sig, handler)
            self._previous.setdefault(sig, previous)

    def restore(self) -> None:
        """Put back the handlers found before the first :meth:`install`."""
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()

    def __enter__(self) -> SignalHandlers:
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        self.restore()
