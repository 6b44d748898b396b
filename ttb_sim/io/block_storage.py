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
Storages for rosbags' rosbag2 writer that take the messages of a block of frames at once.

rosbags' :class:`~rosbags.rosbag2.Writer` keeps doing what it does well: the
connections, message definitions and type hashes, the QoS text, the counts and
``metadata.yaml``. :class:`BlockWriter` only swaps its storages for ones with a
``write_frames`` of many frames' messages (:class:`~ttb_sim.io.codec.BlockEncoder`
rows). :class:`SqliteBlockStorage` is rosbags' own SQLite storage, inserting a
block with one ``executemany`` of rosbags' own statement. :class:`McapBlockStorage`
writes the file rosbags' own MCAP storage
writes (profile ``ros2``, schema encoding ``ros2msg``, message encoding
``cdr``, the ``offered_qos_profiles`` channel metadata, schemas and channels at
the head of the first chunk, uncompressed chunks closed after the message
that takes them past 1 MiB, one message index per channel and chunk, the
``rosbag2`` metadata record, the summary with chunk indexes and statistics,
CRCs left 0) but takes the message records of many frames as one byte array
(:class:`~ttb_sim.io.codec.BlockEncoder`) and indexes them with numpy. Only
the file's ``library`` field differs: it names ttb_sim; and a chunk is also
closed before a message logged :data:`CHUNK_SPAN_NS` (1 s, simulated) or more
after the chunk's first one, which only a lean bag (under 1 MiB a second) meets.

What a killed recording leaves: every closed chunk is handed to the operating
system at once (a SIGKILL loses at most the open chunk: 1 MiB or 1 s of
messages) and synced to the disk at most every :data:`SYNC_SECONDS` of wall
time (a power cut loses at most that much more); :class:`SqliteBlockStorage`
commits every block, where rosbags' storage commits once, on close.
:mod:`ttb_sim.io.salvage` reads such a file back up to its last complete chunk
or transaction.

Neither rosbags' MCAP storage nor the ``mcap`` library's writer takes more
than one message per call, and at about 7-9 microseconds a message (measured)
either cost more than the whole physics of a run of ours.
"""

from __future__ import annotations

from dataclasses import dataclass, field
import os
from pathlib import Path
import time
from typing import Any, cast, Sequence

import numpy as np
from rosbags.interfaces import Connection, ConnectionExtRosbag2, MessageDefinitionFormat
from rosbags.rosbag2 import StoragePlugin, Writer
from rosbags.rosbag2.enums import CompressionMode
from rosbags.rosbag2.errors import WriterError
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Writer

from ttb_sim import __version__

MAGIC = b'\x89MCAP0\r\n'
CHUNK_BYTES = 2 ** 20
"""A chunk is closed after the message that takes it past this size (as rosbags does)."""
CHUNK_SPAN_NS = 10 ** 9
"""A chunk is closed before a message logged this long (ns) after the chunk's first one."""
SYNC_SECONDS = 1.0
"""A closed chunk is synced to the disk (fsync) when the last sync is this old (wall s)."""
RECORD_HEADER = 31
"""Bytes before a message record's data: opcode, length, channel, sequence, two times."""
TIME_OFFSETS = (15, 23)
"""Byte offsets of the log and publish times (uint64 ns) in a message record."""
_NO_START, _NO_END = 2 ** 63 - 1, 0


def _u16(value: int) -> bytes:
    return value.to_bytes(2, 'little')


def _u32(value: int) -> bytes:
    return value.to_bytes(4, 'little')


def _u64(value: int) -> bytes:
    return value.to_bytes(8, 'little')


def _string(text: str | bytes) -> bytes:
    data = text.encode() if isinstance(text, str) else text
    return _u32(len(data)) + data


def _record(opcode: int, body: bytes) -> bytes:
    return bytes((opcode,)) + _u64(len(body)) + body


def _sync_folder(folder: Path) -> None:
    """Sync a folder's entries to the disk (where the system allows it)."""
    try:
        handle = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(handle)
    except OSError:
        pass
    finally:
        os.close(handle)


def message_prefix(channel_id: int, data_size: int) -> bytes:
    """Return a message record's header for a channel, its two times left 0."""
    return (bytes((0x05,)) + _u64(RECORD_HEADER - 9 + data_size) + _u16(channel_id)
            + _u32(0) + _u64(0) + _u64(0))


@dataclass
class _Chunk:
    """The chunk being filled: its byte pieces and the index of its messages."""

    pieces: list[Any] = field(default_factory=list)
    size: int = 0
    start: int = _NO_START
    end: int = _NO_END
    channels: list[np.ndarray] = field(default_factory=list)
    times: list[np.ndarray] = field(default_factory=list)
    offsets: list[np.ndarray] = field(default_factory=list)

    def add(self, data: Any) -> None:
        self.pieces.append(data)
        self.size += len(data)


class McapBlockStorage:
    """
    The storage plugin: rosbags' MCAP layout, messages taken in blocks.

    Parameters
    ----------
    path : Path
        The bag directory (the file is ``<path>/<name>.mcap``).
    compression : CompressionMode
        Only ``NONE`` (the recorder never compresses).

    """

    LIBRARY = f'ttb_sim-{__version__}'
    """The header's ``library`` field."""

    def __init__(self, path: Path, compression: CompressionMode) -> None:
        if compression != CompressionMode.NONE:
            raise WriterError('the block MCAP storage writes uncompressed chunks only')
        self.path = path / f'{path.name}.mcap'
        self.bio = self.path.open('xb')
        self.bio.write(MAGIC + _record(0x01, _string('ros2') + _string(self.LIBRARY)))
        self.schemas: dict[str, int] = {}
        self.schema_records: list[bytes] = []
        self.channel_records: list[bytes] = []
        self.chunk = _Chunk()
        self.chunk_indexes: list[bytes] = []
        self.counts: dict[int, int] = {}
        self.start, self.end = _NO_START, _NO_END
        self.synced: float | None = None   # when the file was last synced (None: never)

    def add_msgtype(self, connection: Connection) -> None:
        """Add the schema of a connection's message type."""
        encoding = 'ros2msg' if connection.msgdef.format == MessageDefinitionFormat.MSG \
            else 'ros2idl'
        self.schemas[connection.msgtype] = len(self.schemas) + 1
        record = _record(0x03, _u16(len(self.schemas)) + _string(connection.msgtype)
                         + _string(encoding) + _string(connection.msgdef.data))
        self.schema_records.append(record)
        self.chunk.add(record)

    def add_connection(self, connection: Connection, offered_qos_profiles: str) -> None:
        """Add a channel (its QoS profiles as the rosbag2 metadata text)."""
        metadata = _string('offered_qos_profiles') + _string(offered_qos_profiles)
        record = _record(0x04, _u16(connection.id) + _u16(self.schemas[connection.msgtype])
                         + _string(connection.topic)
                         + _string(cast(ConnectionExtRosbag2, connection.ext).serialization_format)
                         + _u32(len(metadata)) + metadata)
        self.channel_records.append(record)
        self.counts[connection.id] = 0
        self.chunk.add(record)

    def write(self, connection: Connection, timestamp: int, data: bytes | memoryview) -> None:
        """Write one message."""
        record = bytearray(message_prefix(connection.id, len(data)) + bytes(data))
        for offset in TIME_OFFSETS:
            record[offset:offset + 8] = _u64(timestamp)
        self.write_records(np.frombuffer(bytes(record), dtype=np.uint8), np.array([0]),
                           np.array([connection.id]), np.array([timestamp]))

    def write_frames(self, ids: np.ndarray, records: np.ndarray, starts: np.ndarray,
                     ends: np.ndarray, stamps: np.ndarray) -> None:
        """
        Write the message records of a block of frames, frame after frame.

        Parameters
        ----------
        ids : numpy.ndarray
            ``(topics,)`` the channel of each record of a frame.
        records : numpy.ndarray
            ``(frames, bytes)`` uint8: per frame, one MCAP message record
            (:func:`message_prefix` then CDR) per channel, end to end.
        starts, ends : numpy.ndarray
            ``(topics,)`` where each record begins and ends in a row.
        stamps : numpy.ndarray
            ``(frames,)`` each frame's log time (ns), as written in its records.

        """
        n, width = records.shape
        if n and (starts[0] != 0 or ends[-1] != width or np.any(starts[1:] != ends[:-1])):
            raise WriterError('MCAP message records of a frame must lie end to end')
        at = (np.arange(n, dtype=np.int64)[:, None] * width + starts[None, :]).ravel()
        self.write_records(records.reshape(-1), at, np.tile(ids, n),
                           np.repeat(stamps, len(ids)))

    def write_records(self, stream: np.ndarray, starts: np.ndarray, channels: np.ndarray,
                      times: np.ndarray) -> None:
        """
        Write message records laid end to end in one byte array.

        Parameters
        ----------
        stream : numpy.ndarray
            uint8 records, the first at offset 0, the last ending at the end.
        starts : numpy.ndarray
            Offset of each record in ``stream``, increasing.
        channels, times : numpy.ndarray
            Each record's channel id and log time (ns).

        """
        ends = np.append(starts[1:], len(stream))
        first = 0
        while first < len(starts):
            base = int(starts[first]) - self.chunk.size  # stream offset of the chunk's start
            last = int(np.searchsorted(ends, CHUNK_BYTES + base, side='right'))
            last = min(last, len(starts) - 1)            # the message that closes the chunk
            opened = self.chunk.start if self.chunk.channels else int(times[first])
            late = np.flatnonzero(times[first:last + 1] >= opened + CHUNK_SPAN_NS)
            if late.size and late[0] == 0:               # the open chunk is 1 s long already
                self._close_chunk()
                continue
            if late.size:
                last = first + int(late[0]) - 1          # the last message within 1 s
            self._append(stream, starts[first:last + 1], int(ends[last]), base,
                         channels[first:last + 1], times[first:last + 1])
            if self.chunk.size > CHUNK_BYTES or late.size:
                self._close_chunk()
            first = last + 1
        for channel, count in zip(*np.unique(channels, return_counts=True)):
            self.counts[int(channel)] += int(count)
        if len(times):
            self.start = min(self.start, int(times.min()))
            self.end = max(self.end, int(times.max()))

    def _append(self, stream: np.ndarray, starts: np.ndarray, stop: int, base: int,
                channels: np.ndarray, times: np.ndarray) -> None:
        chunk = self.chunk
        chunk.channels.append(channels)
        chunk.times.append(times)
        chunk.offsets.append(starts - base)
        chunk.add(stream[int(starts[0]):stop].data)
        chunk.start = min(chunk.start, int(times.min()))
        chunk.end = max(chunk.end, int(times.max()))

    def _close_chunk(self) -> None:
        """Write the pending chunk and its message indexes; keep its chunk index."""
        chunk, self.chunk = self.chunk, _Chunk()
        start = self.bio.tell()
        body_size = 8 + 8 + 8 + 4 + 4 + 8 + chunk.size
        self.bio.write(bytes((0x06,)) + _u64(body_size) + _u64(chunk.start) + _u64(chunk.end)
                       + _u64(chunk.size) + _u32(0) + _string('') + _u64(chunk.size))
        for piece in chunk.pieces:
            self.bio.write(piece)
        end = self.bio.tell()
        index = b''.join(_u16(channel) + _u64(end + offset)
                         for channel, offset in self._message_indexes(chunk))
        self.chunk_indexes.append(
            _u64(chunk.start) + _u64(chunk.end) + _u64(start) + _u64(end - start)
            + _u32(len(index)) + index + _u64(self.bio.tell() - end) + _string('')
            + _u64(chunk.size) + _u64(chunk.size))
        self._hand_over()

    def _hand_over(self) -> None:
        """Pass what is written to the operating system; sync it when the last sync is old."""
        self.bio.flush()
        now = time.monotonic()
        if self.synced is None or now - self.synced >= SYNC_SECONDS:
            os.fsync(self.bio.fileno())
            if self.synced is None:   # the new file's name in its folder, once
                _sync_folder(self.path.parent)
            self.synced = now

    def _message_indexes(self, chunk: _Chunk) -> list[tuple[int, int]]:
        """
        Write one message index per channel (in order of first message); return where.

        The offsets returned are relative to the first message index record.
        """
        if not chunk.channels:
            return []
        channels = np.concatenate(chunk.channels)
        ids, first, counts = np.unique(channels, return_index=True, return_counts=True)
        sequence = np.argsort(first)               # the channels by their first message
        rank = np.empty_like(sequence)
        rank[sequence] = np.arange(len(sequence))
        order = np.argsort(rank[np.searchsorted(ids, channels)], kind='stable')
        entries = np.empty((len(channels), 2), dtype='<u8')
        entries[:, 0] = np.concatenate(chunk.times)[order]
        entries[:, 1] = np.concatenate(chunk.offsets)[order]
        data = entries.view(np.uint8).reshape(-1)
        pieces: list[Any] = []
        where, at, done = [], 0, 0
        for k in sequence.tolist():
            body = 16 * int(counts[k])
            header = bytes((0x07,)) + _u64(6 + body) + _u16(int(ids[k])) + _u32(body)
            pieces += [header, data[done:done + body]]
            where.append((int(ids[k]), at))
            at += len(header) + body
            done += body
        self.bio.write(b''.join(pieces))
        return where

    def close(self, version: int, metadata: str) -> None:
        """Close the last chunk, write the metadata record and the summary."""
        del version
        if self.chunk.size:
            self._close_chunk()
        bio = self.bio
        metadata_start = bio.tell()
        serialized = _string('serialized_metadata') + _string(metadata)
        bio.write(_record(0x0C, _string('rosbag2') + _u32(len(serialized)) + serialized))
        metadata_end = bio.tell()
        bio.write(_record(0x0F, _u32(0)))
        sections = [(0x03, self.schema_records), (0x04, self.channel_records),
                    (0x08, [_record(0x08, index) for index in self.chunk_indexes])]
        starts = []
        for _, records in sections:
            starts.append(bio.tell())
            bio.write(b''.join(records))
        index_start = bio.tell()
        bio.write(_record(0x0D, _u64(metadata_start) + _u64(metadata_end - metadata_start)
                          + _string('rosbag2')))
        statistics_start = bio.tell()
        per_channel = b''.join(_u16(c) + _u64(n) for c, n in sorted(self.counts.items()))
        bio.write(_record(0x0B, _u64(sum(self.counts.values())) + _u16(len(self.schemas))
                          + _u32(len(self.counts)) + _u32(0) + _u32(1)
                          + _u32(len(self.chunk_indexes)) + _u64(self.start) + _u64(self.end)
                          + _u32(len(per_channel)) + per_channel))
        summary_offsets = bio.tell()
        bounds = [*starts, index_start]
        for (opcode, _), begin, stop in zip(sections, bounds, bounds[1:]):
            if begin != stop:
                bio.write(_record(0x0E, bytes((opcode,)) + _u64(begin) + _u64(stop - begin)))
        for opcode, begin, stop in ((0x0D, index_start, statistics_start),
                                    (0x0B, statistics_start, summary_offsets)):
            bio.write(_record(0x0E, bytes((opcode,)) + _u64(begin) + _u64(stop - begin)))
        bio.write(_record(0x02, _u64(starts[0]) + _u64(summary_offsets) + _u32(0)) + MAGIC)
        bio.close()

    def abort(self) -> None:
        """Close the file without its index and footer."""
        self.bio.close()


class SqliteBlockStorage(Sqlite3Writer):
    """
    rosbags' SQLite 3 storage, inserting the messages of a block of frames at once.

    Unlike rosbags' storage, which commits once, on close, it commits as the
    MCAP storage closes a chunk: once the messages inserted since the last
    commit pass :data:`CHUNK_BYTES` or span :data:`CHUNK_SPAN_NS` (checked
    after every block), so that a killed recording keeps every committed block.
    """

    INSERT = 'INSERT INTO messages (topic_id, timestamp, data) VALUES(?, ?, ?)'
    """rosbags' own statement for a message (rosbag2's ``messages`` table)."""

    def __init__(self, path: Path, compression: CompressionMode) -> None:
        super().__init__(path, compression)
        self.pending = 0                # bytes inserted since the last commit
        self.uncommitted = 0            # messages inserted since the last commit
        self.since: int | None = None   # the first stamp since the last commit (ns)

    def write_frames(self, ids: np.ndarray, records: np.ndarray, starts: np.ndarray,
                     ends: np.ndarray, stamps: np.ndarray) -> None:
        """
        Insert the messages of a block of frames, frame after frame, topic after topic.

        Parameters
        ----------
        ids : numpy.ndarray
            ``(topics,)`` the topic id of each message of a frame.
        records : numpy.ndarray
            ``(frames, bytes)`` uint8 rows holding the messages.
        starts, ends : numpy.ndarray
            ``(topics,)`` where each CDR message begins and ends in a row.
        stamps : numpy.ndarray
            ``(frames,)`` each frame's time stamp (ns).

        """
        n, width = records.shape
        flat = np.ascontiguousarray(records).reshape(-1).data
        base = np.arange(n, dtype=np.int64)[:, None] * width
        slices = map(slice, (base + starts).ravel().tolist(), (base + ends).ravel().tolist())
        self.cursor.executemany(self.INSERT, zip(np.tile(ids, n).tolist(),
                                                 np.repeat(stamps, len(ids)).tolist(),
                                                 map(flat.__getitem__, slices)))
        if n:
            self.pending += records.size
            self.uncommitted += n * len(ids)
            self.since = int(stamps[0]) if self.since is None else self.since
            if self.pending > CHUNK_BYTES or int(stamps[-1]) - self.since >= CHUNK_SPAN_NS:
                self.conn.commit()   # a killed recording keeps every committed block
                self.pending, self.uncommitted, self.since = 0, 0, None


class BlockWriter(Writer):
    """rosbags' rosbag2 writer whose storages take the messages of blocks of frames."""

    STORAGE_PLUGINS = {StoragePlugin.SQLITE3: SqliteBlockStorage,
                       StoragePlugin.MCAP: McapBlockStorage}

    def write_frames(self, connections: Sequence[Connection], records: np.ndarray,
                     starts: np.ndarray, ends: np.ndarray, stamps: np.ndarray) -> None:
        """
        Write the messages of a block of frames, frame after frame, connection after connection.

        Parameters
        ----------
        connections : sequence of Connection
            The connection of each message of a frame, in order.
        records : numpy.ndarray
            ``(frames, bytes)`` uint8 rows: what the storage stores of each
            message of a frame (for MCAP the whole message records, end to end;
            for SQLite 3 the CDR messages).
        starts, ends : numpy.ndarray
            ``(connections,)`` where each connection's part begins and ends in a row.
        stamps : numpy.ndarray
            ``(frames,)`` each frame's time stamp (ns).

        """
        storage = self.storage
        if not isinstance(storage, (McapBlockStorage, SqliteBlockStorage)):
            raise WriterError('the bag is not open with a block storage')
        ids = np.array([c.id for c in connections], dtype=np.int64)
        storage.write_frames(ids, records, starts, ends, stamps)
        n = len(stamps)
        for connection in connections:
            self.counts[connection.id] += n
        if n:
            self.min_timestamp = min(self.min_timestamp, int(stamps.min()))
            self.max_timestamp = max(self.max_timestamp, int(stamps.max()))
