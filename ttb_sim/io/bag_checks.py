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
Bag files that cannot be read, said in one line: what is wrong with which file.

:func:`check_metadata` refuses a ``metadata.yaml`` that is not YAML or not
rosbag2 metadata before rosbags reads it (its own messages quote the YAML
parser over several lines); :func:`unreadable` words what rosbags or a damaged
storage file raised, pointing to ``ttb-sim recover``; :func:`one_line` bounds a
library's message. :func:`check_bag_path` makes every check that needs no bag
library, so that a verb can refuse a wrong path before it imports one;
:func:`unclosed_file` tells the storage file of a bag whose recording did not
finish (read by :mod:`ttb_sim.io.salvage` instead of rosbags).
"""

from __future__ import annotations

from pathlib import Path
import re

from ttb_sim.errors import BagError
import yaml

__all__ = ['check_bag_path', 'check_metadata', 'MAX_METADATA_BYTES', 'MCAP_MAGIC', 'one_line',
           'SIDE_FILES', 'unclosed_file', 'unreadable']

MAX_METADATA_BYTES = 64 << 20
"""Largest ``metadata.yaml`` read (bytes); ours are about 100 bytes per topic."""

MCAP_MAGIC = b'\x89MCAP0\r\n'
"""The bytes an MCAP file begins with and, once closed, ends with."""

SIDE_FILES = ('-journal', '-wal')
"""What SQLite 3 leaves beside a database whose writer did not finish a transaction."""

RECOVER = '`ttb-sim recover` may rescue it'
"""The advice for a storage file cut short or damaged."""

MAX_DETAIL = 300
"""Most characters of a reader's own message quoted in a BagError."""

METADATA_PROBLEMS = ('Could not read metadata', 'Could not load YAML',
                     'A metadata key is missing', 'Invalid bag metadata', 'Rosbag2 version',
                     'Some database files are missing', 'Storage plugin', 'Compression format',
                     'Serialization format')
"""How rosbags' messages about ``metadata.yaml`` begin (the rest are about storage files)."""

_KINDS = {type(None): 'nothing (an empty file)', list: 'a list', str: 'a string',
          dict: 'an empty mapping', int: 'a number', float: 'a number', bool: 'a boolean'}
"""What a YAML document that is not rosbag2 metadata holds, for messages."""


def one_line(text: str) -> str:
    """Return a library's message on one line, at most about :data:`MAX_DETAIL` characters."""
    text = ' '.join(text.split())
    if len(text) > MAX_DETAIL:
        text = f'{text[:MAX_DETAIL // 2]}...{text[-MAX_DETAIL // 2:]} ({len(text)} characters)'
    return text


def check_bag_path(path: Path) -> None:
    """
    Refuse a path that is not a bag, without reading its storage files.

    Raises
    ------
    BagError
        If ``path`` does not exist, is a file other than ``.mcap`` / ``.db3``,
        neither a file nor a directory, a directory without ``metadata.yaml``
        and with no storage file or several (one alone is a recording that
        did not finish: :func:`unclosed_file`), or with a ``metadata.yaml``
        that :func:`check_metadata` refuses.

    """
    try:
        path.stat()
    except FileNotFoundError:
        raise BagError(f'bag {str(path)!r} does not exist') from None
    except (OSError, ValueError) as exc:   # a name too long, a NUL byte, a loop of links
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise BagError(f'bag {one_line(repr(str(path)))} cannot be reached ({reason})') from None
    if path.is_file():
        if path.suffix not in ('.mcap', '.db3'):
            msg = f'{str(path)!r} is not a bag: give its directory (with metadata.yaml) or ' \
                  'its .mcap / .db3 file'
            raise BagError(msg)
        return
    if not path.is_dir():
        raise BagError(f'{str(path)!r} is not a bag: neither a file nor a directory')
    if not (path / 'metadata.yaml').is_file():
        storage = _storage_files(path)
        if len(storage) == 1:    # a recording that did not finish: read by salvage
            return
        if storage:
            msg = f'{str(path)!r} has {", ".join(p.name for p in storage)} but no ' \
                  'metadata.yaml: the recording did not finish (a killed run?); give ' \
                  '`ttb-sim recover` one storage file at a time'
        else:
            msg = f'{str(path)!r} is not a rosbag2 directory (no metadata.yaml)'
        raise BagError(msg)
    check_metadata(path / 'metadata.yaml')


def _storage_files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.suffix in ('.mcap', '.db3') and p.is_file())


def unclosed_file(path: Path) -> Path | None:
    """
    Return the storage file of a bag whose recording did not finish, or None.

    That is the one storage file of a directory without ``metadata.yaml``
    (rosbag2 writes it on close), an ``.mcap`` file that does not end with its
    footer's magic, or a ``.db3`` file beside a hot journal (``-journal``,
    ``-wal``). Call after :func:`check_bag_path`.
    """
    if path.is_dir():
        if (path / 'metadata.yaml').is_file():
            return None
        storage = _storage_files(path)
        return storage[0] if len(storage) == 1 else None
    if path.suffix == '.db3':
        return path if any(path.with_name(path.name + s).exists() for s in SIDE_FILES) \
            else None
    try:
        with path.open('rb') as stream:
            stream.seek(max(path.stat().st_size - len(MCAP_MAGIC), 0))
            return None if stream.read() == MCAP_MAGIC else path
    except OSError:
        return None     # rosbags says what is wrong


def check_metadata(path: Path) -> None:
    """
    Refuse a ``metadata.yaml`` that is not YAML or not rosbag2 metadata, naming the file.

    rosbags' own messages quote the YAML parser over several lines; this one
    says in one line what is wrong where (line and column for a syntax error).

    Raises
    ------
    BagError
        If the file cannot be read, is larger than :data:`MAX_METADATA_BYTES`,
        is not valid YAML, lacks the ``rosbag2_bagfile_information`` mapping,
        or lists storage files that are not beside it.

    """
    name = f'bag metadata {str(path)!r}'
    try:
        size = path.stat().st_size
        if size > MAX_METADATA_BYTES:
            msg = f'{name} is too large: {size} bytes, the limit is {MAX_METADATA_BYTES} bytes'
            raise BagError(msg)
        text = path.read_bytes().decode('utf-8')
    except (OSError, UnicodeDecodeError) as exc:
        reason = (exc.strerror or str(exc)) if isinstance(exc, OSError) else \
            f'not UTF-8 text ({exc.reason})'
        msg = f'{name} cannot be read: {reason}'
        raise BagError(msg) from None
    try:
        data = yaml.load(text, Loader=getattr(yaml, 'CSafeLoader', yaml.SafeLoader))
    except yaml.YAMLError as exc:
        raise BagError(f'{name} is not valid YAML: {_yaml_problem(exc)}') from None
    except (ValueError, TypeError, IndexError, OverflowError) as exc:  # a bad scalar
        raise BagError(f'{name} is not valid YAML: {one_line(str(exc))}') from None
    info = data.get('rosbag2_bagfile_information') if isinstance(data, dict) else None
    if not isinstance(info, dict):
        found = _KINDS.get(type(data), type(data).__name__)
        if isinstance(data, dict) and data:
            found = f'the keys {one_line(", ".join(map(str, data)))}'
        msg = f'{name} is not rosbag2 metadata: it needs a mapping ' \
              f"'rosbag2_bagfile_information' at the top, found {found}"
        raise BagError(msg)
    files = info.get('relative_file_paths')
    if isinstance(files, list):
        missing = [str(f) for f in files if not (path.parent / Path(str(f)).name).is_file()]
        if missing:
            msg = f'{name} lists storage files that are not in {str(path.parent)!r}: ' \
                  f'{one_line(", ".join(missing))}'
            raise BagError(msg)


def _yaml_problem(exc: yaml.YAMLError) -> str:
    """Return a YAML error as one line: the problem and its line and column."""
    if not isinstance(exc, yaml.MarkedYAMLError):
        return one_line(str(exc))
    what = one_line('; '.join(p for p in (exc.context, exc.problem) if p) or 'invalid YAML')
    mark = exc.problem_mark or exc.context_mark
    return what if mark is None else f'{what} (line {mark.line + 1}, column {mark.column + 1})'


def unreadable(path: Path, exc: Exception) -> str:
    """Say what rosbags found wrong, in one line: the metadata, or a storage file cut short."""
    detail = one_line(str(exc))
    if path.is_dir() and detail.startswith(METADATA_PROBLEMS):
        missing = re.fullmatch(r'A metadata key is missing KeyError\((.*)\)\.?', detail)
        if missing:
            detail = f'the key {missing.group(1)} is missing'
        msg = f'bag metadata {str(path / "metadata.yaml")!r} is invalid: {detail}'
        return msg
    files = [path] if path.is_file() else sorted(
        p for p in path.iterdir() if p.suffix in ('.mcap', '.db3'))
    which = f'{str(files[0])!r}' if len(files) == 1 else 'a storage file'
    return f'bag {str(path)!r} is truncated or corrupt ({which}: {detail}); a recording that ' \
        f'was killed leaves such a file: {RECOVER}'
