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
from typing import Any, Optional, Sequence, TYPE_CHECKING

from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
import numpy as np

from ttb_sim.analysis.excitation import Excitation

if TYPE_CHECKING:
    from ttb_sim.analysis.oma import Identification

__all__ = ['contour_figure', 'grid_figure', 'in_view', 'index_chart', 'IndexValue',
           'indices_figure', 'Panel', 'panels_figure', 'stabilisation_figure']

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


def _mark(ax: Any, marks: Sequence[Excitation]) -> list[Any]:
    """Draw the excitation frequencies in view (dashed), bands (shaded); return their handles."""
    lo, hi = sorted(ax.get_xlim())
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
    ax.set_xlim(lo, hi)   # the marks do not widen the view
    return handles


def _fit_ylabel(ax: Any, text: str) -> None:
    """Set a y label, on two lines when one would be longer than the axis (and be clipped)."""
    label = ax.set_ylabel(text)
    renderer = ax.figure.canvas.get_renderer()
    if label.get_window_extent(renderer).height <= ax.get_window_extent(renderer).height:
        return
    spaces = [i for i, c in enumerate(text) if c == ' ' and text[:i].count('$') % 2 == 0]
    if spaces:
        # nearest the middle, preferring a break before a parenthesis (a unit, a filter)
        cut = min(spaces, key=lambda i: abs(i - len(text) / 2)
                  + (0 if text[i + 1:i + 2] == '(' else len(text) / 4))
        ax.set_ylabel(f'{text[:cut]}\n{text[cut + 1:]}')


def in_view(ax: Any, x: np.ndarray, y: np.ndarray) -> bool:
    """Return True when any part of the line through (x, y) lies inside the axes' limits."""
    x0, x1 = sorted(ax.get_xlim())
    y0, y1 = sorted(ax.get_ylim())
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(x) & np.isfinite(y)
    inside_x = ok & (x >= x0) & (x <= x1)
    if np.any(inside_x & (y >= y0) & (y <= y1)):
        return True
    # a segment crossing the view between two samples outside it (above, then below)
    a, b = y[:-1], y[1:]
    both = inside_x[:-1] & inside_x[1:]
    return bool(np.any(both & (((a > y1) & (b < y0)) | ((a < y0) & (b > y1)))))


def _plot(ax: Any, panel: Panel) -> tuple[list[Any], float]:
    """Draw the traces of a panel; return their lines and the largest finite value."""
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
    return lines, top


def _draw(ax: Any, panel: Panel, explained: set[str]) -> None:
    """
    Draw one panel; its legend lists the traces in view and the marks not yet explained.

    A trace that lies wholly outside the limits (under a log axis' floor, below
    ``floor_below_top``, beyond ``xlim``) is left out of the legend and named in
    a note instead; an excitation mark is explained in the first panel that
    shows it (``explained`` collects the labels across the figure).
    """
    lines, top = _plot(ax, panel)
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
    _fit_ylabel(ax, panel.ylabel)
    ax.set_title(panel.title, fontsize=9)
    ax.grid(True, which='major', alpha=0.3)
    marks = [h for h in _mark(ax, panel.marks) if h.get_label() not in explained]
    explained.update(h.get_label() for h in marks)
    shown = [ln for ln in lines if in_view(ax, ln.get_xdata(), ln.get_ydata())]
    hidden = [ln.get_label() for ln in lines if ln not in shown]
    handles = (shown if len(panel.traces) > 1 or panel.legend else []) + marks
    if handles:
        ax.legend(handles=handles, fontsize=6.5, framealpha=0.75, loc='best')
    if hidden:
        ax.text(0.01, 0.01, f'not in view: {", ".join(hidden)}', transform=ax.transAxes,
                fontsize=6.5, color='0.35', va='bottom')


def grid_figure(title: str, rows: Sequence[Sequence[Panel]]) -> Figure:
    """Return a figure of a grid of panels (rows of equal length, e.g. time beside PSD)."""
    n_rows, n_cols = len(rows), max(len(r) for r in rows)
    width, height = 6.0 * n_cols, 3.4 * n_rows + 0.5
    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)   # a renderer, to measure labels
    fig.suptitle(title, fontsize=11)
    axes = fig.subplots(n_rows, n_cols, squeeze=False)
    # a fixed layout in inches (constrained layout costs seconds per figure)
    fig.subplots_adjust(left=1.05 / width, right=1 - 0.25 / width, bottom=0.55 / height,
                        top=1 - 0.85 / height, wspace=1.2 / (6.0 - 1.2),
                        hspace=0.9 / (3.4 - 0.9))
    explained: set[str] = set()   # each excitation mark is explained once, where first shown
    for i, row in enumerate(rows):
        for j in range(n_cols):
            if j < len(row):
                _draw(axes[i][j], row[j], explained)
            else:
                axes[i][j].set_visible(False)
    return fig


def panels_figure(path: Path, title: str, rows: Sequence[Sequence[Panel]]) -> Path:
    """
    Write a grid of panels (rows of equal length, e.g. time history beside PSD) to a PNG.

    Returns the path written.
    """
    _save(grid_figure(title, rows), path)
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


def map_figure(path: Path, title: str,
               maps: Sequence[tuple[str, np.ndarray, np.ndarray, np.ndarray]],
               colour_label: str) -> Path:
    """
    Write plan maps side by side to a PNG: each (label, x (nx,), y (ny,), values (ny, nx)).

    One colour scale from zero to the largest value over every map (equal axes, m).
    """
    fig = Figure(figsize=(4.2 * len(maps) + 1.2, 4.2))
    fig.subplots_adjust(left=0.07, right=0.9, bottom=0.14, top=0.82, wspace=0.3)
    fig.suptitle(title, fontsize=11)
    axes = np.atleast_1d(fig.subplots(1, len(maps)))
    top = max(float(np.nanmax(v)) for _, _, _, v in maps) or 1.0
    meshes = []
    for ax, (label, x, y, values) in zip(axes, maps):
        meshes.append(ax.pcolormesh(x, y, values, shading='nearest', cmap='viridis', vmin=0.0,
                                    vmax=top))
        ax.set_aspect('equal')
        ax.set_title(label, fontsize=10)
        ax.set_xlabel('x along the track (m)')
        ax.set_ylabel('y (m)')
    bar = fig.colorbar(meshes[0], ax=list(axes), fraction=0.04)
    bar.set_label(colour_label)
    _save(fig, path)
    return path


IndexValue = tuple[str, Optional[float], str]
"""(bag label, value or None where the model cannot produce the index, reason for None)."""


def index_chart(title: str,
                rows: Sequence[tuple[str, Sequence[IndexValue], float, str]]) -> Figure:
    """
    Return ride and safety indices as bars against their limits.

    ``rows`` are (index name, [(bag label, value, reason)], limit, unit); each bar
    is the value over its limit (1 = at the limit), annotated with the value and
    unit. A value of None (an index the bag's model cannot produce, e.g. the
    derailment coefficient of a quarter car) has no bar: 'n/a' and the reason.
    The margins are fixed in inches, so one row has room for its axis label.
    """
    n_bars = sum(max(len(values), 1) for _, values, _, _ in rows) + 0.4 * max(len(rows) - 1, 0)
    height = 0.5 * max(n_bars, 1.0) + 1.25
    fig = Figure(figsize=(9.0, height))
    FigureCanvasAgg(fig)
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    fig.subplots_adjust(left=0.32, right=0.97, bottom=0.62 / height, top=1 - 0.45 / height)
    y = 0.0
    ticks, names = [], []
    for name, values, limit, unit in rows:
        for label, value, reason in values:
            shown = '' if unit in ('', '-') else f' {unit}'
            if value is None:
                ax.text(0.01, y, f'n/a: {reason}' if reason else 'n/a', va='center',
                        fontsize=7, color='0.35', style='italic')
            else:
                ratio = value / limit if limit else np.nan
                ax.barh(y, ratio, color='tab:green' if ratio <= 1.0 else 'tab:red',
                        height=0.8, alpha=0.8)
                ax.text(max(ratio, 0) + 0.01, y,
                        f'{value:.3g}{shown} (limit {limit:.3g}{shown})', va='center',
                        fontsize=7)
            ticks.append(y)
            names.append(f'{name} [{label}]' if len(values) > 1 else name)
            y += 1.0
        y += 0.4
    ax.axvline(1.0, color='k', ls='--', lw=1.0)
    ax.set_yticks(ticks)
    ax.set_yticklabels(names, fontsize=8)
    ax.set_ylim(y - 0.9, -0.5)   # top to bottom, half a bar of room at both ends
    ax.set_xlabel('value / limit (-); dashed line: the limit')
    xmax = max([1.3] + [v / lim * 1.35 for _, vals, lim, _ in rows for _, v, _ in vals
                        if v is not None and lim and np.isfinite(v)])
    ax.set_xlim(0, xmax)
    return fig


def indices_figure(path: Path, title: str,
                   rows: Sequence[tuple[str, Sequence[IndexValue], float, str]]) -> Path:
    """Write :func:`index_chart` of the rows to a PNG; return the path written."""
    _save(index_chart(title, rows), path)
    return path


def stabilisation_figure(path: Path, title: str, ident: Identification,
                         psd: tuple[np.ndarray, np.ndarray],
                         model_frequencies: Sequence[float] = ()) -> Path:
    """
    Write the stabilisation diagram of an identification to a PNG; return the path.

    Poles by model order against frequency (stable ones filled), the identified modes as
    solid lines, the model's as dashed lines, over the channels' summed PSD (log scale,
    right axis).
    """
    fig = Figure(figsize=(10.0, 5.2))
    fig.subplots_adjust(left=0.08, right=0.9, bottom=0.11, top=0.86)
    fig.suptitle(title, fontsize=11)
    ax = fig.subplots()
    lo, hi = ident.band_hz
    unstable = [p for p in ident.poles if not p.stable]
    stable = [p for p in ident.poles if p.stable]
    ax.plot([p.frequency_hz for p in unstable], [p.order for p in unstable], 'o', ms=3,
            mfc='none', color='0.6', label='pole')
    ax.plot([p.frequency_hz for p in stable], [p.order for p in stable], 'o', ms=4,
            color='tab:green', label='stable pole (f 1 %, zeta 5 %, MAC 2 %)')
    for i, m in enumerate(ident.modes):
        ax.axvline(m.frequency_hz, color='tab:blue', lw=1.2,
                   label='identified mode' if i == 0 else None)
        ax.annotate(f'{m.frequency_hz:.3g} Hz\n{100 * m.damping_ratio:.2g} %',
                    (m.frequency_hz, ident.orders[-1]), textcoords='offset points',
                    xytext=(3, 4), fontsize=8, color='tab:blue')
    shown = [f for f in model_frequencies if lo <= f <= hi]
    for i, f in enumerate(shown):
        ax.axvline(f, color='tab:red', ls='--', lw=1.0, label='model mode' if i == 0 else None)
    ax.set_xlim(lo, hi)
    ax.set_ylim(0, ident.orders[-1] + 6)
    ax.set_xlabel('frequency (Hz)')
    ax.set_ylabel('model order')
    freq, density = psd
    band = (freq >= lo) & (freq <= hi) & (density > 0)
    if np.any(band):
        twin = ax.twinx()
        twin.semilogy(freq[band], density[band], color='0.3', lw=0.8, alpha=0.7)
        twin.set_ylabel('summed PSD ((m/s^2)^2/Hz)')
    ax.legend(loc='lower right', fontsize=8)
    _save(fig, path)
    return path
