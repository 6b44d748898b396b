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

"""The wheel-rail contact record: tread, friction, geometry and contact iteration settings."""

from __future__ import annotations

from dataclasses import dataclass

from ttb_sim.declarations import check_declared, param

__all__ = ['ContactParameters']


@dataclass(frozen=True)
class ContactParameters:
    """Wheel-rail contact of multibody cars (PHYSICS.md section 2)."""

    tread: str = param('lm', '-', "Zhai's Hertz constant: worn 'lm' or 'conical' tread.",
                       choices=('lm', 'conical'))
    friction: float = param(0.3, '-', 'Friction coefficient of the Shen-Hedrick-Elkins '
                            'saturation.', low=0.0, high=1.0, low_inclusive=False)
    geometry: str = param('profiles', '-', "'profiles': LMA wheel on CHN60 rail contact "
                          "table; 'conicity': equivalent cone.",
                          choices=('profiles', 'conicity'))
    conicity: float = param(0.05, '-', "Equivalent conicity for geometry = 'conicity'.",
                            low=0.0, high=1.0)
    tolerance: float = param(1e-9, 'm', 'Convergence tolerance of the contact iteration on '
                             'the compression of every wheel.', low=1e-15, high=1e-3,
                             low_inclusive=False)
    max_iterations: int = param(30, '-', 'Contact iterations per step before the run stops '
                                'as diverged.', low=1, high=1000)

    def __post_init__(self) -> None:
        """Check every field against its declaration."""
        check_declared(self, 'contact parameter')
