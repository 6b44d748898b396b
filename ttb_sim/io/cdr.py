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
CDR messages: the ROS 2 Jazzy type store and the decoding of raw messages by their layout.

:func:`typestore` is the rosbags type store the recorder serialises with and the
reader deserialises with.  :func:`groups` splits the raw messages of one topic
into groups that share one little-endian CDR layout (:class:`CdrLayout`: the
byte offset of every primitive, from the type definitions of the store), so that
each field of a group is one strided column of a ``(messages, bytes)`` array;
a message without such a layout (another layout, big-endian CDR, exotic types)
is a group of one, read from rosbags' own deserialisation with the same result.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np
from rosbags.typesys import get_typestore, Stores
from rosbags.typesys.store import Nodetype


_PRIMITIVES = {'bool': '<u1', 'byte': '<u1', 'char': '<u1', 'int8': '<i1', 'uint8': '<u1',
               'int16': '<i2', 'uint16': '<u2', 'int32': '<i4', 'uint32': '<u4',
               'int64': '<i8', 'uint64': '<u8', 'float32': '<f4', 'float64': '<f8'}
"""ROS primitive type -> little-endian numpy dtype."""


def typestore() -> Any:
    """Return the rosbags type store of ROS 2 Jazzy."""
    return get_typestore(Stores.ROS2_JAZZY)


class NoLayout(Exception):
    """The message cannot be decoded by layout (the per-message path takes it)."""


@dataclass(frozen=True)
class _Leaf:
    """A primitive value or a block of primitives at a fixed byte offset."""

    offset: int
    dtype: str
    count: int | None   # None: one scalar; else the number of elements


class CdrLayout:
    """
    Byte offsets of every primitive of one little-endian CDR message.

    ``prefixes`` are the offsets of the uint32 lengths of strings and
    sequences; messages of the same size that agree there share the layout.
    """

    def __init__(self, store: Any, msgtype: str, data: bytes) -> None:
        if len(data) < 4 or data[1] != 1:   # encapsulation: CDR little-endian only
            raise NoLayout
        self._defs = store.fielddefs
        self._data = data
        self.pos = 4
        self.leaves: dict[str, _Leaf] = {}
        self.prefixes: list[int] = []
        self._message(msgtype, '')
        if not 0 <= len(data) - self.pos < 4:
            raise NoLayout

    def _align(self, size: int) -> None:
        self.pos += -(self.pos - 4) % size

    def _uint32(self) -> int:
        self._align(4)
        if self.pos + 4 > len(self._data):
            raise NoLayout
        self.prefixes.append(self.pos)
        value = int.from_bytes(self._data[self.pos:self.pos + 4], 'little')
        self.pos += 4
        return value

    def _message(self, msgtype: str, prefix: str) -> None:
        for name, (nodetype, desc) in self._defs[msgtype][1]:
            self._node(nodetype, desc, prefix + name)

    def _node(self, nodetype: int, desc: Any, path: str) -> None:
        if nodetype == Nodetype.BASE:
            self._base(desc[0], path)
        elif nodetype == Nodetype.NAME:
            self._message(desc, path + '.')
        elif nodetype == Nodetype.ARRAY:
            self._elements(desc[0], desc[1], path)
        else:
            self._elements(desc[0], self._uint32(), path)

    def _elements(self, sub: tuple[int, Any], count: int, path: str) -> None:
        nodetype, desc = sub
        if nodetype == Nodetype.BASE and desc[0] in _PRIMITIVES:
            dtype = _PRIMITIVES[desc[0]]
            size = int(dtype[2])
            if count:
                self._align(size)
            self.leaves[path] = _Leaf(self.pos, dtype, count)
            self.pos += size * count
        else:
            for i in range(count):
                self._node(nodetype, desc, f'{path}[{i}]')
        if self.pos > len(self._data):
            raise NoLayout

    def _base(self, typename: str, path: str) -> None:
        if typename == 'string':
            length = self._uint32()   # (not `pos += ...`: that reads pos before the call)
            self.pos += length
        elif typename in _PRIMITIVES:
            dtype = _PRIMITIVES[typename]
            self._align(int(dtype[2]))
            self.leaves[path] = _Leaf(self.pos, dtype, None)
            self.pos += int(dtype[2])
        else:   # wstring and other exotic types
            raise NoLayout


Getter = Callable[[str], np.ndarray]
"""Message path -> values of a group of messages: (n,) for a scalar, (n, k) for a block."""


def _block_getter(layout: CdrLayout, block: np.ndarray) -> Getter:
    """Read paths from a (messages, bytes) array that shares one layout."""
    def get(path: str) -> np.ndarray:
        leaf = layout.leaves[path]
        size = int(leaf.dtype[2])
        count = 1 if leaf.count is None else leaf.count
        columns = np.ascontiguousarray(block[:, leaf.offset:leaf.offset + size * count])
        values = columns.view(leaf.dtype)
        return values[:, 0] if leaf.count is None else values
    return get


def _message_getter(msg: Any) -> Getter:
    """Read paths from one deserialised message (as a group of one)."""
    def get(path: str) -> np.ndarray:
        value = msg
        for part in path.split('.'):
            value = getattr(value, part)
        return np.asarray(value)[None, ...]
    return get


@dataclass(frozen=True)
class Group:
    """Messages of one topic read the same way: their indices, a getter, one of them."""

    index: np.ndarray
    get: Getter
    sample: Callable[[], Any]   # the first message deserialised (for metadata)


def groups(store: Any, msgtype: str, raws: Sequence[bytes]) -> list[Group]:
    """Split a topic's messages into groups of one layout (plus single messages)."""
    by_size: dict[int, list[int]] = defaultdict(list)
    for i, data in enumerate(raws):
        by_size[len(data)].append(i)
    out: list[Group] = []
    pending = [np.asarray(v, dtype=np.int64) for v in by_size.values()]
    while pending:
        index = pending.pop()
        first = raws[int(index[0])]
        sample = _deserializer(store, first, msgtype)
        try:
            layout = CdrLayout(store, msgtype, first)
        except NoLayout:
            out.append(Group(index[:1], _message_getter(sample()), sample))
            if len(index) > 1:
                pending.append(index[1:])
            continue
        block = np.frombuffer(b''.join(raws[int(i)] for i in index),
                              dtype=np.uint8).reshape(len(index), len(first))
        same = np.ones(len(index), dtype=bool)
        for p in layout.prefixes:
            same &= np.all(block[:, p:p + 4] == block[0, p:p + 4], axis=1)
        same &= block[:, 1] == 1
        out.append(Group(index[same], _block_getter(layout, block[same]), sample))
        if not same.all():
            pending.append(index[~same])
    return out


def _deserializer(store: Any, data: bytes, msgtype: str) -> Callable[[], Any]:
    def sample() -> Any:
        return store.deserialize_cdr(data, msgtype)
    return sample
