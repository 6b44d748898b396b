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
What a killed recording left, read back: MCAP up to its last complete chunk, SQLite 3 commits.

A recording killed by SIGKILL (or a power cut) leaves its storage file without
what rosbag2 writes on close: ``metadata.yaml``, and for MCAP the summary and
footer. :func:`salvage` reads such a file (or any storage file, closed or not)
without them: an MCAP file with the ``mcap`` library's stream reader, record
after record up to the first one cut short or damaged (the messages of a chunk
come only with the whole chunk); an SQLite 3 file by its committed
transactions (a copy is opened where a hot journal must be rolled back: the
original is never written). :func:`write_closed` writes what was read as a
new, closed bag with a fresh ``metadata.yaml`` (``ttb-sim recover``); the bag
reader reads an unclosed bag through :func:`salvage` directly (``ttb-sim
analyze``).
"""

from __future__ import annotations

from dataclasses import dataclass
import logging
from pathlib import Path
import shutil
import sqlite3
import struct
import tempfile
from typing import Any, Iterable, Iterator

from mcap.exceptions import EndOfFile, InvalidMagic, McapError, RecordLengthLimitExceeded
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader
from rosbags.interfaces import (Connection, ConnectionExtRosbag2, MessageDefinition,
                                MessageDefinitionFormat)
from rosbags.rosbag2 import ReaderError, StoragePlugin, Writer
from rosbags.rosbag2.errors import WriterError
from rosbags.rosbag2.metadata import parse_qos
from ttb_sim.errors import BagError
from ttb_sim.io.bag_checks import MCAP_MAGIC, one_line, SIDE_FILES
from ttb_sim.io.cdr import typestore

log = logging.getLogger(__name__)

__all__ = ['salvage', 'Salvage', 'write_closed']

Record = tuple[int, int, bytes]
"""A message as stored: connection id, log time (ns), serialised data."""

_FORMATS = {'ros2msg': MessageDefinitionFormat.MSG, 'ros2idl': MessageDefinitionFormat.IDL}
_DAMAGED = (McapError, struct.error, ValueError, UnicodeDecodeError, IndexError, KeyError,
            OverflowError, MemoryError, EOFError)
"""What the stream reader raises at a record cut short or damaged."""


@dataclass
class Salvage:
    """
    The messages read back from one storage file, in the order they were recorded.

    Attributes
    ----------
    file : Path
        The storage file.
    storage : str
        'mcap' or 'sqlite3'.
    connections : list of Connection
        rosbags connections (id, topic, type, definition, QoS), as the file has them.
    records : list of Record
        Every message read: (connection id, log time ns, data).
    closed : bool
        Whether the file was closed by its writer (an MCAP footer; an SQLite
        file without a hot journal and with its rosbag2 metadata row).
    stop : str
        Why reading stopped before the file's end ('' when it did not).

    """

    file: Path
    storage: str
    connections: list[Connection]
    records: list[Record]
    closed: bool
    stop: str = ''

    def messages(self, connections: Iterable[Connection] = ()) -> Iterator[
            tuple[Connection, int, bytes]]:
        """Yield (connection, log time, data) like rosbags' reader (all connections by default)."""
        wanted = {c.id for c in connections} or {c.id for c in self.connections}
        by_id = {c.id: c for c in self.connections}
        for cid, stamp, data in self.records:
            if cid in wanted:
                yield by_id[cid], stamp, data

    def describe(self) -> str:
        """Say in a few words what was read: messages, topics and the time span."""
        times = [r[1] for r in self.records]
        span = f't = {min(times) * 1e-9:.3f} .. {max(times) * 1e-9:.3f} s' if times else 'none'
        return f'{len(self.records)} messages of {len(self.connections)} topics, {span}'


def salvage(file: Path) -> Salvage:
    """
    Read every complete message of a storage file, without its summary or ``metadata.yaml``.

    Raises
    ------
    BagError
        If the file cannot be read, or holds no complete message to read back
        (killed before its first chunk or commit).

    """
    try:
        found = _mcap(file) if file.suffix == '.mcap' else _sqlite(file)
    except OSError as exc:
        raise BagError(f'storage file {str(file)!r} cannot be read: '
                       f'{exc.strerror or exc}') from None
    if not found.records:
        what = 'chunk' if found.storage == 'mcap' else 'committed transaction'
        why = f' ({found.stop})' if found.stop else ''
        raise BagError(f'nothing to recover in {str(file)!r}: it holds no message in a '
                       f'complete {what}{why}')
    return found


# -- MCAP -----------------------------------------------------------------------------------

def _mcap(file: Path) -> Salvage:
    """Read an MCAP file record by record, up to the first record cut short or damaged."""
    size = file.stat().st_size
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    records: list[Record] = []
    stop = ''
    with file.open('rb') as stream:
        reader = StreamReader(stream, record_size_limit=max(size, 1))
        try:
            for record in reader.records:
                if isinstance(record, Message):
                    if record.channel_id in channels:
                        records.append((record.channel_id, record.log_time, record.data))
                elif isinstance(record, Channel):
                    channels.setdefault(record.id, record)
                elif isinstance(record, Schema):
                    schemas.setdefault(record.id, record)
        except (EndOfFile, RecordLengthLimitExceeded):   # a record longer than the rest
            stop = 'the file ends inside a record'
        except InvalidMagic:
            stop = 'it does not begin with the MCAP magic: not an MCAP file'
        except _DAMAGED as exc:
            stop = f'a damaged record ({type(exc).__name__}' + (
                f': {one_line(str(exc))})' if str(exc) else ')')
        tail = _tail(stream, size)
    connections = [_mcap_connection(c, schemas.get(c.schema_id)) for c in channels.values()]
    return Salvage(file, 'mcap', connections, records, closed=tail == MCAP_MAGIC, stop=stop)


def _tail(stream: Any, size: int) -> bytes:
    """Return the last bytes of a file: the footer's magic when it was closed."""
    if size < len(MCAP_MAGIC):
        return b''
    stream.seek(size - len(MCAP_MAGIC))
    return bytes(stream.read(len(MCAP_MAGIC)))


def _mcap_connection(channel: Channel, schema: Schema | None) -> Connection:
    """Return the rosbags connection of an MCAP channel and its schema."""
    msgtype = schema.name if schema is not None else ''
    definition = MessageDefinition(_FORMATS.get(schema.encoding, MessageDefinitionFormat.NONE),
                                   schema.data.decode(errors='replace')) \
        if schema is not None else MessageDefinition(MessageDefinitionFormat.NONE, '')
    qos = _qos(channel.metadata.get('offered_qos_profiles', ''))
    return Connection(channel.id, channel.topic, msgtype, definition, '', 0,
                      ConnectionExtRosbag2(channel.message_encoding, qos), None)


def _qos(text: str) -> list[Any]:
    try:
        return parse_qos(text)
    except (ReaderError, TypeError, KeyError, ValueError, AttributeError):
        return []


# -- SQLite 3 -------------------------------------------------------------------------------

def _sqlite(file: Path) -> Salvage:
    """Read an SQLite 3 file's committed messages (a copy rolls a hot journal back)."""
    sides = [file.with_name(file.name + s) for s in SIDE_FILES]
    hot = any(p.exists() for p in sides)
    with tempfile.TemporaryDirectory(prefix='ttb_sim-salvage-') as scratch:
        target = file
        if hot:    # rolling the journal back writes the file: on a copy
            target = Path(scratch) / file.name
            for source in (file, *sides):
                if source.exists():
                    shutil.copyfile(source, target.with_name(source.name))
        uri = f'file:{target}' if hot else f'file:{target}?mode=ro'
        try:
            db = sqlite3.connect(uri, uri=True)
        except sqlite3.Error as exc:
            raise BagError(f'storage file {str(file)!r} is not an SQLite 3 database: '
                           f'{one_line(str(exc))}') from None
        try:
            return _sqlite_read(db, file, hot)
        finally:
            db.close()


def _sqlite_read(db: sqlite3.Connection, file: Path, hot: bool) -> Salvage:
    """Read the topics, then the messages in the order they were inserted."""
    try:
        connections = _sqlite_connections(db)
        closed = not hot and bool(db.execute('SELECT count(*) FROM metadata').fetchone()[0])
    except sqlite3.Error as exc:
        raise BagError(f'storage file {str(file)!r} is not a rosbag2 database or is damaged '
                       f'before its first message: {one_line(str(exc))}') from None
    known = {c.id for c in connections}
    records: list[Record] = []
    stop = ''
    try:
        cursor = db.execute('SELECT topic_id, timestamp, data FROM messages ORDER BY id')
        while rows := cursor.fetchmany(4096):
            records.extend((int(t), int(s), bytes(d)) for t, s, d in rows if t in known)
    except sqlite3.Error as exc:
        stop = f'the database is damaged after {len(records)} messages: {one_line(str(exc))}'
    return Salvage(file, 'sqlite3', connections, records, closed=closed, stop=stop)


def _sqlite_connections(db: sqlite3.Connection) -> list[Connection]:
    """Return the rosbags connections of the ``topics`` and ``message_definitions`` tables."""
    definitions: dict[str, tuple[str, str, str]] = {}
    tables = {row[0] for row in db.execute("SELECT name FROM sqlite_master WHERE type='table'")}
    if 'message_definitions' in tables:
        for name, encoding, text, digest in db.execute(
                'SELECT topic_type, encoding, encoded_message_definition, '
                'type_description_hash FROM message_definitions'):
            definitions[name] = (encoding, text, digest)
    cursor = db.execute('SELECT * FROM topics ORDER BY id')
    names = [d[0] for d in cursor.description]
    out = []
    for row in cursor.fetchall():
        topic = dict(zip(names, row))
        encoding, text, digest = definitions.get(topic['type'], ('', '', ''))
        definition = MessageDefinition(_FORMATS.get(encoding, MessageDefinitionFormat.NONE),
                                       text)
        qos = _qos(str(topic.get('offered_qos_profiles') or ''))
        out.append(Connection(int(topic['id']), topic['name'], topic['type'], definition,
                              str(topic.get('type_description_hash') or digest or ''), 0,
                              ConnectionExtRosbag2(topic['serialization_format'], qos), None))
    return out


# -- writing a closed bag -------------------------------------------------------------------

def write_closed(found: Salvage, out: Path) -> int:
    """
    Write the messages read back as a new, closed bag (same storage) at ``out``; return them.

    Topics whose type neither the file defines nor the ROS 2 type store knows
    are left out, with a warning.

    Raises
    ------
    BagError
        If the bag cannot be created.

    """
    plugin = StoragePlugin.MCAP if found.storage == 'mcap' else StoragePlugin.SQLITE3
    store = typestore()
    written = 0
    try:
        with Writer(out, version=9, storage_plugin=plugin) as writer:
            added = {}
            for conn in found.connections:
                new = _add(writer, store, conn)
                if new is not None:
                    added[conn.id] = new
            for cid, stamp, data in found.records:
                if cid in added:
                    writer.write(added[cid], stamp, data)
                    written += 1
    except WriterError as exc:
        raise BagError(f'cannot write the recovered bag {str(out)!r}: '
                       f'{one_line(str(exc))}') from None
    return written


def _add(writer: Writer, store: Any, conn: Connection) -> Connection | None:
    """Add a connection to the new bag: by the type store, or the file's own definition."""
    ext = conn.ext
    assert isinstance(ext, ConnectionExtRosbag2)
    options: dict[str, Any] = {'serialization_format': ext.serialization_format,
                               'offered_qos_profiles': ext.offered_qos_profiles}
    if conn.msgtype in store.types:
        options['typestore'] = store
    elif conn.msgdef.data and conn.digest:
        options.update(msgdef=conn.msgdef.data, rihs01=conn.digest)
    else:
        log.warning('topic %s (%s) left out: its type is unknown and the file does not '
                    'define it', conn.topic, conn.msgtype or 'no type')
        return None
    return writer.add_connection(conn.topic, conn.msgtype, **options)
