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
Post-processing of frames and bag arrays (never imports the model).

- ``psd``: Welch PSD with windows long enough for the lowest frequency of
  interest, zero-padded periodograms, peak and level-change frequencies;
- ``power_flow``: frequency-domain power flow of a force against a velocity
  ([P] Eqs. 17-18), Parseval-consistent;
- ``weighting``: ISO 2631 weightings Wk, Wd, Wm and weighted r.m.s.;
- ``levels``: 1/3-octave vibration acceleration levels (a0 = 1e-6 m/s^2);
- ``ride``: Sperling index, car-body acceleration limits;
- ``safety``: Q/P, wheel-load reduction, lateral wheelset force, deck acceleration;
- ``excitation``: excitation frequencies to mark ([P] Eqs. 15, 19, passing);
- ``rigid_displacement``: the rigid-displacement method ([P] Eq. 16);
- ``figures``: PNG figures (matplotlib, Agg) of these on arrays.
"""

from ttb_sim.analysis.psd import (level_change_frequency, padded_periodogram, peak_frequency,
                                  resolving_segment_seconds, welch_psd)

__all__ = ['level_change_frequency', 'padded_periodogram', 'peak_frequency',
           'resolving_segment_seconds', 'welch_psd']
