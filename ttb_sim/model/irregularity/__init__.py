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
Track irregularity: the public face of the modules of this package.

- :mod:`.spectrum_records`: a spectrum's components and families, their integrals.
- :mod:`.spectra`: spectrum families (Chinese HSR, Sato, German, FRA) and
  their band integrals.
- :mod:`.profile`: a realised profile on a grid (:class:`TrackIrregularity`)
  and its sampling with derivatives.
- :mod:`.synthesis`: random profiles from spectra, layers and presets.
- :mod:`.measured`: measured profiles from CSV, and CSV output.
- :data:`GRID_SLACK`: the tolerance, in grid steps, for positions and lengths on a
  profile's grid (shared with the couplings that sample profiles).
"""

from ttb_sim.model.irregularity._checks import GRID_SLACK
from ttb_sim.model.irregularity.measured import CSV_COLUMNS, load_csv, MIN_CSV_ROWS, save_csv
from ttb_sim.model.irregularity.profile import (IrregularitySample, RAIL_QUANTITIES,
                                                TrackIrregularity)
from ttb_sim.model.irregularity.spectra import (band_rms, band_variance, CONTACT_SPACING,
                                                get_spectrum, SATO_DEFAULT_ROUGHNESS,
                                                sato_spectrum, SPECTRA)
from ttb_sim.model.irregularity.spectrum_records import (COMPONENTS, SpectrumComponent,
                                                         SpectrumFamily)
from ttb_sim.model.irregularity.synthesis import (available_spectra, IrregularityLayer,
                                                  MIN_RECORD_WAVELENGTHS, PRESETS, synthesize)

__all__ = [
    'COMPONENTS',
    'CONTACT_SPACING',
    'CSV_COLUMNS',
    'GRID_SLACK',
    'IrregularityLayer',
    'IrregularitySample',
    'MIN_CSV_ROWS',
    'MIN_RECORD_WAVELENGTHS',
    'PRESETS',
    'RAIL_QUANTITIES',
    'SATO_DEFAULT_ROUGHNESS',
    'SPECTRA',
    'SpectrumComponent',
    'SpectrumFamily',
    'TrackIrregularity',
    'available_spectra',
    'band_rms',
    'band_variance',
    'get_spectrum',
    'load_csv',
    'sato_spectrum',
    'save_csv',
    'synthesize',
]
