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
The ``recover`` verb: a bag a killed recording left -> a new, closed bag beside it.

The storage file is read up to its last complete chunk (MCAP) or commit (SQLite
3) by :func:`ttb_sim.io.salvage.salvage` and written as a new bag of the same
storage with a fresh ``metadata.yaml`` (``summary.json`` copied when there is
one); the original is only read. A bag with nothing complete to read back is
refused in one line (exit 2), as any bad argument.
"""

from __future__ import annotations

import logging
from pathlib import Path
import shutil

from ttb_sim.errors import BagError
from ttb_sim.io.bag_checks import check_bag_path

log = logging.getLogger(__name__)

EXIT_OK = 0


def default_output(bag: Path) -> Path:
    """Return the default destination: ``<bag>-recovered`` beside the bag directory."""
    folder = bag if bag.is_dir() else bag.parent
    return folder.with_name(f'{folder.name}-recovered')


def recover(bag: str | Path, *, out: str | Path | None = None) -> int:
    """
    Run ``ttb-sim recover``; return the exit code.

    Raises
    ------
    BagError
        When the bag is missing, not a bag, or holds nothing to recover.
    ScenarioError
        When ``out`` exists or cannot be created.

    """
    path = Path(bag)
    try:
        check_bag_path(path)
    except BagError:
        if not (path.is_dir() and (path / 'metadata.yaml').is_file()):
            raise   # not a bag; a bag whose metadata.yaml is broken is recovered all the same
    file = _storage_file(path)
    target = Path(out) if out is not None else default_output(path)
    storage = 'mcap' if file.suffix == '.mcap' else 'sqlite3'
    from ttb_sim.io.bag import check_destination, make_parents   # the bag libraries
    from ttb_sim.io.salvage import salvage, write_closed
    check_destination(target, storage)
    found = salvage(file)
    make_parents(target)
    written = write_closed(found, target)
    summary = (path if path.is_dir() else path.parent) / 'summary.json'
    if summary.is_file():
        shutil.copyfile(summary, target / 'summary.json')
    state = 'was closed' if found.closed else 'was not closed'
    stop = f'; {found.stop}' if found.stop else ''
    print(f'{target}: {written} messages recovered from {file} ({state}{stop}): '
          f'{found.describe()}')
    return EXIT_OK


def _storage_file(path: Path) -> Path:
    """Return the one storage file of a bag (directory or file)."""
    if path.is_file():
        return path
    files = sorted(p for p in path.iterdir() if p.suffix in ('.mcap', '.db3') and p.is_file())
    if len(files) != 1:
        found = ', '.join(p.name for p in files) or 'none'
        raise BagError(f'bag {str(path)!r} has {len(files)} storage files ({found}): '
                       'give `ttb-sim recover` one .mcap or .db3 file')
    return files[0]
