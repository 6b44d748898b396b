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
Recording frames to rosbag2 (MCAP or SQLite 3) with the rosbags library, a block at a time.

:class:`BagRecorder` keeps the flat rows (:attr:`~ttb_sim.sim.Frame.row`) of the
frames it is given and writes them a block at a time: the CDR bytes of every
topic's messages for the whole block come from :class:`~ttb_sim.io.codec.BlockEncoder`
(layouts learnt from the topic table's own builders); MCAP bags take the block
as one array of message records, SQLite 3 bags as one ``executemany``
(:class:`~ttb_sim.io.block_storage.BlockWriter`: rosbags' writer with storages
that take blocks). The messages, their order, stamps and bytes are those of
the per-message path (``bulk=False``: each message built and serialised by
rosbags, written by rosbags' own storages), which stays as the reference.
"""

from __future__ import annotations

import errno
import logging
import os
from pathlib import Path
import signal
import tempfile
import time
from types import TracebackType
from typing import Any, Sequence

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.errors import WriterError
from ttb_sim.errors import ScenarioError
from ttb_sim.inputs import shown
from ttb_sim.io.block_storage import BlockWriter, message_prefix, TIME_OFFSETS
from ttb_sim.io.cdr import typestore
from ttb_sim.io.codec import BlockEncoder, learn
from ttb_sim.io.topics import NAMESPACE, Topic
from ttb_sim.sim import Frame

log = logging.getLogger(__name__)

STORAGES = {'mcap': StoragePlugin.MCAP, 'sqlite3': StoragePlugin.SQLITE3}
"""Storage back-ends by their rosbag2 plugin names."""
BLOCK_BYTES = 2 ** 18
"""About how many bytes of messages a block of frames holds before it is written."""
MAX_BLOCK_FRAMES = 512
"""The most frames a block holds (a live node's bag gets them at most this late)."""
BLOCK_SPAN_NS = 250_000_000
"""A block is written once its frames span this long (ns, simulated): a killed
recording loses at most a block and the storage's open chunk."""
_REASONS = {errno.EROFS: 'read-only file system', errno.EACCES: 'permission denied',
            errno.EPERM: 'permission denied'}


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
    if isinstance(path, str) and not path:
        raise ScenarioError(f'output directory path is empty (give a folder to create with '
                            f'{option})')
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
    # access() says yes to root even on /proc or a read-only mount, and says no without
    # telling why: the probe tells (a read-only file system, or no permission)
    denied = not os.access(ancestor, os.W_OK | os.X_OK)
    problem = _probe(ancestor)
    if problem is None and denied:
        problem = 'permission denied'
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
        return _REASONS.get(exc.errno or 0, (exc.strerror or str(exc)).lower())
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
    block ends, including on KeyboardInterrupt. Frames are kept and written a
    block at a time (:data:`BLOCK_BYTES`, at most :data:`MAX_BLOCK_FRAMES`);
    :meth:`flush` writes those kept so far, :meth:`close` writes them and closes.

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
    bulk : bool
        True (default): serialise blocks of frames with learnt layouts; False:
        build and serialise every message with rosbags (the reference path,
        also taken when a topic's layout cannot be learnt).
    extra : sequence of (str, str)
        (name, message type) of topics whose messages come one by one, at times of
        their own (:meth:`write_message`): the virtual sensors and the labels.

    Raises
    ------
    ScenarioError
        If the storage is unknown or the directory exists.

    """

    def __init__(self, path: str | Path, topics: Sequence[Topic], storage: str = 'mcap',
                 namespace: str = NAMESPACE, bulk: bool = True,
                 extra: Sequence[tuple[str, str]] = ()) -> None:
        check_destination(path, storage)
        self.path = Path(path)
        self._store = typestore()
        self._types = self._store.types.__getitem__
        self._topics = list(topics)
        self._mcap = storage == 'mcap'
        self._bulk = bulk
        writer = BlockWriter if bulk else Writer
        self._writer = writer(self.path, version=9, storage_plugin=STORAGES[storage])
        self._connections: list[Any] = []
        self._extra = list(extra)
        self._extra_connections: list[Any] = []
        self._namespace = namespace
        self.messages = 0
        self._open = False
        self._encoder: BlockEncoder | None = None
        self._rows: list[np.ndarray] = []     # the flat rows of the frames kept
        self._stamps: list[int] = []
        self._width = -1                      # values per frame (-1: no frame yet)
        self._capacity = 1                    # frames per block

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
        self._extra_connections = [
            self._writer.add_connection(name if name.startswith('/')
                                        else f'{self._namespace}/{name}', msgtype,
                                        typestore=self._store)
            for name, msgtype in self._extra]
        if self._bulk:
            self._encoder = self._block_encoder()
        return self

    def _block_encoder(self) -> BlockEncoder | None:
        """Return the encoder of the topic table (None: some topic has no fixed layout)."""
        learnt = [learn(self._store, t) for t in self._topics]
        codecs = [c for c in learnt if c is not None]
        if len(codecs) < len(learnt):
            missing = [t.name for t, c in zip(self._topics, learnt) if c is None]
            log.warning('no fixed CDR layout for %s: writing message by message',
                        ', '.join(missing))
            return None
        if not self._mcap:
            return BlockEncoder(self._topics, codecs)
        prefixes = [message_prefix(c.id, len(codec.template))
                    for c, codec in zip(self._connections, codecs)]
        return BlockEncoder(self._topics, codecs, prefixes, TIME_OFFSETS)

    def write(self, frame: Frame) -> None:
        """Write (or keep for the next block) every topic's message of one frame."""
        if self._encoder is None:
            stamp = frame.stamp_ns
            serialize = self._store.serialize_cdr
            for topic, conn in zip(self._topics, self._connections):
                msg = topic.message(self._types, frame)
                self._writer.write(conn, stamp, serialize(msg, topic.msgtype))
        else:
            self._keep(frame)
        self.messages += len(self._topics)

    def write_message(self, index: int, stamp_ns: int, message: Any) -> None:
        """Write one message of the ``index``-th extra topic, stamped ``stamp_ns``."""
        name, msgtype = self._extra[index]
        self._writer.write(self._extra_connections[index], int(stamp_ns),
                           self._store.serialize_cdr(message, msgtype))
        self.messages += 1

    @property
    def extra(self) -> list[tuple[str, str]]:
        """Return (name, message type) of the extra topics, in :meth:`write_message` order."""
        return list(self._extra)

    @property
    def types(self) -> Any:
        """Return the map from a type name to its message class (rosbags' typestore)."""
        return self._types

    def set_custom_data(self, key: str, value: str) -> None:
        """Store ``key: value`` in the bag's metadata (rosbag2's ``custom_data``)."""
        self._writer.set_custom_data(key, value)

    def _keep(self, frame: Frame) -> None:
        row = frame.row
        if row.size != self._width:
            self._set_width(row.size, frame.time)
        self._rows.append(row)
        self._stamps.append(frame.stamp_ns)
        if len(self._rows) == self._capacity or \
                self._stamps[-1] - self._stamps[0] >= BLOCK_SPAN_NS:
            self.flush()

    def _set_width(self, width: int, time: float) -> None:
        """Take the number of values of the first frame (and size the blocks by it)."""
        assert self._encoder is not None
        if self._width >= 0:
            raise ValueError(f'frame at t = {time:g} s has {width} values; the frames '
                             f'before it had {self._width}')
        needed = max((int(t.index.max(initial=0)) for t in self._topics), default=0) + 1
        if width < needed:
            raise ValueError(f'a frame has {width} values; the topic table reads {needed}')
        self._width = width
        self._capacity = max(1, min(MAX_BLOCK_FRAMES,
                                    BLOCK_BYTES // max(self._encoder.width, 1)))

    def flush(self) -> None:
        """Write the frames kept for the block so far."""
        rows, stamps, self._rows, self._stamps = self._rows, self._stamps, [], []
        if not rows or self._encoder is None:
            return
        times = np.array(stamps, dtype=np.int64)
        records = self._encoder.encode(times, np.stack(rows))
        assert isinstance(self._writer, BlockWriter)
        starts = self._encoder.starts if self._mcap else self._encoder.data_starts
        self._writer.write_frames(self._connections, records, starts, self._encoder.ends,
                                  times)

    def close(self) -> None:
        """Write the frames kept, then close the bag (idempotent)."""
        if self._open:
            self._open = False
            try:
                self.flush()
            finally:
                self._writer.close()

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        """Close the bag whatever happened inside the block."""
        self.close()
