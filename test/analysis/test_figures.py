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
The layout of the analysis figures (issue #28 item 5.7), measured on the drawn figures.

Labels must lie inside the figure (nothing clipped), an index a model cannot
produce is drawn as n/a with its reason (no bar of 0), and a legend lists only
the lines and excitation marks that are in view.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ttb_sim.analysis.excitation import Excitation
from ttb_sim.analysis.figures import grid_figure, in_view, index_chart, Panel

LONG = 'PSD of vertical acceleration (30 Hz low-pass) (m/s$^2$)$^2$/Hz'
"""The y label of the girder figure's deck PSD, which used to be clipped."""


def _inside(fig: Any, artist: Any) -> bool:
    fig.canvas.draw()   # places the axis labels
    box = artist.get_window_extent(fig.canvas.get_renderer())
    return box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.width and \
        box.y1 <= fig.bbox.height


def _legend(ax: Any) -> list[str]:
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend else []


def test_a_one_row_index_chart_shows_its_x_label():
    fig = index_chart('Ride comfort and running safety against limits',
                      [('deck acceleration', [('bag', 0.224, '')], 5.0, 'm/s^2')])
    ax = fig.axes[0]
    assert ax.get_xlabel() == 'value / limit (-); dashed line: the limit'
    assert _inside(fig, ax.xaxis.label)
    low, high = ax.get_xlim()
    assert all(_inside(fig, t) for t in ax.get_xticklabels() if low <= t.get_position()[0] <= high)
    assert _inside(fig, fig.texts[0])   # the title


def test_an_index_a_model_cannot_produce_is_n_a_with_its_reason():
    reason = 'quarter cars (train.vehicle = sprung_mass) have no lateral dynamics'
    fig = index_chart('indices', [
        ('sperling vertical', [('qc', 1.8, '')], 2.5, '-'),
        ('derailment coefficient', [('qc', None, reason)], 0.8, '-'),
        ('lateral wheelset force', [('qc', None, reason)], 62.3, 'kN')])
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.texts]
    assert texts == ['1.8 (limit 2.5)', f'n/a: {reason}', f'n/a: {reason}']
    assert len(ax.patches) == 1   # one bar: the n/a rows have none (no bar of 0, no 'within')
    assert [t.get_text() for t in ax.get_yticklabels()] == [
        'sperling vertical', 'derailment coefficient', 'lateral wheelset force']
    assert _inside(fig, ax.xaxis.label)


def test_a_long_y_label_is_wrapped_inside_the_figure():
    t = np.linspace(0.0, 1.0, 200)
    rows = [[Panel('time', 'time t (s)', 'vertical acceleration (m/s$^2$)', [('a', t, t)]),
             Panel('psd', 'frequency f (Hz)', LONG, [('a', t + 1, t + 1)], logy=True)]
            for _ in range(4)]
    fig = grid_figure('Girder mid-span', rows)
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        label = ax.yaxis.label
        assert _inside(fig, label), label.get_text()
        assert label.get_window_extent(renderer).height <= \
            ax.get_window_extent(renderer).height
    psd = fig.axes[-1].yaxis.label.get_text()
    assert psd == 'PSD of vertical acceleration\n(30 Hz low-pass) (m/s$^2$)$^2$/Hz'
    assert fig.axes[0].yaxis.label.get_text() == 'vertical acceleration (m/s$^2$)'


def test_a_legend_leaves_out_lines_and_marks_out_of_view():
    f = np.linspace(1.0, 50.0, 100)
    marks = [Excitation('span', 2.6, 2.6), Excitation('wheelbase', 83.3, 83.3)]
    under = Panel('log y', 'f (Hz)', 'PSD', [('loud', f, np.ones_like(f)),
                                             ('quiet', f, np.full_like(f, 1e-12))],
                  logy=True, xlim=(0.0, 50.0), marks=marks)
    beyond = Panel('x range', 'f (Hz)', 'PSD', [('in', f, f), ('beyond', f + 100, f)],
                   xlim=(0.0, 50.0))
    val = Panel('dB', 'f (Hz)', 'VAL (dB)', [('near', f, 80 + 0 * f), ('far', f, 0 * f)],
                floor_below_top=40.0)
    fig = grid_figure('legends', [[under, beyond], [val]])
    first, second, third = fig.axes[0], fig.axes[1], fig.axes[2]
    assert _legend(first) == ['loud', 'span: 2.6 Hz']   # no 'quiet', no 83.3 Hz mark
    assert [t.get_text() for t in first.texts] == ['not in view: quiet']
    assert _legend(second) == ['in']
    assert [t.get_text() for t in second.texts] == ['not in view: beyond']
    assert _legend(third) == ['near']


def test_a_mark_is_explained_in_the_first_panel_that_shows_it():
    f = np.linspace(1.0, 50.0, 100)
    marks = [Excitation('span', 2.6, 2.6), Excitation('wheelbase', 33.3, 33.3)]
    narrow = Panel('0-20 Hz', 'f (Hz)', 'PSD', [('a', f, f)], xlim=(0.0, 20.0), marks=marks)
    wide = Panel('0-50 Hz', 'f (Hz)', 'PSD', [('a', f, f)], xlim=(0.0, 50.0), marks=marks)
    fig = grid_figure('marks', [[narrow, wide]])
    assert _legend(fig.axes[0]) == ['span: 2.6 Hz']
    assert _legend(fig.axes[1]) == ['wheelbase: 33.3 Hz']


def test_in_view_counts_a_segment_that_crosses_the_view():
    fig = grid_figure('view', [[Panel('p', 'x', 'y', [('a', [0.0, 1.0], [0.0, 1.0])])]])
    ax = fig.axes[0]
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.4, 0.6)
    assert in_view(ax, np.array([0.2, 0.8]), np.array([-5.0, 5.0]))    # steep, through it
    assert not in_view(ax, np.array([0.2, 0.8]), np.array([-5.0, -4.0]))
    assert not in_view(ax, np.array([0.2, 0.8]), np.array([np.nan, np.nan]))
