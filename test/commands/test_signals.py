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

"""The signal helper of ``ttb-sim``: names, handlers installed and restored, the stop flag."""

import signal
import threading

import pytest
from ttb_sim.commands.signals import (raise_stopped, signal_name, SignalHandlers, StopFlag,
                                      Stopped)

pytestmark = pytest.mark.skipif(threading.current_thread() is not threading.main_thread(),
                                reason='signal handlers are installed on the main thread only')


def test_signal_names():
    assert signal_name(signal.SIGINT) == 'SIGINT'
    assert signal_name(signal.SIGTERM) == 'SIGTERM'
    assert signal_name(None) == 'a signal'
    assert signal_name(999) == 'signal 999'


def test_the_handlers_found_first_are_restored():
    before = {sig: signal.getsignal(sig) for sig in (signal.SIGINT, signal.SIGTERM)}
    flag = StopFlag()
    with SignalHandlers() as handlers:
        handlers.install(signal.SIG_IGN, (signal.SIGINT,))
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN
        handlers.install(flag)
        assert signal.getsignal(signal.SIGINT) is flag
        assert signal.getsignal(signal.SIGTERM) is flag
    assert {sig: signal.getsignal(sig) for sig in before} == before


def test_the_stop_flag_after_set_up_only_records_the_signal():
    flag = StopFlag()
    flag.setup = False
    assert not flag
    flag(signal.SIGTERM, None)
    assert flag and flag.signal == signal.SIGTERM


def test_raise_stopped_carries_the_signal():
    with pytest.raises(Stopped) as caught:
        raise_stopped(signal.SIGINT, None)
    assert caught.value.signum == signal.SIGINT
