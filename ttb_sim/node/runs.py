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
What the live node steps and records into: the train run it controls, the frame sink.

:class:`~ttb_sim.node.passage.PassageController` steps any
:class:`~ttb_sim.sim.Runner`; a train passage (:class:`TrainRun`) also takes live
speed changes and ends once the train has left. Every frame goes to a
:class:`FrameSink` (a :class:`~ttb_sim.io.bag.BagRecorder`).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

from ttb_sim.sim import Frame, Runner

__all__ = ['FrameSink', 'TrainRun']


class _Structure(Protocol):
    """What passage control reads of a train run's structure."""

    @property
    def fundamental_frequency(self) -> float:
        """The first natural frequency of the track-bridge structure (Hz)."""


@runtime_checkable
class TrainRun(Runner, Protocol):
    """
    A :class:`~ttb_sim.sim.Runner` of a train passage: what passage control needs beyond it.

    :class:`~ttb_sim.sim.Runner` has none of these (a pile-soil substructure run has no
    train): a live speed change, the head position at which the train has left the
    bridge, and the structure's fundamental frequency (the free-vibration tail).
    """

    @property
    def structure(self) -> _Structure:
        """The track-bridge structure."""

    @property
    def exit_position(self) -> float:
        """Head position (m) at which the last axle leaves the bridge."""

    def set_speed(self, speed: float) -> None:
        """Change the train speed (m/s) from the next step on."""


class FrameSink(Protocol):
    """What the controller hands every frame to (a :class:`~ttb_sim.io.bag.BagRecorder`)."""

    def write(self, frame: Frame) -> None:
        """Record one frame."""

    def close(self) -> None:
        """Finish recording (idempotent)."""
