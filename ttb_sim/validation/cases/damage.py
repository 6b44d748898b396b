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
V23: the first bending frequency of a span with a stiffness loss over a segment.

The pipeline (``moving_force_beam`` with a ``damage.girders`` entry -> the assembled
structure -> its natural modes, as ``ttb-sim modes`` finds them) against the exact
frequency of the stepped Euler-Bernoulli beam
(:class:`~ttb_sim.validation.references.stepped_beam.SteppedBeam`, transfer matrices).
Rows: the sound span; 10, 30 and 50 % over 4 m at mid-span (zones on element
boundaries); 30 % over 4 m centred 9 m from the support (a zone that covers two
elements in half, the flexibility average of :mod:`ttb_sim.model.damage`); 50 % over
1 m at mid-span (inside one element). Tolerance 0.1 %: the 16-element mesh is within
1.1e-6 of the continuum where zones follow the elements; the in-element average adds
up to 3.6e-4 (the 1 m zone) and the rest of the tolerance is margin. Without the
damage the frequency would be 1.4 to 11.7 % off, so every damaged row can fail.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

from ttb_sim.config import load_scenario
from ttb_sim.validation.references.stepped_beam import SteppedBeam
from ttb_sim.validation.rows import Case, relative_row, Row

V23_TOLERANCE = 0.001
"""Relative tolerance on the first bending frequency (see the module docstring)."""

V23_ZONES: tuple[tuple[float, float, float], ...] = (
    (16.0, 4.0, 0.1), (16.0, 4.0, 0.3), (16.0, 4.0, 0.5), (9.0, 4.0, 0.3), (16.0, 1.0, 0.5))
"""(centre from the span's start (m), length (m), stiffness loss) of each damaged row."""


def first_bending_frequency(overrides: Sequence[str] = ()) -> float:
    """
    Return the pipeline's first vertical bending frequency of span 1 (Hz).

    Of the lowest modes of the assembled structure (``moving_force_beam``), the one
    with the largest vertical mid-span amplitude of span 1 per unit modal mass.
    """
    from ttb_sim.model.modes import natural_modes
    from ttb_sim.sim import build_structure

    structure = build_structure(load_scenario('moving_force_beam', overrides))
    modes = natural_modes(structure.mass, structure.stiffness, structure.damping, 0.0,
                          min(6, structure.n_free))
    shapes = np.vstack([modes.shapes, np.zeros((1, modes.shapes.shape[1]))])
    vertical = np.abs(shapes[structure.midspan_dofs[0, 2]])
    return float(modes.frequencies[int(np.argmax(vertical))])


def girder_damage(position: float, length: float, loss: float) -> str:
    """Return the ``--set`` override of one damaged zone on span 1."""
    return (f'damage.girders=[{{span: 1, start: {position - 0.5 * length!r}, '
            f'length: {length!r}, loss: {loss!r}}}]')


def v23_rows() -> list[Row]:
    """Return the rows of V23 (see the module docstring)."""
    bridge = load_scenario('moving_force_beam').bridge
    span, ei, mass = bridge.span_length, bridge.bending_stiffness, bridge.mass_per_length
    sound = SteppedBeam.with_zones(span, ei, mass, ())  # pi / (2 L^2) sqrt(EI / m)
    rows = [relative_row('V23', 'f1, sound span', first_bending_frequency(),
                         float(sound.frequencies(1)[0]), V23_TOLERANCE, 'Hz')]
    for position, length, loss in V23_ZONES:
        zone = (position - 0.5 * length, position + 0.5 * length, loss)
        reference = float(SteppedBeam.with_zones(span, ei, mass, (zone,)).frequencies(1)[0])
        computed = first_bending_frequency([girder_damage(position, length, loss)])
        rows.append(relative_row('V23', f'f1, EI -{loss:.0%} over {zone[0]:g}-{zone[1]:g} m',
                                 computed, reference, V23_TOLERANCE, 'Hz'))
    return rows


DAMAGE_CASES: tuple[Case, ...] = (
    Case('V23', 'damaged span: first bending frequency against the stepped beam '
                '(transfer matrices)', v23_rows),
)
