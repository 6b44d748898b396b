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

"""Tests of measured irregularity profiles: CSV input and output."""

from __future__ import annotations

import numpy as np
import pytest

from ttb_sim.errors import ScenarioError
from ttb_sim.model.irregularity import measured
from ttb_sim.model.irregularity.profile import TrackIrregularity
from ttb_sim.model.irregularity.synthesis import synthesize


@pytest.fixture(scope='module')
def chinese_profile() -> TrackIrregularity:
    """Chinese HSR 2-200 m, 400 m at 0.02 m (100 points per shortest wavelength)."""
    return synthesize('chinese_hsr', length=400.0, dx=0.02, seed=21, x_start=-50.0)


def test_csv_round_trip(tmp_path, chinese_profile):
    """
    save_csv then load_csv gives back the grid and the values exactly.

    Slopes and curvatures come from a cubic spline of the values; they match
    the spectral ones to 1e-3 / 2e-2 of the peak (at 100 points per shortest
    wavelength).
    """
    path = tmp_path / 'profile.csv'
    measured.save_csv(chinese_profile, path)
    assert path.read_text().splitlines()[0] == 'x,z_left,z_right,y_left,y_right'
    loaded = measured.load_csv(path, min_length=400.0)
    assert loaded.n_points == chinese_profile.n_points
    assert loaded.x_start == chinese_profile.x_start
    assert loaded.dx == pytest.approx(chinese_profile.dx, rel=1e-12)
    np.testing.assert_array_equal(loaded.values, chinese_profile.values)
    for arr, ref, tol in ((loaded.slopes, chinese_profile.slopes, 1e-3),
                          (loaded.curvatures, chinese_profile.curvatures, 2e-2)):
        peak = np.max(np.abs(ref), axis=1, keepdims=True)
        assert np.all(np.abs(arr - ref)[:, 5:-5] <= tol * peak)
    assert loaded.source == f'csv:{path}'


def test_csv_nonuniform_rows_are_resampled(tmp_path):
    """
    Non-uniform x is resampled onto a uniform grid (median spacing, or dx given).

    Reference: analytic sine profiles. Tolerance: 1e-6 m on values (spline error).
    """
    x = np.sort(np.random.default_rng(1).uniform(0.0, 20.0, 400))
    x[0], x[-1] = 0.0, 20.0
    shapes = [np.sin(2 * np.pi * x / 10.0) * 1e-3, np.cos(2 * np.pi * x / 8.0) * 1e-3,
              np.sin(2 * np.pi * x / 12.0) * 5e-4, np.zeros_like(x)]
    path = tmp_path / 'uneven.csv'
    lines = ['y_right, x, z_left, z_right, y_left, comment']
    lines += [f'{d},{a},{b},{c},{e},hello' for a, b, c, e, d in zip(x, *shapes)]
    path.write_text('\n'.join(lines) + '\n')
    prof = measured.load_csv(path, dx=0.1)
    assert prof.dx == 0.1 and prof.n_points == 201 and prof.x_start == 0.0
    np.testing.assert_allclose(prof.z_left, np.sin(2 * np.pi * prof.x / 10.0) * 1e-3, atol=1e-6)
    np.testing.assert_allclose(prof.z_right, np.cos(2 * np.pi * prof.x / 8.0) * 1e-3, atol=1e-6)
    np.testing.assert_allclose(prof.slopes[0], np.cos(2 * np.pi * prof.x / 10.0) * 2e-4 * np.pi,
                               atol=1e-5)
    default = measured.load_csv(path)
    assert default.dx == pytest.approx(np.median(np.diff(x)))


GOOD_ROWS = ['0.0,0,0,0,0', '0.5,1e-3,0,0,0', '1.0,0,0,0,0', '1.5,0,0,0,0', '2.0,0,0,0,0']


@pytest.mark.parametrize(('lines', 'kwargs', 'message'), [
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.5,0,nan,0,0', GOOD_ROWS[4]], {},
     r'row 5: value .nan. in column z_right is not a finite number'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:2], '1.0,abc,0,0,0', *GOOD_ROWS[3:]], {},
     r'row 4: non-numeric value .abc. in column z_left'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.5,0,,0,0', GOOD_ROWS[4]], {},
     r'row 5: non-numeric value .. in column z_right'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '0.9,0,0,0,0', GOOD_ROWS[4]], {},
     r'row 5: x = 0.9 m does not increase strictly'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3], '1.0,0,0,0,0', GOOD_ROWS[4]], {},
     r'row 5: x = 1 m does not increase strictly'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:3]], {},
     r'row 4: too few rows: 3 data row'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS], {'min_length': 10.0},
     r'row 6: profile too short: it covers 2 m'),
    (['x,z_left,z_right,y_left', *GOOD_ROWS], {},
     r'row 1: header is missing column\(s\) y_right'),
    (['# measured 2026', '', 'x,z_left,z_right,yleft,y_right', *GOOD_ROWS], {},
     r'row 3: header is missing column\(s\) y_left'),
    (['x,z_left,z_right,y_left,y_right', *GOOD_ROWS[:2], '1.0,0,0,0', *GOOD_ROWS[3:]], {},
     r'row 4: expected 5 fields as in the header, found 4'),
    ([], {}, r'row 1: no header'),
])
def test_csv_refusals_name_file_and_row(tmp_path, lines, kwargs, message):
    """Each bad CSV raises ScenarioError naming the file and the row (file line number)."""
    path = tmp_path / 'bad.csv'
    path.write_text('\n'.join(lines) + '\n')
    with pytest.raises(ScenarioError, match=f'bad.csv: {message}'):
        measured.load_csv(path, **kwargs)


def test_csv_unreadable_file_is_refused(tmp_path):
    """A missing file, a directory and a binary file are refused naming the path."""
    with pytest.raises(ScenarioError, match=r"irregularity file '.*missing.csv' does not "
                       'exist'):
        measured.load_csv(tmp_path / 'missing.csv')
    with pytest.raises(ScenarioError, match=r'irregularity file .* is a directory, not a file'):
        measured.load_csv(tmp_path)
    binary = tmp_path / 'binary.csv'
    binary.write_bytes(b'\xff\xfe\x00\x81' * 10)
    with pytest.raises(ScenarioError, match=r"cannot read irregularity file '.*binary.csv': "
                       'not utf-8-sig text'):
        measured.load_csv(binary)


def test_csv_skips_comments_and_blank_lines(tmp_path):
    """Comment and blank lines and a UTF-8 byte-order mark are skipped."""
    path = tmp_path / 'ok.csv'
    lines = ['# track km 12', 'x,z_left,z_right,y_left,y_right', '', *GOOD_ROWS, '']
    path.write_text('\ufeff' + '\n'.join(lines), encoding='utf-8')
    prof = measured.load_csv(path, min_length=2.0)
    assert prof.n_points == 5 and prof.dx == 0.5
    assert prof.z_left[1] == 1e-3


def test_a_headerless_five_column_csv_is_read_as_x_z_left_z_right_y_left_y_right(tmp_path):
    """Without a header the five columns are taken in the documented order, values exact."""
    plain = tmp_path / 'plain.csv'
    plain.write_text('\n'.join(['# measured', *GOOD_ROWS]) + '\n')
    named = tmp_path / 'named.csv'
    named.write_text('\n'.join(['x,z_left,z_right,y_left,y_right', *GOOD_ROWS]) + '\n')
    a, b = measured.load_csv(plain), measured.load_csv(named)
    np.testing.assert_array_equal(a.values, b.values)
    assert a.x_start == b.x_start and a.dx == b.dx


@pytest.mark.parametrize('first, found', [('0.0,0,0,0', 4), ('0.0,0,0,0,0,7', 6)])
def test_a_headerless_csv_needs_exactly_five_columns(tmp_path, first, found):
    path = tmp_path / 'short.csv'
    path.write_text('\n'.join([first, *GOOD_ROWS]) + '\n')
    with pytest.raises(ScenarioError, match=r'short.csv: row 1: the first row is numbers, so '
                       r'the file has no header: a headerless file needs exactly 5 columns '
                       rf'\(x, z_left, z_right, y_left, y_right, in that order\), found {found}'):
        measured.load_csv(path)


def test_a_csv_field_over_the_csv_limit_is_refused(tmp_path):
    path = tmp_path / 'long.csv'
    path.write_text('x,z_left,z_right,y_left,y_right\n"' + 'a' * 200_000 + '",0,0,0,0\n')
    with pytest.raises(ScenarioError, match='long.csv: cannot parse as CSV'):
        measured.load_csv(path)


def test_a_long_extra_column_does_not_blow_up_memory(tmp_path):
    """Ignored columns are never put in a fixed-width array (a 100 kB note would be 400 kB)."""
    path = tmp_path / 'note.csv'
    rows = [f'{r},note' for r in GOOD_ROWS]
    rows[0] += 'x' * 100_000
    path.write_text('\n'.join(['x,z_left,z_right,y_left,y_right,note', *rows]) + '\n')
    assert measured.load_csv(path).n_points == len(GOOD_ROWS)
