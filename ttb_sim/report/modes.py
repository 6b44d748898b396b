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
The modes section of ``ttb-sim analyze``: its metrics, its table and its figure.

:func:`modes_metrics` lays out the modes identified from a bag's accelerometer records
(:func:`ttb_sim.io.sensor_records.accelerometer_records`, :mod:`ttb_sim.analysis.oma`)
beside the model's for ``metrics.json``, :func:`modes_rows` for ``index.html``, and
:func:`stabilisation_plot` draws the stabilisation diagram. Choosing the window and
computing the model's modes is the command's (``ttb_sim.commands.analyze_modes``): this
layer never builds the model.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ttb_sim.analysis.oma import Identification, ModelMode, ModePair
from ttb_sim.analysis.psd import welch_psd
from ttb_sim.io.sensor_records import Records

__all__ = ['modes_metrics', 'modes_rows', 'MODES_HEAD', 'stabilisation_plot']

log = logging.getLogger(__name__)


def _percent(x: float | None) -> float | None:
    return None if x is None else 100.0 * x


def modes_metrics(ident: Identification, records: Records, window: dict[str, Any],
                  model: Sequence[ModelMode] | None, pairs: Sequence[ModePair],
                  model_about: dict[str, Any]) -> dict[str, Any]:
    """Return the ``modes`` section of ``metrics.json`` (JSON-ready; see docs/analysis.md)."""
    names = [c.name for c in records.channels]
    identified = []
    for pair, mode in zip(pairs, ident.modes):
        entry: dict[str, Any] = {
            'mode': pair.identified + 1, 'frequency_hz': mode.frequency_hz,
            'damping_ratio': mode.damping_ratio, 'frequency_std_hz': mode.frequency_std_hz,
            'damping_std': mode.damping_std, 'stable_poles': mode.poles,
            'phase_collinearity': mode.phase_collinearity,
            'shape': dict(zip(names, (float(v) for v in mode.shape))),
            'model_mode': None, 'model_frequency_hz': None, 'model_damping_ratio': None,
            'frequency_difference_percent': None, 'damping_difference_percent': None,
            'mac': pair.mac}
        if model is not None and pair.model is not None:
            mm = model[pair.model]
            entry.update(model_mode=pair.model + 1, model_frequency_hz=mm.frequency_hz,
                         model_damping_ratio=mm.damping_ratio,
                         frequency_difference_percent=_percent(pair.frequency_difference),
                         damping_difference_percent=_percent(pair.damping_difference))
        identified.append(entry)
    paired = {p.model: p.identified for p in pairs if p.model is not None}

    def shape(m: ModelMode) -> dict[str, float | None] | None:
        if m.shape is None:
            return None
        return {n: float(v) if np.isfinite(v) else None for n, v in zip(names, m.shape)}

    model_rows = None if model is None else [
        {'mode': k + 1, 'frequency_hz': m.frequency_hz, 'damping_ratio': m.damping_ratio,
         'identified_mode': None if k not in paired else paired[k] + 1, 'shape': shape(m)}
        for k, m in enumerate(model)]
    return {'status': 'identified',
            'method': {'library': 'strid', 'algorithm': 'SSI-data', 'block_rows': ident.block_rows,
                       'orders': [ident.orders[0], ident.orders[-1]],
                       'band_hz': list(ident.band_hz)},
            'window': window, 'rate_hz': ident.rate_hz, 'samples': ident.samples,
            'channels': names, 'places': [c.place for c in records.channels],
            'identified': identified, 'model': {**model_about, 'modes': model_rows}}


MODES_HEAD = ('mode', 'f (Hz)', 'zeta (%)', 'model mode', 'model f (Hz)', 'model zeta (%)',
              'f diff (%)', 'zeta diff (%)', 'MAC', 'stable poles')
"""Columns of :func:`modes_rows`."""


def modes_rows(section: dict[str, Any]) -> list[list[Any]]:
    """Return the rows of the modes table of ``index.html`` from the ``modes`` section."""
    return [[m['mode'], m['frequency_hz'], _percent(m['damping_ratio']), m['model_mode'],
             m['model_frequency_hz'], _percent(m['model_damping_ratio']),
             m['frequency_difference_percent'], m['damping_difference_percent'], m['mac'],
             m['stable_poles']] for m in section.get('identified', [])]


def stabilisation_plot(path: Path, ident: Identification, records: Records,
                       model_frequencies: Sequence[float], title: str) -> Path:
    """Draw the stabilisation diagram over the channels' summed PSD; return the path."""
    from ttb_sim.analysis.figures import stabilisation_figure

    segment = min(records.values.shape[1] / records.rate, max(4.0 / ident.band_hz[0], 1.0))
    psd = None
    f = np.zeros(0)
    for row in records.values:
        f, p = welch_psd(row - row.mean(), records.rate, segment_seconds=segment)
        psd = p if psd is None else psd + p
    return stabilisation_figure(path, title, ident, (f, psd if psd is not None else f),
                                model_frequencies)
