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
Bounded handling of user input: values shown in messages, and files read from disk.

Every message that embeds a user value goes through :func:`shown`, which never
costs more than a few hundred characters however large (or alias-expanded) the
value is, and notes the full length when it cuts. Every user file (scenario
YAML, irregularity CSV) is read with :func:`read_user_file`, which accepts only
regular files up to a size limit and reads no more than that.
"""

from __future__ import annotations

import os
from os import PathLike
from pathlib import Path
import reprlib
import stat
from typing import Any

from ttb_sim.errors import ScenarioError

__all__ = ['MAX_SHOWN', 'read_user_file', 'shown']

MAX_SHOWN = 120
"""Most characters of a user value shown in a message (before the length note)."""

_REPR = reprlib.Repr()
_REPR.maxlevel = 3
_REPR.maxlist = _REPR.maxtuple = _REPR.maxdict = _REPR.maxset = 8
_REPR.maxstring = MAX_SHOWN
_REPR.maxother = MAX_SHOWN
_REPR.maxlong = 40


def shown(value: Any) -> str:
    """
    Return a bounded ``repr`` of a user value for an error message.

    Containers show their first items and at most three levels (``...`` marks
    what is left out), long strings their start and end; when anything was cut
    a note gives the full size, e.g. ``'aaaa...aaaa' (100000 characters)``. The
    cost is bounded too: a YAML alias bomb is never expanded.

    Parameters
    ----------
    value : Any
        The value to show.

    Returns
    -------
    str
        At most about ``MAX_SHOWN`` + 30 characters.

    """
    try:
        text = _REPR.repr(value)
    except Exception:  # noqa: B902 - a repr that fails (e.g. an int over 4300 digits)
        text = (f'<int of {value.bit_length()} bits>' if isinstance(value, int)
                else f'<{type(value).__name__}>')
    note = ''
    if isinstance(value, (str, bytes)) and len(value) > MAX_SHOWN:
        note = f' ({len(value)} characters)'
    elif isinstance(value, (list, tuple, dict, set, frozenset)) and (
            len(value) > _REPR.maxlist or '...' in text):
        note = f' ({type(value).__name__} of {len(value)} items)'
    elif isinstance(value, int) and not isinstance(value, bool) and len(text) > 40:
        note = f' ({value.bit_length()} bits)'
    if len(text) > MAX_SHOWN + 2:
        text = text[:MAX_SHOWN // 2] + '...' + text[-MAX_SHOWN // 2:]
        note = note or f' (shown {MAX_SHOWN} characters)'
    return text + note


def read_user_file(path: str | PathLike[str], what: str, limit: int, *,
                   encoding: str = 'utf-8') -> str:
    """
    Read a user file as text: a regular file of at most ``limit`` bytes.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    what : str
        What the file is, for messages ('scenario file', 'irregularity file').
    limit : int
        Largest accepted size (bytes); no more than ``limit`` + 1 bytes are read.
    encoding : str
        Text encoding.

    Returns
    -------
    str
        The text.

    Raises
    ------
    ScenarioError
        If the file does not exist, is a directory or another non-regular file
        (a device such as /dev/zero, a FIFO), is larger than ``limit``, cannot
        be read or is not valid text; the message names the file.

    """
    name = shown(os.fspath(path))
    try:
        info = os.stat(path)
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ScenarioError(f'{what} {name} does not exist or cannot be reached '
                            f'({reason})') from None
    if stat.S_ISDIR(info.st_mode):
        raise ScenarioError(f'{what} {name} is a directory, not a file')
    if not stat.S_ISREG(info.st_mode):
        raise ScenarioError(f'{what} {name} is not a regular file (a device, FIFO or socket '
                            'cannot be read as one)')
    if info.st_size > limit:
        raise ScenarioError(f'{what} {name} is too large: {info.st_size} bytes, the limit is '
                            f'{limit} bytes')
    try:
        with Path(path).open('rb') as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise ScenarioError(f'cannot read {what} {name}: {exc.strerror or exc}') from None
    if len(data) > limit:
        raise ScenarioError(f'{what} {name} is too large: over {limit} bytes')
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise ScenarioError(f'cannot read {what} {name}: not {encoding} text (byte '
                            f'{exc.start}: {exc.reason})') from None
