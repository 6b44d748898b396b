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
Bulk CDR: the serialised messages of many frames at once, learnt from the topic table.

A topic's message (:class:`~ttb_sim.io.topics.Topic`) has the same CDR layout in
every frame: only its stamp and its numbers change. :func:`learn` finds that
layout from the topic's own builder, which stays the one definition of the
message: it serialises the builder's messages with rosbags for a few probe
stamps and values, finds where each probe number and the stamp land in the
bytes (float64, or float32 as in ``sensor_msgs/msg/PointCloud2``), and checks
that a message it composes from that template equals the builder's own, byte
for byte, for fresh probes. :class:`BlockEncoder` then writes the messages of
every topic for a block of frames into one ``(frames, bytes)`` array with two
numpy index operations, each message optionally preceded by a record prefix
(the MCAP message record header, with its time fields).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ttb_sim.io.topics import Topic

_PROBE_SECONDS = (1_597_412_345, 1_308_642_075, 1_764_913_520)
_PROBE_NANOSECONDS = (864_209_753, 123_456_789, 975_310_864)
_NS = 1_000_000_000


@dataclass(frozen=True)
class MessageCodec:
    """
    The CDR layout of one topic's messages.

    Attributes
    ----------
    template : numpy.ndarray
        uint8 bytes of the message at stamp 0 with every value 0.
    stamp : int or None
        Byte offset of the ``builtin_interfaces/msg/Time`` (int32 sec, uint32
        nanosec), None when the message has none.
    offsets : numpy.ndarray
        Byte offset of each value, in the topic's value order.
    float32 : numpy.ndarray
        Per value: True if stored as float32, False if float64.

    """

    template: np.ndarray
    stamp: int | None
    offsets: np.ndarray
    float32: np.ndarray


def _stamp_bytes(stamps: np.ndarray) -> np.ndarray:
    """Return ``(n, 8)`` uint8: int32 seconds and uint32 nanoseconds of stamps in ns."""
    sec, nanosec = np.divmod(np.asarray(stamps, dtype=np.int64), _NS)
    out = np.empty((len(sec), 2), dtype='<u4')
    out[:, 0] = sec.astype('<i4').view('<u4')
    out[:, 1] = nanosec
    return out.view(np.uint8)


def _find(data: np.ndarray, words: np.ndarray, size: int) -> np.ndarray:
    """
    Return the byte offset of each word in ``data`` (-1: absent, -2: more than once).

    ``words`` are the bit patterns (unsigned, ``size`` bytes, little-endian); every
    byte alignment is searched.
    """
    order = np.argsort(words, kind='stable')
    ranked = words[order]
    found = np.full(len(words), -1, dtype=np.int64)
    count = np.zeros(len(words), dtype=np.int64)
    for align in range(size):
        n = (len(data) - align) // size
        if n <= 0 or not len(words):
            continue
        view = data[align:align + n * size].view(f'<u{size}')
        at = np.minimum(np.searchsorted(ranked, view), len(ranked) - 1)
        hit = np.nonzero(ranked[at] == view)[0]
        index = order[at[hit]]
        np.add.at(count, index, 1)
        found[index] = align + size * hit
    found[count > 1] = -2
    return found


def _serializer(store: Any, topic: Topic) -> Any:
    types = store.types.__getitem__

    def serialize(stamp_ns: int, values: np.ndarray) -> np.ndarray:
        msg = topic.build(types, stamp_ns, values)
        return np.frombuffer(bytes(store.serialize_cdr(msg, topic.msgtype)), dtype=np.uint8)
    return serialize


_MANTISSAS = 2 ** 23 - 1     # 47 * 178481
_SCRAMBLE = 2_654_435_761   # prime to _MANTISSAS: i -> i * _SCRAMBLE is one-to-one modulo it


def _probe(n: int, seed: int) -> np.ndarray:
    """Return ``n`` distinct, scrambled numbers in (1, 2), exact in float32 (so in float64)."""
    steps = (np.arange(1, n + 1, dtype=np.int64) * _SCRAMBLE + seed * 7_919) % _MANTISSAS
    return 1.0 + (steps + 1) * 2.0 ** -23


def learn(store: Any, topic: Topic) -> MessageCodec | None:
    """
    Learn a topic's CDR layout from its builder (None if it has no fixed layout).

    Parameters
    ----------
    store : rosbags Typestore
        The type store the messages are built and serialised with.
    topic : Topic
        The topic (its ``build`` and number of values).

    Returns
    -------
    MessageCodec or None
        A layout that reproduced the builder's bytes for fresh probes, or None
        (the message's size or shape changes with the values, or probes did not
        land at one place each): such a topic takes the per-message path.

    """
    serialize = _serializer(store, topic)
    k = len(topic.columns)
    template = serialize(0, np.zeros(k))
    for attempt in range(len(_PROBE_SECONDS) - 1):
        codec = _locate(serialize, template, k, attempt)
        if codec is not None and _verified(serialize, topic, codec, attempt + 1):
            return codec
    return None


def _locate(serialize: Any, template: np.ndarray, k: int, seed: int) -> MessageCodec | None:
    """Find the stamp and the values of probe messages in their bytes."""
    stamp_ns = _PROBE_SECONDS[seed] * _NS + _PROBE_NANOSECONDS[seed]
    values = _probe(k, seed)
    data = serialize(stamp_ns, values)
    if len(data) != len(template):
        return None
    stamp = _find(data, _stamp_bytes(np.array([stamp_ns])).view('<u8').ravel(), 8)[0]
    offsets = _find(data, values.view('<u8'), 8)
    float32 = offsets == -1
    offsets[float32] = _find(data, values[float32].astype('<f4').view('<u4'), 4)
    if stamp == -2 or np.any(offsets < 0):
        return None
    return MessageCodec(template, None if stamp < 0 else int(stamp), offsets, float32)


def _verified(serialize: Any, topic: Topic, codec: MessageCodec, seed: int) -> bool:
    """Whether the codec composes the builder's bytes for a fresh probe, negative values too."""
    stamp_ns = _PROBE_SECONDS[seed] * _NS + _PROBE_NANOSECONDS[seed]
    row = np.zeros((1, int(topic.index.max(initial=0)) + 1))
    row[0] = _probe(row.shape[1], seed) * np.where(np.arange(row.shape[1]) % 2, -3.0, 5.0)
    want = serialize(stamp_ns, row[0, topic.index])   # (a column may serve twice)
    got = BlockEncoder([topic], [codec]).encode(np.array([stamp_ns]), row)
    return got.shape == (1, len(want)) and bool(np.all(got[0] == want))


class BlockEncoder:
    """
    The messages of every topic of a table for a block of frames, as rows of bytes.

    Row ``k`` holds, for every topic in order, its optional record prefix then
    its CDR message for frame ``k``.

    Parameters
    ----------
    topics : sequence of Topic
        The topics (their value columns in the frames' flat rows).
    codecs : sequence of MessageCodec
        Their layouts (:func:`learn`).
    prefixes : sequence of bytes, optional
        A constant record prefix before each topic's message (none by default).
    time_offsets : sequence of int
        Byte offsets in every prefix that get the frame's stamp as uint64 ns.

    """

    def __init__(self, topics: Sequence[Topic], codecs: Sequence[MessageCodec],
                 prefixes: Sequence[bytes] | None = None,
                 time_offsets: Sequence[int] = ()) -> None:
        prefixes = prefixes or [b''] * len(codecs)
        pieces, starts, ends = [], [], []
        f8_dst, f8_col, f4_dst, f4_col, stamp_dst, time_dst = [], [], [], [], [], []
        position = 0
        for topic, codec, prefix in zip(topics, codecs, prefixes):
            starts.append(position)
            pieces += [np.frombuffer(prefix, dtype=np.uint8), codec.template]
            time_dst += [position + t for t in time_offsets]
            position += len(prefix)
            if codec.stamp is not None:
                stamp_dst.append(position + codec.stamp)
            columns = topic.index
            f8_dst.append(position + codec.offsets[~codec.float32])
            f8_col.append(columns[~codec.float32])
            f4_dst.append(position + codec.offsets[codec.float32])
            f4_col.append(columns[codec.float32])
            position += len(codec.template)
            ends.append(position)
        self.template = np.concatenate(pieces) if pieces else np.zeros(0, dtype=np.uint8)
        self.starts = np.asarray(starts, dtype=np.int64)
        """Byte offset of each topic's record (its prefix) in a row."""
        self.ends = np.asarray(ends, dtype=np.int64)
        """Byte offset just past each topic's message in a row."""
        self.data_starts = self.ends - np.array([len(c.template) for c in codecs], dtype=np.int64)
        """Byte offset of each topic's CDR message in a row."""
        self._f8 = np.concatenate(f8_col or [np.zeros(0, np.intp)]).astype(np.intp)
        self._f4 = np.concatenate(f4_col or [np.zeros(0, np.intp)]).astype(np.intp)
        self._scatter, self._gather = _plan(
            [np.concatenate(f8_dst or [np.zeros(0, np.int64)]),
             np.concatenate(f4_dst or [np.zeros(0, np.int64)]),
             np.asarray(stamp_dst, dtype=np.int64), np.asarray(time_dst, dtype=np.int64)],
            len(self._f8), len(self._f4))

    @property
    def width(self) -> int:
        """Return the bytes of one row (one frame's records)."""
        return len(self.template)

    def encode(self, stamps: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """
        Return the ``(frames, width)`` uint8 records of a block of frames.

        Parameters
        ----------
        stamps : numpy.ndarray
            ``(frames,)`` message stamps in integer ns.
        rows : numpy.ndarray
            ``(frames, row width)`` the frames' flat rows (float64).

        """
        n = len(stamps)
        with np.errstate(over='ignore'):   # beyond float32: inf, as the builders give
            single = np.take(rows, self._f4, axis=1).astype('<f4')
        source = np.concatenate([
            np.take(rows, self._f8, axis=1).view(np.uint8).reshape(n, -1),
            single.view(np.uint8).reshape(n, -1),
            _stamp_bytes(stamps),
            np.asarray(stamps, dtype='<u8').view(np.uint8).reshape(n, 8)], axis=1)
        out = np.tile(self.template, (n, 1))
        out[:, self._scatter] = source[:, self._gather]
        return out


def _plan(destinations: list[np.ndarray], n8: int, n4: int) -> tuple[np.ndarray, np.ndarray]:
    """
    Return the byte destinations in a row and their source bytes in the encoder's source.

    ``destinations`` are the byte offsets of the float64 values, the float32
    values, the stamps (8 bytes each, all from one stamp) and the uint64 times.
    """
    f8, f4, stamps, times = destinations
    stamp_source, time_source = 8 * n8 + 4 * n4, 8 * n8 + 4 * n4 + 8
    scatter = np.concatenate([(f8[:, None] + np.arange(8)).ravel(),
                              (f4[:, None] + np.arange(4)).ravel(),
                              (stamps[:, None] + np.arange(8)).ravel(),
                              (times[:, None] + np.arange(8)).ravel()])
    gather = np.concatenate([np.arange(8 * n8), 8 * n8 + np.arange(4 * n4),
                             np.tile(stamp_source + np.arange(8), len(stamps)),
                             np.tile(time_source + np.arange(8), len(times))])
    return scatter.astype(np.intp), gather.astype(np.intp)
