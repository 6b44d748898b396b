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


"""The report of ``ttb-sim identify``: corner and trace plots, the data against the model."""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ttb_sim.report.output import _table, FigureNote

__all__ = ['corner_figure', 'fit_figure', 'trace_figure', 'write_identify_index']


def corner_figure(path: Path, samples: np.ndarray, labels: Sequence[str],
                  truths: Sequence[float] | None = None) -> FigureNote:
    """Draw the posterior's corner plot (corner: marginals and pairwise densities)."""
    import corner
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    d = samples.shape[1]
    fig = Figure(figsize=(2.6 * d + 1.5, 2.6 * d + 1.5))
    FigureCanvasAgg(fig)
    fig.subplots(d, d, squeeze=False)
    corner.corner(samples, labels=list(labels), quantiles=[0.05, 0.5, 0.95], show_titles=True,
                  title_fmt='.4g', truths=truths, fig=fig)
    fig.savefig(path, dpi=110)
    return FigureNote(path.name, 'Posterior: marginals with the 5, 50 and 95 % quantiles, and '
                      'the pairwise densities' + (' (lines: the truth given)' if truths else ''))


def trace_figure(path: Path, chain: np.ndarray, labels: Sequence[str], burn: int) -> FigureNote:
    """Draw every walker's trace per parameter, with the burn-in marked."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    d = chain.shape[2]
    fig = Figure(figsize=(9.0, 2.2 * d + 0.6), layout='constrained')
    FigureCanvasAgg(fig)
    axes = fig.subplots(d, 1, squeeze=False, sharex=True)[:, 0]
    for j, ax in enumerate(axes):
        ax.plot(chain[:, :, j], color='k', alpha=0.25, lw=0.5)
        ax.axvline(burn, color='tab:red', lw=1.0)
        ax.set_ylabel(labels[j])
    axes[-1].set_xlabel('step (red: end of burn-in)')
    fig.savefig(path, dpi=110)
    return FigureNote(path.name, 'Chains: every walker per parameter; the samples after the '
                      'red line (burn-in) are the posterior')


def fit_figure(path: Path, names: Sequence[str], observed: np.ndarray,
               design: np.ndarray, at_median: np.ndarray | None) -> FigureNote:
    """Draw the data's log PSD points against the design runs and the run at the median."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    fig = Figure(figsize=(10.0, 4.0), layout='constrained')
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    x = np.arange(len(names))
    ax.fill_between(x, design.min(axis=0), design.max(axis=0), color='0.85',
                    label='design runs (range)')
    if at_median is not None:
        ax.plot(x, at_median, 'tab:blue', lw=1.2, label='model at the posterior median')
    ax.plot(x, observed, 'k.', label='data')
    ax.set_xticks(x[::max(1, len(x) // 12)])
    ax.set_xticklabels([names[i].replace('log10_psd.', '') for i in x[::max(1, len(x) // 12)]],
                       rotation=30, ha='right', fontsize=7)
    ax.set_ylabel('log10 PSD')
    ax.legend(fontsize=8)
    fig.savefig(path, dpi=110)
    return FigureNote(path.name, 'The features used: the data, the range of the design runs, '
                      'and a real run at the posterior median')


def write_identify_index(out: Path, bag: str, summary: dict[str, Any],
                         written: Sequence[FigureNote]) -> None:
    """Write ``index.html``: the posterior table, the diagnostics, the figures."""
    rows = [[key, p['median'], p['q05'], p['q95'], p['prior_q05'], p['prior_q95'],
             'yes' if p['identified'] else 'no: ' + p['note']]
            for key, p in summary['parameters'].items()]
    diag = summary['diagnostics']
    parts = ['<!DOCTYPE html><html><head><meta charset="utf-8"><title>identify</title>'
             '<style>body{font-family:sans-serif;margin:1.5em;max-width:1400px}'
             'table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #bbb;'
             'padding:2px 8px;font-size:90%;text-align:left}img{max-width:100%}</style>'
             '</head><body>', f'<h1>identify: {html.escape(bag)}</h1>',
             _table(['parameter', 'median', 'q05', 'q95', 'prior q05', 'prior q95',
                     'identified'], rows),
             '<h2>Diagnostics</h2>',
             _table(['item', 'value'], [[k, v if not isinstance(v, (dict, list)) else
                                         str(v)] for k, v in diag.items()]),
             '<p>All numbers: <a href="posterior.json">posterior.json</a>; chains: '
             'chains.npz.</p>']
    for note in written:
        parts.append(f'<figure><img src="{html.escape(note.name)}" alt="{html.escape(note.name)}">'
                     f'<figcaption>{html.escape(note.text)}</figcaption></figure>')
    parts.append('</body></html>')
    (out / 'index.html').write_text('\n'.join(parts) + '\n')
