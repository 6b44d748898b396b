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
from typing import Any, Sequence

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
import numpy as np

from ttb_sim.analysis.excitation import Excitation

__all__ = ['Panel', 'contour_figure', 'indices_figure', 'panels_figure']

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
    style: str = 'line'   # 'line', 'step', or 'sweep' (markers and a mean line)
    legend: bool = False  # a legend even for one trace
    floor_below_top: float | None = None   # linear y axis: show only this far below the top


def _save(fig: Figure, path: Path) -> None:
    FigureCanvasAgg(fig)
    fig.savefig(str(path), dpi=110)


def _mark(ax: Any, marks: Sequence[Excitation], xlim: tuple[float, float] | None) -> list[Any]:
    """Draw excitation frequencies (dashed) and bands (shaded); return their legend handles."""
    lo, hi = xlim if xlim else (-np.inf, np.inf)
    handles = []
    for i, m in enumerate(marks):
        if m.high < lo or m.low > hi:
            continue
        colour = _MARK_COLOURS[i % len(_MARK_COLOURS)]
        label = f'{m.label}: {m.low:.3g}' + (f'-{m.high:.3g}' if m.is_band else '') + ' Hz'
        if m.is_band:
            handles.append(ax.axvspan(m.low, m.high, color=colour, alpha=0.18, lw=0,
                                      label=label))
        else:
            handles.append(ax.axvline(m.low, color=colour, ls='--', lw=0.9, label=label))
    return handles


def _draw(ax: Any, panel: Panel, mark_legend: bool = True) -> None:
    lines = []
    top = -np.inf
    for label, x, y in panel.traces:
        xs, ys = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        if panel.logy:
            ys = np.where(ys > 0, ys, np.nan)
        if np.any(np.isfinite(ys)):
            top = max(top, float(np.nanmax(ys)))
        if panel.style == 'step':
            lines.extend(ax.step(xs, ys, where='mid', label=label, lw=1.0))
        elif panel.style == 'sweep' and label.startswith('cases'):
            lines.extend(ax.plot(xs, ys, 'o', label=label, ms=4, alpha=0.6))
        elif panel.style == 'sweep':
            lines.extend(ax.plot(xs, ys, '-s', label=label, lw=1.2, ms=4))
        else:
            lines.extend(ax.plot(xs, ys, label=label, lw=0.8))
    if panel.logx:
        ax.set_xscale('log')
    if panel.logy:
        ax.set_yscale('log')
        if np.isfinite(top) and top > 0:   # eight decades below the top: filters' floors hidden
            ax.set_ylim(bottom=max(ax.get_ylim()[0], top * 1e-8), top=top * 5.0)
    if panel.floor_below_top is not None and np.isfinite(top):
        ax.set_ylim(bottom=top - panel.floor_below_top, top=top + 0.08 * panel.floor_below_top)
    if panel.xlim:
        ax.set_xlim(*panel.xlim)
    ax.set_xlabel(panel.xlabel)
    ax.set_ylabel(panel.ylabel)
    ax.set_title(panel.title, fontsize=9)
    ax.grid(True, which='major', alpha=0.3)
    handles = _mark(ax, panel.marks, panel.xlim)
    if not mark_legend:
        handles = []
    if len(panel.traces) > 1 or panel.legend:
        handles = lines + handles
    if handles:
        ax.legend(handles=handles, fontsize=6.5, framealpha=0.75,
                  loc='best')


def panels_figure(path: Path, title: str, rows: Sequence[Sequence[Panel]]) -> Path:
    """
    Write a grid of panels (rows of equal length, e.g. time history beside PSD) to a PNG.

    Returns the path written.
    """
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    width, height = 6.0 * n_cols, 3.4 * n_rows + 0.5
    fig = Figure(figsize=(width, height))
    fig.suptitle(title, fontsize=11)
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    # a fixed layout in inches (constrained layout costs seconds per figure)
    fig.subplots_adjust(left=1.05 / width, right=1 - 0.25 / width, bottom=0.55 / height,
                        top=1 - 0.85 / height, wspace=1.2 / (6.0 - 1.2),
                        hspace=0.9 / (3.4 - 0.9))
    legend_done = False   # the excitation marks are explained once, in the first panel
    for i, row in enumerate(rows):
        for j in range(n_cols):
            if j < len(row):
                _draw(axes[i][j], row[j], not legend_done)
                legend_done = legend_done or bool(row[j].marks)
            else:
                axes[i][j].set_visible(False)
    _save(fig, path)
    return path


def contour_figure(path: Path, title: str, t: np.ndarray, s: np.ndarray, values: np.ndarray,
                   xlabel: str, ylabel: str, colour_label: str) -> Path:
    """Write a space-time contour (values (len(t), len(s))) to a PNG, symmetric colour scale."""
    fig = Figure(figsize=(8.0, 4.5))
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.12, top=0.86)
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
                          if rows else 2.0))
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    fig.subplots_adjust(left=0.32, right=0.97)
    y = 0.0
    ticks, names = [], []
    for name, values, limit, unit in rows:
        for j, (label, value) in enumerate(values):
            ratio = value / limit if limit else np.nan
            colour = 'tab:green' if ratio <= 1.0 else 'tab:red'
            ax.barh(y, ratio, color=colour, height=0.8, alpha=0.8)
            shown = '' if unit in ('', '-') else f' {unit}'
            ax.text(max(ratio, 0) + 0.01, y, f'{value:.3g}{shown} (limit {limit:.3g}{shown})',
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
