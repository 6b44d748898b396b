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
Excitation frequencies to mark on spectra ([P] Eqs. 15 and 19, PHYSICS.md section 9.6).

- ``V / lambda``: the boundary wavelength between two irregularity spectra
  (Eq. 15; 83.3 Hz at 300 km/h for lambda = 1 m);
- the axle-spacing band of Eq. 19, ``V / (2 L_w + 2 L_b)`` to ``V / (2 L_b)``,
  with L_b the bogie semi-spacing and L_w the wheelbase semi-length;
- passing frequencies ``V / L`` of the car length, the wheelbase ``2 L_w``, the
  span, the unit slab and the fastener spacing.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ['Excitation', 'axle_band', 'excitation_frequencies']


@dataclass(frozen=True)
class Excitation:
    """A frequency (``low == high``) or a band to mark, with its label."""

    label: str
    low: float
    high: float

    @property
    def is_band(self) -> bool:
        """True for a band, False for a single frequency."""
        return self.high > self.low


def axle_band(speed: float, bogie_semi_spacing: float, wheelbase_semi: float
              ) -> tuple[float, float]:
    """Return the Eq. 19 band (Hz) for a speed (m/s), L_b and L_w (m)."""
    return (speed / (2 * wheelbase_semi + 2 * bogie_semi_spacing),
            speed / (2 * bogie_semi_spacing))


def excitation_frequencies(speed: float, *, boundary_wavelength: float | None = 1.0,
                           bogie_semi_spacing: float | None = None,
                           wheelbase_semi: float | None = None,
                           car_length: float | None = None, span_length: float | None = None,
                           slab_length: float | None = None,
                           fastener_spacing: float | None = None) -> list[Excitation]:
    """
    Return the excitation frequencies of a train at ``speed`` (m/s) for the lengths given (m).

    Lengths left as None (unknown for the bag) give no mark.
    """
    if not speed > 0:
        return []
    out: list[Excitation] = []
    if bogie_semi_spacing and wheelbase_semi:
        lo, hi = axle_band(speed, bogie_semi_spacing, wheelbase_semi)
        out.append(Excitation('axle band (Eq. 19)', lo, hi))
    for label, length in (('span', span_length), ('car', car_length),
                          ('wheelbase', 2 * wheelbase_semi if wheelbase_semi else None),
                          ('slab', slab_length), ('V/\u03bb (Eq. 15)', boundary_wavelength),
                          ('fastener', fastener_spacing)):
        if length:
            out.append(Excitation(label, speed / length, speed / length))
    return out
