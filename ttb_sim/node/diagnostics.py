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
What the live node reports on ``/diagnostics``, as plain data.

:class:`DiagnosticsReport` is what :meth:`~ttb_sim.node.passage.PassageController.diagnostics`
returns and the shell copies into a ``diagnostic_msgs/msg/DiagnosticStatus``;
:class:`StepMeter` keeps the stepping totals (simulated time, steps, stepping wall
and CPU time) and gives their window since the previous report;
:func:`passage_level` rates the passage state; :func:`frame_values` gives a frame's
headline values; :func:`diagnostic_array` copies a report into a
``diagnostic_msgs/msg/DiagnosticArray`` of the message classes it is given.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import Any

from ttb_sim.io.topics import MessageTypes
from ttb_sim.sim import Frame

OK, WARN, ERROR = 0, 1, 2
"""The ``diagnostic_msgs/msg/DiagnosticStatus`` levels."""

RTF_WINDOW = 5.0
"""Wall-clock seconds over which the achieved real-time factor is measured."""

RTF_TOLERANCE = 0.05
"""Shortfall of the achieved real-time factor below the requested one that warns (5 %)."""


@dataclass(frozen=True)
class DiagnosticsReport:
    """
    Solver health for ``/diagnostics``, as plain data.

    Attributes
    ----------
    level : int
        0 OK, 1 WARN, 2 ERROR (the ``diagnostic_msgs/msg/DiagnosticStatus`` levels).
    message : str
        One line summary.
    values : tuple of (str, str)
        Key/value pairs; keys carry their unit.

    """

    level: int
    message: str
    values: tuple[tuple[str, str], ...]

    def as_dict(self) -> dict[str, str]:
        """Return the key/value pairs as a dict."""
        return dict(self.values)


@dataclass(frozen=True)
class StepWindow:
    """
    The stepping between two reports.

    Attributes
    ----------
    wall : float
        Wall-clock seconds of the window.
    simulated : float
        Simulated seconds stepped.
    steps : int
        Time steps taken.
    stepping : float
        Wall-clock seconds spent stepping.
    cpu : float
        CPU seconds (of the stepping thread) spent stepping.

    """

    wall: float
    simulated: float
    steps: int
    stepping: float
    cpu: float

    @property
    def real_time_factor(self) -> float:
        """Simulated over wall-clock seconds (0 for an empty window)."""
        return self.simulated / self.wall if self.wall > 0 else 0.0

    @property
    def step_ms(self) -> float:
        """Milliseconds of stepping per time step (0 without steps)."""
        return 1e3 * self.stepping / self.steps if self.steps else 0.0


class StepMeter:
    """
    Stepping totals, and the window since the previous :meth:`window`.

    Parameters
    ----------
    now : float
        The wall clock (s) at which the first window starts.

    """

    def __init__(self, now: float) -> None:
        # wall, sim time, steps, stepping seconds (wall), stepping CPU seconds
        self._window = (now, 0.0, 0, 0.0, 0.0)
        self._sim_total = 0.0
        self._steps_total = 0
        self._stepping_total = 0.0
        self._stepping_cpu = 0.0

    def frame(self, steps: int, simulated: float) -> None:
        """Count one frame: its time steps and the simulated seconds it advanced."""
        self._steps_total += steps
        self._sim_total += simulated

    def stepping(self, wall: float, cpu: float) -> None:
        """Count wall-clock and CPU seconds spent stepping."""
        self._stepping_total += wall
        self._stepping_cpu += cpu

    def window(self, now: float) -> StepWindow:
        """Return the stepping since the previous call (or the start) and start a new window."""
        wall0, sim0, steps0, busy0, cpu0 = self._window
        self._window = (now, self._sim_total, self._steps_total, self._stepping_total,
                        self._stepping_cpu)
        return StepWindow(wall=now - wall0, simulated=self._sim_total - sim0,
                          steps=self._steps_total - steps0,
                          stepping=self._stepping_total - busy0,
                          cpu=self._stepping_cpu - cpu0)


def merged(windows: Any) -> StepWindow:
    """Return the sum of consecutive stepping windows (an empty one for none)."""
    items = list(windows)
    return StepWindow(wall=sum(w.wall for w in items), simulated=sum(w.simulated for w in items),
                      steps=sum(w.steps for w in items), stepping=sum(w.stepping for w in items),
                      cpu=sum(w.cpu for w in items))


class SlidingWindow:
    """
    The stepping over the last ``span`` wall-clock seconds, from consecutive windows.

    Parameters
    ----------
    span : float
        Wall-clock seconds to cover (the newest windows whose walls add up to at
        least ``span``, or all since :meth:`clear`).

    """

    def __init__(self, span: float = RTF_WINDOW) -> None:
        self.span = span
        self._windows: deque[StepWindow] = deque()

    def add(self, window: StepWindow) -> StepWindow:
        """Add the newest window; return the stepping over the last ``span`` seconds."""
        self._windows.append(window)
        while (len(self._windows) > 1
               and sum(w.wall for w in self._windows) - self._windows[0].wall >= self.span):
            self._windows.popleft()
        return merged(self._windows)

    def clear(self) -> None:
        """Forget the windows (after a pause or a change of the requested pace)."""
        self._windows.clear()


def passage_level(state: str, divergence: str, bag_error: str, passage: int, target: float,
                  window: StepWindow) -> tuple[int, str]:
    """
    Return the level and one-line message of a passage's state.

    Parameters
    ----------
    state : str
        The controller's state ('running', 'paused', 'idle', 'diverged', 'failed', ...).
    divergence : str
        Why stepping stopped ('' if it did not).
    bag_error : str
        Why recording stopped ('' if it did not).
    passage : int
        The passage number.
    target : float
        The requested real-time factor (0: as fast as possible).
    window : StepWindow
        The stepping over the measuring window (the last :data:`RTF_WINDOW` seconds):
        a running passage more than :data:`RTF_TOLERANCE` below the target warns,
        saying by how much.

    """
    rtf = window.real_time_factor
    if state == 'diverged':
        return ERROR, f'diverged: {divergence}'
    if state == 'failed':
        return ERROR, divergence
    if bag_error:
        return ERROR, bag_error
    slow = rtf < (1 - RTF_TOLERANCE) * target
    if state == 'running' and target > 0 and window.steps and slow:
        short = 100 * (1 - rtf / target)
        return WARN, (f'slower than requested: real-time factor {rtf:.2f} over the last '
                      f'{window.wall:.1f} s < {target:g} ({short:.0f} % short)')
    return OK, f'{state}, passage {passage}'


def frame_values(frame: Frame) -> list[tuple[str, str]]:
    """
    Return a frame's headline values as diagnostic key/value pairs (keys carry units).

    Parameters
    ----------
    frame : Frame
        The frame.

    Returns
    -------
    list of (str, str)

    """
    out = [('head position (m)', f'{frame.head_position:.3f}'),
           ('speed (m/s)', f'{frame.speed:.3f}'),
           ('speed (km/h)', f'{frame.speed * 3.6:.2f}')]
    for k, mid in enumerate(frame.midspan):
        out.append((f'span{k + 1:02d} midspan z (m)', f'{float(mid[2]):.6g}'))
    return out


def diagnostic_array(types: MessageTypes, report: DiagnosticsReport, name: str,
                     hardware_id: str, stamp: Any) -> Any:
    """
    Copy a report into a ``diagnostic_msgs/msg/DiagnosticArray`` of one status.

    Parameters
    ----------
    types : callable
        Maps a ROS type name to its message class (rclpy's in the node).
    report : DiagnosticsReport
        Level, message and key/value pairs.
    name, hardware_id : str
        The status's name and hardware id.
    stamp : builtin_interfaces/msg/Time
        The header stamp.

    """
    key_value = types('diagnostic_msgs/msg/KeyValue')
    status = types('diagnostic_msgs/msg/DiagnosticStatus')(
        level=bytes([report.level]), name=name, message=report.message,
        hardware_id=hardware_id, values=[key_value(key=k, value=v) for k, v in report.values])
    header = types('std_msgs/msg/Header')(stamp=stamp, frame_id='')
    return types('diagnostic_msgs/msg/DiagnosticArray')(header=header, status=[status])
