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
PNG figures of analysis results, in the manner of [P] Figs. 12-26.

Functions take arrays and write one PNG each with the Agg back-end
(``matplotlib.figure.Figure``, no pyplot state, no display needed).  Every axis
carries a label with its unit; excitation frequencies (:class:`Excitation`) are
drawn on frequency axes as dashed lines, bands as shaded spans, each labelled.
Several traces per axis overlay several bags (``ttb-sim compare``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Sequence

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
import numpy as np

from ttb_sim.analysis.excitation import Excitation

__all__ = ['Panel', 'bar_levels_figure', 'contour_figure', 'indices_figure', 'panels_figure']

Trace = tuple[str, np.ndarray, np.ndarray]
"""(label, x, y) of one line."""

_MARK_COLOURS = ('tab:red', 'tab:purple', 'tab:brown', 'tab:olive', 'tab:cyan', 'tab:pink',
                 'tab:gray')


@dataclass
class Panel:
    """One axis: traces, axis labels with units, scales, limits and marks."""

    title: str
    xlabel: str
    ylabel: str
    traces: list[Trace]
    logx: bool = False
    logy: bool = False
    xlim: tuple[float, float] | None = None
    marks: Sequence[Excitation] = field(default_factory=list)
    style: str = 'line'   # 'line' or 'step'


def _save(fig: Figure, path: Path) -> None:
    FigureCanvasAgg(fig)
    fig.savefig(str(path), dpi=110)


def _mark(ax: object, marks: Sequence[Excitation], xlim: tuple[float, float] | None) -> None:
    """Draw excitation frequencies and bands on a frequency axis, labelled at the top."""
    lo, hi = xlim if xlim else (-np.inf, np.inf)
    for i, m in enumerate(marks):
        if m.high < lo or m.low > hi:
            continue
        colour = _MARK_COLOURS[i % len(_MARK_COLOURS)]
        if m.is_band:
            ax.axvspan(m.low, m.high, color=colour, alpha=0.15, lw=0)  # type: ignore
        else:
            ax.axvline(m.low, color=colour, ls='--', lw=0.9)  # type: ignore
        label = f'{m.label} {m.low:.3g}' + (f'-{m.high:.3g}' if m.is_band else '') + ' Hz'
        ax.text(m.low, 0.98 - 0.07 * (i % 6), label, color=colour,  # type: ignore
                transform=ax.get_xaxis_transform(), fontsize=7,  # type: ignore
                ha='left', va='top', rotation=0,
                bbox={'facecolor': 'white', 'alpha': 0.6, 'lw': 0, 'pad': 0.5})


def _draw(ax: object, panel: Panel) -> None:
    for label, x, y in panel.traces:
        xs, ys = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if panel.logy:
            ys = np.where(ys > 0, ys, np.nan)
        if panel.style == 'step':
            ax.step(xs, ys, where='mid', label=label, lw=1.0)  # type: ignore
        else:
            ax.plot(xs, ys, label=label, lw=0.8)  # type: ignore
    if panel.logx:
        ax.set_xscale('log')  # type: ignore
    if panel.logy:
        ax.set_yscale('log')  # type: ignore
    if panel.xlim:
        ax.set_xlim(*panel.xlim)  # type: ignore
    ax.set_xlabel(panel.xlabel)  # type: ignore
    ax.set_ylabel(panel.ylabel)  # type: ignore
    ax.set_title(panel.title, fontsize=9)  # type: ignore
    ax.grid(True, which='major', alpha=0.3)  # type: ignore
    _mark(ax, panel.marks, panel.xlim)
    if len(panel.traces) > 1:
        ax.legend(fontsize=7, loc='lower left' if panel.logy else 'best')  # type: ignore


def panels_figure(path: Path, title: str, rows: Sequence[Sequence[Panel]]) -> Path:
    """
    Write a grid of panels (rows of equal length, e.g. time history beside PSD) to a PNG.

    Returns the path written.
    """
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    fig = Figure(figsize=(6.0 * n_cols, 3.4 * n_rows + 0.5), layout='constrained')
    fig.suptitle(title, fontsize=11)
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    for i, row in enumerate(rows):
        for j in range(n_cols):
            if j < len(row):
                _draw(axes[i][j], row[j])
            else:
                axes[i][j].set_visible(False)
    _save(fig, path)
    return path


def bar_levels_figure(path: Path, title: str, centres: np.ndarray,
                      levels: Sequence[tuple[str, np.ndarray]], ylabel: str,
                      marks: Sequence[Excitation] = ()) -> Path:
    """Write levels per 1/3-octave band (grouped bars, one group per band centre) to a PNG."""
    fig = Figure(figsize=(10.0, 4.2), layout='constrained')
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    k = max(len(levels), 1)
    x = np.log10(centres)
    width = 0.1 / k * 0.9
    floor = min((np.nanmin(np.where(np.isfinite(v), v, np.nan)) for _, v in levels
                 if np.any(np.isfinite(v))), default=0.0) - 10.0
    for i, (label, values) in enumerate(levels):
        v = np.where(np.isfinite(values), values, floor)
        ax.bar(x + (i - (k - 1) / 2) * width, v - floor, width, bottom=floor, label=label)
    ax.set_xticks(x)
    ax.set_xticklabels([f'{c:.3g}' for c in centres], rotation=90, fontsize=7)
    ax.set_xlabel('1/3-octave band centre frequency (Hz)')
    ax.set_ylabel(ylabel)
    ax.grid(True, axis='y', alpha=0.3)
    log_marks = [Excitation(m.label, float(np.log10(m.low)), float(np.log10(m.high)))
                 for m in marks if m.low > 0]
    lo, hi = x[0] - 0.05, x[-1] + 0.05
    ax.set_xlim(lo, hi)
    for i, (m, orig) in enumerate(zip(log_marks, [m for m in marks if m.low > 0])):
        if m.high < lo or m.low > hi:
            continue
        colour = _MARK_COLOURS[i % len(_MARK_COLOURS)]
        if m.is_band:
            ax.axvspan(m.low, m.high, color=colour, alpha=0.15, lw=0)
        else:
            ax.axvline(m.low, color=colour, ls='--', lw=0.9)
        text = f'{orig.label} {orig.low:.3g}' + (f'-{orig.high:.3g}' if orig.is_band else '')
        ax.text(m.low, 0.98 - 0.07 * (i % 6), text + ' Hz', color=colour, fontsize=7,
                transform=ax.get_xaxis_transform(), va='top',
                bbox={'facecolor': 'white', 'alpha': 0.6, 'lw': 0, 'pad': 0.5})
    if len(levels) > 1:
        ax.legend(fontsize=7, loc='lower right')
    _save(fig, path)
    return path


def contour_figure(path: Path, title: str, t: np.ndarray, s: np.ndarray, values: np.ndarray,
                   xlabel: str, ylabel: str, colour_label: str) -> Path:
    """Write a space-time contour (values (len(t), len(s))) to a PNG, symmetric colour scale."""
    fig = Figure(figsize=(8.0, 4.5), layout='constrained')
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    peak = float(np.nanmax(np.abs(values))) or 1.0
    levels = np.linspace(-peak, peak, 41)
    cs = ax.contourf(t, s, values.T, levels=levels, cmap='RdBu_r')
    bar = fig.colorbar(cs, ax=ax)
    bar.set_label(colour_label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    _save(fig, path)
    return path


def indices_figure(path: Path, title: str,
                   rows: Sequence[tuple[str, Sequence[tuple[str, float]], float, str]]) -> Path:
    """
    Write ride and safety indices as bars against their limits to a PNG.

    ``rows`` are (index name, [(bag label, value)], limit, unit); each bar is the
    value over its limit (1 = at the limit), annotated with the value and unit.
    """
    fig = Figure(figsize=(9.0, 0.55 * max(len(rows), 1) * max(len(rows[0][1]), 1) + 1.6
                          if rows else 2.0), layout='constrained')
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    y = 0.0
    ticks, names = [], []
    for name, values, limit, unit in rows:
        for j, (label, value) in enumerate(values):
            ratio = value / limit if limit else np.nan
            colour = 'tab:green' if ratio <= 1.0 else 'tab:red'
            ax.barh(y, ratio, color=colour, height=0.8, alpha=0.8)
            ax.text(max(ratio, 0) + 0.01, y, f'{value:.3g} {unit} (limit {limit:.3g})',
                    va='center', fontsize=7)
            ticks.append(y)
            names.append(f'{name} [{label}]' if len(values) > 1 else name)
            y += 1.0
        y += 0.4
    ax.axvline(1.0, color='k', ls='--', lw=1.0)
    ax.set_yticks(ticks)
    ax.set_yticklabels(names, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel('value / limit (-); dashed line: the limit')
    xmax = max([1.3] + [v / lim * 1.35 for _, vals, lim, _ in rows for _, v in vals
                        if lim and np.isfinite(v)])
    ax.set_xlim(0, xmax)
    _save(fig, path)
    return path
