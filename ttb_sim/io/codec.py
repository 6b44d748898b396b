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
from functools import lru_cache
from typing import Any, Callable, Sequence

import numpy as np

from ttb_sim.io.topics import Topic

Builder = Callable[..., Any]
"""A topic's message builder: (types, stamp_ns, values) -> message."""

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


def _serializer(store: Any, msgtype: str, build: Builder) -> Any:
    types = store.types.__getitem__

    def serialize(stamp_ns: int, values: np.ndarray) -> np.ndarray:
        msg = build(types, stamp_ns, values)
        return np.frombuffer(bytes(store.serialize_cdr(msg, msgtype)), dtype=np.uint8)
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

    Topics of one builder, type and number of values share their layout: it is
    learnt once per type store (the arrays of a codec are read-only).

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
    return _learn(store, topic.msgtype, topic.build, len(topic.columns))


@lru_cache(maxsize=256)
def _learn(store: Any, msgtype: str, build: Builder, k: int) -> MessageCodec | None:
    serialize = _serializer(store, msgtype, build)
    template = serialize(0, np.zeros(k))
    probe = Topic('probe', msgtype, (), tuple(range(k)), build)   # a column per value
    for attempt in range(len(_PROBE_SECONDS) - 1):
        codec = _locate(serialize, template, k, attempt)
        if codec is not None and _verified(serialize, probe, codec, attempt + 1):
            for array in (codec.template, codec.offsets, codec.float32):
                array.setflags(write=False)
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


def _verified(serialize: Any, probe: Topic, codec: MessageCodec, seed: int) -> bool:
    """Whether the codec composes the builder's bytes for fresh values, negative ones too."""
    stamp_ns = _PROBE_SECONDS[seed] * _NS + _PROBE_NANOSECONDS[seed]
    k = len(probe.columns)
    values = _probe(k, seed) * np.where(np.arange(k) % 2, -3.0, 5.0)
    want = serialize(stamp_ns, values)
    got = BlockEncoder([probe], [codec]).encode(np.array([stamp_ns]), values[None, :])
    return got.shape == (1, len(want)) and bool(np.all(got[0] == want))


class BlockEncoder:
    """
    The messages of every topic of a table for a block of frames, as rows of bytes.

    Row ``k`` holds, for every topic in order, its optional record prefix then
    its CDR message for frame ``k``. A row is the template of constant bytes
    with, at fixed offsets, each topic's values (float64 or float32), its stamp
    and the prefix's times: one structured numpy view of the rows receives all
    of them from one packed array per block.

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
        pieces, starts, data_starts = [], [], []
        places: dict[str, list[np.ndarray]] = {'f8': [], 'f4': [], 'stamp': [], 'time': []}
        f8_col, f4_col = [], []
        position = 0
        for topic, codec, prefix in zip(topics, codecs, prefixes):
            starts.append(position)
            pieces += [np.frombuffer(prefix, dtype=np.uint8), codec.template]
            places['time'].append(position + np.asarray(time_offsets, dtype=np.int64))
            position += len(prefix)
            data_starts.append(position)
            if codec.stamp is not None:
                places['stamp'].append(np.array([position + codec.stamp]))
            places['f8'].append(position + codec.offsets[~codec.float32])
            places['f4'].append(position + codec.offsets[codec.float32])
            f8_col.append(topic.index[~codec.float32])
            f4_col.append(topic.index[codec.float32])
            position += len(codec.template)
        self.template = np.concatenate(pieces) if pieces else np.zeros(0, dtype=np.uint8)
        self.starts = np.asarray(starts, dtype=np.int64)
        """Byte offset of each topic's record (its prefix) in a row."""
        self.data_starts = np.asarray(data_starts, dtype=np.int64)
        """Byte offset of each topic's CDR message in a row."""
        self.ends = self.data_starts + [len(c.template) for c in codecs]
        """Byte offset just past each topic's message in a row."""
        self._f8 = _joined(f8_col).astype(np.intp)
        self._f4 = _joined(f4_col).astype(np.intp)
        self._stamps = len(_joined(places['stamp']))
        self._times = self._stamps + len(_joined(places['time']))
        self._destination, self._source = _views(
            {name: _joined(offsets) for name, offsets in places.items()}, self.width)

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
        times = np.empty((n, self._times), dtype='<u8')   # the stamps, then the record times
        times[:, :self._stamps] = _stamp_bytes(stamps).view('<u8')
        times[:, self._stamps:] = np.asarray(stamps, dtype='<u8')[:, None]
        source = np.concatenate([np.take(rows, self._f8, axis=1).view(np.uint8).reshape(n, -1),
                                 single.view(np.uint8).reshape(n, -1),
                                 times.view(np.uint8).reshape(n, -1)], axis=1)
        out = np.tile(self.template, (n, 1))
        out.view(self._destination)[:, 0] = source.view(self._source)[:, 0]
        return out


def _joined(parts: Sequence[np.ndarray]) -> np.ndarray:
    return np.concatenate(parts) if parts else np.zeros(0, dtype=np.int64)


def _views(places: dict[str, np.ndarray], width: int) -> tuple[np.dtype, np.dtype]:
    """
    Return the structured dtypes of a row's variable fields and of their packed source.

    ``places`` are the byte offsets in a row of the float64 values, the float32
    values, the stamps and the uint64 times, in the order of the packed source
    (which :meth:`BlockEncoder.encode` fills in that order). Values next to each other
    in both are merged into one field of raw bytes (``V<n>``), so that the copy is a few
    hundred block moves per frame rather than one per value, and bytes are copied as
    they are (NaN payloads too).
    """
    offsets: list[int] = []
    sizes: list[int] = []
    for name, size in (('f8', 8), ('f4', 4), ('stamp', 8), ('time', 8)):
        for offset in places[name].tolist():
            if offsets and offsets[-1] + sizes[-1] == offset:
                sizes[-1] += size   # contiguous in the row as in the source: one run
            else:
                offsets.append(offset)
                sizes.append(size)
    # Runs of raw bytes: a cloud's thousands of floats are one field, copied as one block.
    formats = [f'V{size}' for size in sizes]
    names = [f'v{i}' for i in range(len(offsets))]
    destination = np.dtype({'names': names, 'formats': formats, 'offsets': offsets,
                            'itemsize': width})
    return destination, np.dtype({'names': names, 'formats': formats})
