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

"""Recording frames to rosbag2 (MCAP or SQLite 3) with the rosbags library."""

from __future__ import annotations

import os
from pathlib import Path
import signal
import tempfile
import time
from types import TracebackType
from typing import Any, Sequence

from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.errors import WriterError
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.io.cdr import typestore
from ttb_sim.io.topics import NAMESPACE, Topic
from ttb_sim.sim import Frame

STORAGES = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}
"""Storage back-ends by their rosbag2 plugin names."""


def check_destination(path: str | Path, storage: str, option: str = '--out') -> None:
    """
    Refuse a bag destination that cannot be created, before anything is built or written.

    The destination must not exist (not even as a broken link); its nearest
    existing ancestor must be a directory (not a file, which the path would be
    inside) that this process may write into, so that the missing parents and
    the bag directory can be made.

    Parameters
    ----------
    path : path-like
        The bag directory to create.
    storage : str
        The storage plugin name.
    option : str
        How the user gave the destination (``--out``, or the node's ``bag.path``),
        named in the messages.

    Raises
    ------
    ScenarioError
        Naming the storage and what is allowed, or the destination and why it
        cannot be used.

    """
    if storage not in STORAGES:
        raise ScenarioError(f'storage {shown(storage)}: allowed values are {", ".join(STORAGES)}')
    out = Path(path)
    name = shown(str(path))
    if out.exists() or out.is_symlink():
        raise ScenarioError(f'output directory {name} exists; refusing to overwrite it '
                            f'(choose another {option})')
    try:
        absolute = Path(os.path.abspath(out))
    except (OSError, ValueError) as exc:
        raise ScenarioError(f'output directory {name} is not a usable path ({exc})') from None
    ancestor = absolute.parent
    while not ancestor.exists() and ancestor != ancestor.parent:
        if ancestor.is_symlink():
            raise ScenarioError(f'output directory {name}: {shown(str(ancestor))} is a broken '
                                'link')
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise ScenarioError(f'output directory {name} is inside {shown(str(ancestor))}, which '
                            'is a file, not a directory')
    what = 'parent directory' if ancestor == absolute.parent else 'nearest existing folder'
    problem = None if os.access(ancestor, os.W_OK | os.X_OK) else 'permission denied'
    if problem is None:  # access() says yes to root even on /proc or a read-only mount
        problem = _probe(ancestor)
    if problem is not None:
        raise ScenarioError(f'output directory {name} cannot be created: the {what} '
                            f'{shown(str(ancestor))} is not writable ({problem})')


def _probe(folder: Path) -> str | None:
    """
    Make and remove a folder in ``folder``; return why that failed, or None.

    SIGINT and SIGTERM are held for the instant the probe exists, so that a
    signal handler which ends the process never leaves it behind.
    """
    held = {signal.SIGINT, signal.SIGTERM}
    mask = hasattr(signal, 'pthread_sigmask')
    if mask:
        signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        os.rmdir(tempfile.mkdtemp(prefix='.ttb_sim-probe-', dir=folder))
    except OSError as exc:
        return (exc.strerror or str(exc)).lower()
    finally:
        if mask:
            signal.pthread_sigmask(signal.SIG_UNBLOCK, held)
    return None


def make_parents(path: str | Path) -> None:
    """
    Create the missing parent directories of a bag destination.

    Raises
    ------
    ScenarioError
        If they cannot be made (a race with another process, a full disk).

    """
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ScenarioError(f'cannot create the parent folder of {shown(str(path))}: '
                            f'{exc.strerror or exc}') from None


def default_bag_path(name: str, root: Path = Path('runs')) -> Path:
    """
    Return a new bag directory for a scenario name: ``root/<name>-<YYYYmmdd-HHMMSS>``.

    A suffix ``-2``, ``-3``, ... is added when that directory exists already.
    Nothing is created.

    Parameters
    ----------
    name : str
        Scenario name.
    root : Path
        Folder that holds the runs (``./runs`` by default).

    Returns
    -------
    Path
        A path that does not exist (at the time of the call).

    """
    stem = root / f'{name}-{time.strftime("%Y%m%d-%H%M%S")}'
    path, k = stem, 1
    while path.exists():
        k += 1
        path = stem.with_name(f'{stem.name}-{k}')
    return path


class BagRecorder:
    """
    Write frames as messages of a topic table into a new rosbag2 directory.

    Use as a context manager: the bag is closed (and so readable) however the
    block ends, including on KeyboardInterrupt.

    Parameters
    ----------
    path : path-like
        Bag directory to create; it must not exist.
    topics : sequence of Topic
        The topic table.
    storage : str
        'mcap' (default) or 'sqlite3'.
    namespace : str
        Namespace of the private topics.

    Raises
    ------
    ScenarioError
        If the storage is unknown or the directory exists.

    """

    def __init__(self, path: str | Path, topics: Sequence[Topic], storage: str = 'mcap',
                 namespace: str = NAMESPACE) -> None:
        check_destination(path, storage)
        self.path = Path(path)
        self._store = typestore()
        self._types = self._store.types.__getitem__
        self._topics = list(topics)
        self._writer = Writer(self.path, version=9, storage_plugin=STORAGES[storage])
        self._connections: list[Any] = []
        self._namespace = namespace
        self.messages = 0
        self._open = False

    def __enter__(self) -> BagRecorder:
        """Open the bag and register one connection per topic."""
        try:
            self._writer.open()
        except WriterError as exc:
            raise ScenarioError(f'cannot create bag {shown(str(self.path))}: {exc}') from None
        self._open = True
        self._connections = [
            self._writer.add_connection(t.full_name(self._namespace), t.msgtype,
                                        typestore=self._store)
            for t in self._topics]
        return self

    def write(self, frame: Frame) -> None:
        """Write every topic's message for one frame, stamped with simulation time."""
        stamp = frame.stamp_ns
        serialize = self._store.serialize_cdr
        for topic, conn in zip(self._topics, self._connections):
            msg = topic.message(self._types, frame)
            self._writer.write(conn, stamp, serialize(msg, topic.msgtype))
        self.messages += len(self._topics)

    def close(self) -> None:
        """Close the bag (idempotent)."""
        if self._open:
            self._open = False
            self._writer.close()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        """Close the bag whatever happened inside the block."""
        self.close()
