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
A data set as one Parquet table: a row per case, a typed column per value.

Parquet (through pyarrow) because analysts read it directly — pandas, polars,
DuckDB, Spark, R's arrow, MATLAB's ``parquetread`` — column by column without
loading the rest, with the types kept (a PSD is a list column, one array per row),
and compressed; xarray/zarr would suit dense arrays on one grid better, but a
data set's rows mix parameters, labels, strings and per-case arrays.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Mapping, Sequence

__all__ = ['flatten', 'write_table']


def flatten(data: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    """Flatten nested mappings to dotted keys (``labels.train.speed_kmh``); lists stay."""
    out: dict[str, Any] = {}
    for key, value in data.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping) and value:
            out.update(flatten(value, f'{name}.'))
        elif isinstance(value, Mapping):
            out[name] = None
        else:
            out[name] = value
    return out


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_number_list(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and all(_is_number(x) or x is None for x in value)


def _column(values: Sequence[Any]) -> tuple[Any, list[Any]]:
    """Return the arrow type of a column and its values in that type."""
    import pyarrow as pa
    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.bool_(), list(values)
    if present and all(_is_number(v) for v in present):
        if all(isinstance(v, int) for v in present):
            return pa.int64(), list(values)
        return pa.float64(), [None if v is None or not math.isfinite(float(v)) else float(v)
                              for v in values]
    if present and all(_is_number_list(v) for v in present):
        return pa.list_(pa.float64()), [
            None if v is None else [float('nan') if x is None else float(x) for x in v]
            for v in values]
    if all(isinstance(v, str) for v in present):
        return pa.string(), list(values)
    return pa.string(), [None if v is None else json.dumps(v, sort_keys=True) for v in values]


def write_table(path: Path, rows: Sequence[Mapping[str, Any]],
                metadata: Mapping[str, Any]) -> None:
    """
    Write rows (flat mappings) as one Parquet file, atomically.

    Columns are the union of the rows' keys in first-seen order; a column whose
    values are all numbers is float64 (int64 if all integers; NaN and missing are
    null), lists of numbers are ``list<float64>``, strings stay strings and
    anything else is its JSON text.  ``metadata`` is stored as JSON under the
    schema's ``ttb_sim`` key.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq
    columns: list[str] = []
    for row in rows:
        columns.extend(k for k in row if k not in columns)
    arrays, fields = [], []
    for name in columns:
        typ, values = _column([row.get(name) for row in rows])
        arrays.append(pa.array(values, type=typ))
        fields.append(pa.field(name, typ))
    schema = pa.schema(fields, metadata={'ttb_sim': json.dumps(metadata, sort_keys=True)})
    table = pa.Table.from_arrays(arrays, schema=schema)
    tmp = path.with_name(f'.{path.name}.tmp')
    pq.write_table(table, tmp)
    tmp.replace(path)
