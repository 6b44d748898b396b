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
Measured rail irregularity profiles: CSV read (:func:`load_csv`) and write.

The file has a header row naming at least :data:`CSV_COLUMNS` (x along the
track, then the rail irregularities with the signs of :mod:`.profile`), one
row per position; a file without a header must have exactly those five
numeric columns, in that order.  A refused user file raises
:class:`~ttb_sim.errors.ScenarioError` naming the file and the row; a bad
argument (``dx``) raises :class:`~ttb_sim.errors.ModelError`.
"""

from __future__ import annotations

import csv
import logging
import math
import operator
from os import PathLike

import numpy as np
from scipy.interpolate import CubicSpline

from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import MAX_SHOWN, read_user_file, shown
from ttb_sim.model.irregularity._checks import check_positive, GRID_SLACK
from ttb_sim.model.irregularity.profile import RAIL_QUANTITIES, TrackIrregularity

__all__ = [
    'CSV_COLUMNS',
    'MAX_CSV_BYTES',
    'MAX_GRID_POINTS',
    'MIN_CSV_ROWS',
    'load_csv',
    'save_csv',
]

_LOG = logging.getLogger(__name__)

#: Columns a measured-profile CSV must have (any order; others are ignored).
CSV_COLUMNS: tuple[str, ...] = ('x', *RAIL_QUANTITIES)

#: Fewest data rows accepted from a CSV (a cubic spline needs four).
MIN_CSV_ROWS: int = 4

#: Largest irregularity CSV read (bytes): 3 km at 1 cm is about 20 MB.
MAX_CSV_BYTES: int = 64 << 20

#: Longest numeric cell read (characters); longer ones are refused as non-numeric.
MAX_CELL_CHARS: int = 100

#: Most points of a resampled profile (10 km at 1 mm).
MAX_GRID_POINTS: int = 10_000_000


def save_csv(irregularity: TrackIrregularity, path: str | PathLike[str]) -> None:
    """
    Write the grid values of a profile as CSV readable by :func:`load_csv`.

    Parameters
    ----------
    irregularity : TrackIrregularity
        Profile to write; values are written with 17 significant digits.
    path : str or os.PathLike
        Output file.

    Raises
    ------
    ScenarioError
        If the file cannot be written.

    """
    table = np.column_stack([irregularity.x, irregularity.values.T])
    try:
        np.savetxt(path, table, fmt='%.17g', delimiter=',', header=','.join(CSV_COLUMNS),
                   comments='')
    except OSError as exc:
        raise ScenarioError(f'{path}: cannot write irregularity file: {exc}') from None


def _refuse(path: str | PathLike[str], row: int | None, problem: str) -> ScenarioError:
    name = shown(str(path)) if len(str(path)) > MAX_SHOWN else str(path)
    where = name if row is None else f'{name}: row {row}'
    return ScenarioError(f'{where}: {problem}')


def load_csv(
    path: str | PathLike[str],
    *,
    min_length: float | None = None,
    dx: float | None = None,
) -> TrackIrregularity:
    """
    Load a measured rail irregularity profile from CSV.

    The file has a header row naming at least the columns ``x, z_left,
    z_right, y_left, y_right`` (any order; other columns are ignored), then one
    row per position; or no header, when its first row is all numbers, and then
    exactly these five columns in this order. Each row holds x along the
    track (m, strictly increasing) and the rail irregularities (m, signs as
    in :mod:`.profile`).  Blank lines and
    lines starting with ``#`` are skipped.  Row numbers in messages are line
    numbers of the file, counting from 1 (the header is usually row 1).

    A not-a-knot cubic spline through the data gives slopes and curvatures.
    If the rows are uniformly spaced (relative spread of the spacing below
    1e-6) and ``dx`` is not given, the grid is the rows themselves and the
    values are kept exactly; otherwise the spline is resampled onto a uniform
    grid of spacing ``dx`` (default: the median spacing of the rows) starting
    at the first x.

    Parameters
    ----------
    path : str or os.PathLike
        CSV file.
    min_length : float, optional
        Length (m) the profile must cover, x_last - x_first.
    dx : float, optional
        Spacing (m) of the uniform grid to resample onto.

    Returns
    -------
    TrackIrregularity
        The profile.

    Raises
    ------
    ScenarioError
        If the file cannot be read, a required column is missing, a row has
        the wrong number of fields or a non-numeric / non-finite value, x does
        not strictly increase, there are fewer than ``MIN_CSV_ROWS`` rows, or
        the profile is shorter than ``min_length``.  The message names the
        file and the row.  Cells are checked before rows are counted, so a
        short file with a bad cell names the cell (row, column and text).
    ModelError
        If ``dx`` is given and is not a finite number > 0.

    """
    rows, content = _read_rows(path)
    header, data_index = _header(path, rows, content)
    numbers, row_numbers = _numbers(path, rows, header, data_index)  # bad cells first
    _check_count(path, data_index, int(content[0]))
    x = numbers[:, 0]
    rails = numbers[:, 1:].T
    steps, covered = _check_x(path, x, row_numbers, min_length)
    return _resampled(path, x, rails, steps, covered, dx)


def _read_rows(path: str | PathLike[str]) -> tuple[list[list[str]], np.ndarray]:
    """Return the CSV rows of a file and the indices of its content (not blank, not #) rows."""
    text = read_user_file(path, 'irregularity file', MAX_CSV_BYTES, encoding='utf-8-sig')
    lines = text.splitlines()
    try:
        rows = list(csv.reader(lines))
    except csv.Error as exc:  # e.g. a field over the csv module's size limit
        raise _refuse(path, None, f'cannot parse as CSV ({shown(str(exc))[1:-1]})') from None
    if len(rows) != len(lines):   # a quoted field spanning lines
        raise _refuse(path, None, 'unbalanced quotes; cannot parse as CSV')
    content = np.array([i for i, line in enumerate(lines)
                        if line.strip() and not line.strip().startswith('#')], dtype=np.intp)
    if content.size == 0:
        raise _refuse(path, 1, f'no header and no data rows; expected a header row naming '
                      f'the columns {", ".join(CSV_COLUMNS)} (or no header and exactly five '
                      'numeric columns in that order)')
    return rows, content


def _header(path: str | PathLike[str], rows: list[list[str]],
            content: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Return the column names (the header's, or CSV_COLUMNS without one) and the data rows."""
    header_index = int(content[0])
    header = [name.strip() for name in rows[header_index]]
    if header and all(_parses_as_float(name) for name in header):  # no header: numbers
        if len(header) != len(CSV_COLUMNS):
            message = (f'the first row is numbers, so the file has no header: a headerless '
                       f'file needs exactly {len(CSV_COLUMNS)} columns '
                       f'({", ".join(CSV_COLUMNS)}, in that order), found {len(header)}; '
                       'or add a header row naming the columns')
            raise _refuse(path, header_index + 1, message)
        header = list(CSV_COLUMNS)
        data_index = content
    else:
        missing = [name for name in CSV_COLUMNS if name not in header]
        if missing:
            message = (
                f'header is missing column(s) {", ".join(missing)}; '
                f'expected {", ".join(CSV_COLUMNS)}, found {shown(", ".join(header))}')
            raise _refuse(path, header_index + 1, message)
        duplicated = sorted({name for name in CSV_COLUMNS if header.count(name) > 1})
        if duplicated:
            raise _refuse(path, header_index + 1,
                          f'duplicated column(s) {", ".join(duplicated)}')
        data_index = content[1:]
    return header, data_index


def _check_count(path: str | PathLike[str], data_index: np.ndarray, header_index: int) -> None:
    """Refuse fewer than MIN_CSV_ROWS data rows (after their cells were checked)."""
    if data_index.size < MIN_CSV_ROWS:
        row_numbers = data_index + 1
        last = f'last data row {row_numbers[-1]}' if data_index.size else 'no data rows'
        message = (
            f'too few rows: {data_index.size} data row(s) ({last}), need at least '
            f'{MIN_CSV_ROWS}')
        raise _refuse(path, int(row_numbers[-1]) if data_index.size else header_index + 1,
                      message)


def _numbers(path: str | PathLike[str], rows: list[list[str]], header: list[str],
             data_index: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Return the values (n, 5) of CSV_COLUMNS in the data rows and the rows' line numbers."""
    row_numbers = data_index + 1
    widths = np.fromiter(map(len, rows), dtype=np.intp, count=len(rows))[data_index]
    wrong = np.flatnonzero(widths != len(header))
    if wrong.size:
        r = wrong[0]
        message = f'expected {len(header)} fields as in the header, found {widths[r]}'
        raise _refuse(path, int(row_numbers[r]), message)
    columns = [header.index(name) for name in CSV_COLUMNS]
    getter = operator.itemgetter(*columns)
    selected = [[cell.strip() for cell in getter(rows[i])] for i in data_index]
    for r, row_cells in enumerate(selected):  # bound the fixed-width array below
        for c, cell in enumerate(row_cells):
            if len(cell) > MAX_CELL_CHARS:
                message = f'non-numeric value {shown(cell)} in column {CSV_COLUMNS[c]}'
                raise _refuse(path, int(row_numbers[r]), message)
    cells = np.array(selected, dtype=str).reshape(len(selected), len(CSV_COLUMNS))
    try:
        numbers = cells.astype(np.float64)
    except ValueError:
        parsed = np.asarray(np.frompyfunc(_parses_as_float, 1, 1)(cells)).astype(bool)
        r, c = np.argwhere(~parsed)[0]
        message = f'non-numeric value {shown(str(cells[r, c]))} in column {CSV_COLUMNS[c]}'
        raise _refuse(path, int(row_numbers[r]), message) from None
    bad = np.argwhere(~np.isfinite(numbers))
    if bad.size:
        r, c = bad[0]
        message = (f'value {shown(str(cells[r, c]))} in column {CSV_COLUMNS[c]} is not a finite '
                   'number')
        raise _refuse(path, int(row_numbers[r]), message)
    return numbers, row_numbers


def _check_x(path: str | PathLike[str], x: np.ndarray, row_numbers: np.ndarray,
             min_length: float | None) -> tuple[np.ndarray, float]:
    """Return the steps of x and the length it covers, checked increasing and long enough."""
    with np.errstate(over='ignore', invalid='ignore'):  # a span over 1.8e308 m: refused below
        steps = np.diff(x)
    decreasing = np.flatnonzero(steps <= 0.0)
    if decreasing.size:
        r = decreasing[0] + 1
        message = (
            f'x = {x[r]:g} m does not increase strictly (previous data row {row_numbers[r - 1]} '
            f'has x = {x[r - 1]:g} m)')
        raise _refuse(path, int(row_numbers[r]), message)
    with np.errstate(over='ignore'):
        covered = float(x[-1] - x[0])
    if min_length is not None and covered < float(min_length) * (1.0 - GRID_SLACK):
        message = (
            f'profile too short: it covers {covered:g} m (x = {x[0]:g} to {x[-1]:g} m, last '
            f'data row {row_numbers[-1]}), {float(min_length):g} m is needed')
        raise _refuse(path, int(row_numbers[-1]), message)
    return steps, covered


def _resampled(path: str | PathLike[str], x: np.ndarray, rails: np.ndarray, steps: np.ndarray,
               covered: float, dx: float | None) -> TrackIrregularity:
    """Return the profile on its rows (uniform, no dx) or resampled onto a uniform grid."""
    spacing = float(np.median(steps))
    if not (math.isfinite(covered) and spacing > 0.0 and math.isfinite(spacing)):
        raise _refuse(path, None, f'x spans {covered:g} m with a median spacing of {spacing:g} m; '
                      'both must be finite and > 0')
    uniform = bool(np.max(np.abs(steps - spacing)) <= 1e-6 * spacing)
    spline = CubicSpline(x, rails, axis=1)
    if dx is None and uniform:
        grid_dx = covered / (x.size - 1)
        values = rails
        grid = x
    else:
        grid_dx = spacing if dx is None else check_positive('dx', dx)
        n_grid = covered / grid_dx
        if n_grid > MAX_GRID_POINTS:
            raise _refuse(path, None, f'resampling {covered:g} m at dx = {grid_dx:g} m (the '
                          f'{"median row spacing" if dx is None else "grid spacing"}) gives '
                          f'{n_grid:.3g} points, over the limit of {MAX_GRID_POINTS}; give '
                          'uniformly spaced rows or fewer, wider-spaced ones')
        grid = x[0] + grid_dx * np.arange(int(math.floor(covered / grid_dx + GRID_SLACK)) + 1)
        if grid.size < 2:
            raise _refuse(path, None, f'dx = {grid_dx:g} m is longer than the profile')
        values = spline(grid)
        _LOG.info('%s: resampled %d rows onto %d points at dx = %g m',
                  path, x.size, grid.size, grid_dx)
    return TrackIrregularity(
        float(x[0]), grid_dx, values, spline(grid, 1), spline(grid, 2), source=f'csv:{path}')


def _parses_as_float(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True
