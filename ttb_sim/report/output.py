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
Output folders of ``analyze`` and ``compare``: staged writing, JSON and the ``index.html`` page.

:func:`staged_output` gives a hidden sibling folder to write into and renames it
to the destination only when everything is written, so an interrupted or
failed analysis never leaves a folder that looks complete.  A destination that
holds an earlier analysis (its ``metrics.json``) is replaced; any other
non-empty folder is refused.  :func:`write_json` (NaN and infinities as null) also
writes the files of ``sweep``; :class:`FigureNote` is what the page lists of a figure.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass
import html
import json
import math
import os
from pathlib import Path
import shutil
from typing import Any, Iterator, Sequence

from ttb_sim.errors import ScenarioError


@dataclass(frozen=True)
class FigureNote:
    """A figure written (file, caption) or skipped (file, reason)."""

    name: str
    text: str


def check_output(out: Path) -> None:
    """Refuse an output folder that cannot be (re)written, before any work is done."""
    try:
        out.stat()
    except FileNotFoundError:
        pass
    except (OSError, ValueError) as exc:   # a name too long, a NUL byte, a loop of links
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ScenarioError(f'--out {str(out)!r} cannot be used ({reason})') from None
    if out.exists() and not out.is_dir():
        raise ScenarioError(f'--out {str(out)!r} is a file; give a folder to write the '
                            'figures, metrics.json and index.html into')
    if out.is_dir() and any(out.iterdir()) and not (out / 'metrics.json').is_file():
        raise ScenarioError(f'--out {str(out)!r} is a non-empty folder that is not an earlier '
                            'analysis (no metrics.json); give a new or empty folder')
    parent = out.parent if str(out.parent) else Path('.')
    probe = parent
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir() or not os.access(probe, os.W_OK | os.X_OK):
        raise ScenarioError(f'--out {str(out)!r}: {str(probe)!r} is not a writable folder')


@contextmanager
def staged_output(out: Path) -> Iterator[Path]:
    """Yield a staging folder; on success it replaces ``out``, on any exit else it is removed."""
    out.parent.mkdir(parents=True, exist_ok=True)
    stage = out.parent / f'.{out.name}.partial-{os.getpid()}'
    if stage.exists():
        shutil.rmtree(stage)
    stage.mkdir()
    try:
        yield stage
        old = out.parent / f'.{out.name}.old-{os.getpid()}'
        if out.exists():
            out.rename(old)
        stage.rename(out)
        if old.exists():
            shutil.rmtree(old, ignore_errors=True)
    finally:
        if stage.exists():
            shutil.rmtree(stage, ignore_errors=True)


def write_json(path: Path, data: Any) -> None:
    """Write JSON with NaN and infinities as null."""
    path.write_text(json.dumps(_clean(data), indent=2) + '\n')


def _clean(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _cell(value: Any) -> str:
    if isinstance(value, float):
        return f'{value:.4g}'
    if value is None:
        return '&ndash;'
    return html.escape(str(value))


def _table(head: Sequence[str], rows: Sequence[Sequence[Any]]) -> str:
    out = ['<table><tr>' + ''.join(f'<th>{html.escape(h)}</th>' for h in head) + '</tr>']
    out.extend('<tr>' + ''.join(f'<td>{_cell(c)}</td>' for c in row) + '</tr>' for row in rows)
    return '\n'.join(out) + '</table>'


def index_rows(labels: Sequence[str], metrics: Sequence[dict[str, Any]]) -> list[list[Any]]:
    """
    Return rows (index, unit, limit, value per bag, verdict, where) of the ride and safety indices.

    An index a bag's model cannot produce (value null) shows as 'n/a' with its reason; the
    verdict rates the bags that have a value ('n/a' when none has).
    """
    names: list[str] = []
    for m in metrics:
        names.extend(k for k in m.get('indices', {}) if k not in names)
    rows = []
    for name in names:
        entries = [m.get('indices', {}).get(name) for m in metrics]
        first = next(e for e in entries if e)
        rated = [e for e in entries if e and e.get('value') is not None]
        values = [None if not e else 'n/a' if e.get('value') is None else e['value']
                  for e in entries]
        verdict = 'n/a' if not rated else (
            'within' if all(e['within_limit'] for e in rated) else 'EXCEEDED')
        where = [e['where'] or (f'n/a: {e["reason"]}' if e.get('value') is None
                                and e.get('reason') else '') for e in entries if e]
        rows.append([name.replace('_', ' '), first['unit'], first['limit'], *values, verdict,
                     '; '.join(w for w in where if w)])
    return rows


def write_index(out: Path, title: str, labels: Sequence[str], bags: Sequence[str],
                metrics: Sequence[dict[str, Any]], written: Sequence[FigureNote],
                skipped: Sequence[FigureNote],
                extra: Sequence[tuple[str, Sequence[str], Sequence[Sequence[Any]]]] = ()) -> None:
    """Write ``index.html``: bags, the indices table, extra tables, every figure, the skips."""
    parts = [f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{html.escape(title)}'
             '</title><style>body{font-family:sans-serif;margin:1.5em;max-width:1400px}'
             'table{border-collapse:collapse;margin:0.5em 0 1.5em}td,th{border:1px solid #bbb;'
             'padding:2px 8px;font-size:90%;text-align:left}img{max-width:100%;border:1px '
             'solid #ddd}figure{margin:1em 0 2em}</style></head><body>',
             f'<h1>{html.escape(title)}</h1>']
    parts.append(_table(['label', 'bag', 'scenario', 'speed (km/h)', 'duration (s)',
                         'rate (Hz)'],
                        [[lbl, b, m.get('scenario'), m.get('speed_kmh'), m.get('duration_s'),
                          m.get('sample_rate_hz')] for lbl, b, m in zip(labels, bags, metrics)]))
    parts.append('<h2>Ride comfort and running safety</h2>')
    parts.append(_table(['index', 'unit', 'limit', *labels, 'verdict', 'where'],
                        index_rows(labels, metrics)))
    for heading, head, rows in extra:
        parts.append(f'<h2>{html.escape(heading)}</h2>')
        parts.append(_table(head, rows))
    parts.append('<p>All numbers: <a href="metrics.json">metrics.json</a>.</p><h2>Figures</h2>')
    for note in written:
        parts.append(f'<figure><img src="{html.escape(note.name)}" alt="{html.escape(note.name)}">'
                     f'<figcaption>{html.escape(note.text)}</figcaption></figure>')
    if skipped:
        parts.append('<h2>Figures skipped</h2><ul>')
        parts.extend(f'<li>{html.escape(n.name)}: {html.escape(n.text)}</li>' for n in skipped)
        parts.append('</ul>')
    parts.append('</body></html>')
    (out / 'index.html').write_text('\n'.join(parts) + '\n')
