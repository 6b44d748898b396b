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
What a killed recording leaves, read back: nothing that reached the disk as complete is lost.

Deterministic and in-process: a bag's files copied while the recorder is still
writing are what a SIGKILL at that moment leaves (every closed MCAP chunk and
SQLite commit is handed to the operating system at once); a complete bag cut at
byte offsets is what a power cut or a damaged copy leaves. Every assertion is
exact (no tolerance): the messages read back must be the complete bag's first
messages, topic by topic, with the same stamps and bytes, and exactly as many
as the closed chunks or commits hold.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import replace
import logging
from pathlib import Path
import shutil

from mcap.reader import make_reader
from mcap.records import Chunk, Message
from mcap.stream_reader import breakup_chunk, StreamReader
import pytest
from rosbags.highlevel import AnyReader
from ttb_sim.errors import BagError
from ttb_sim.io import bag as bag_module
from ttb_sim.io import block_storage
from ttb_sim.io.bag import BagRecorder
from ttb_sim.io.reader import read_bag
from ttb_sim.io.salvage import salvage, write_closed
from ttb_sim.io.topics import topic_table

from block_frames import frames, LAYOUT   # noqa: I100 - the helper next to this file

FRAMES = 420
pytestmark = pytest.mark.filterwarnings('ignore:overflow encountered in cast:RuntimeWarning')

Messages = dict[str, list[tuple[int, bytes]]]


def _by_topic(items) -> Messages:
    out: Messages = defaultdict(list)
    for topic, stamp, data in items:
        out[topic].append((stamp, bytes(data)))
    return dict(out)


def _read(path: Path) -> Messages:
    with AnyReader([path]) as reader:
        return _by_topic((c.topic, t, raw) for c, t, raw in reader.messages())


def _salvaged(file: Path) -> Messages:
    found = salvage(file)
    return _by_topic((c.topic, t, d) for c, t, d in found.messages())


def _assert_prefix(part: Messages, whole: Messages) -> int:
    """Each topic's messages are the first of the complete bag's; return how many in all."""
    assert set(part) <= set(whole)
    for topic, items in part.items():
        assert items == whole[topic][:len(items)], topic
    return sum(map(len, part.values()))


@pytest.fixture(scope='module')
def snapshots(tmp_path_factory) -> dict[str, tuple[Path, list[tuple[Path, int]]]]:
    """
    Per storage: the complete bag, and copies of its files taken while it was being written.

    Each copy comes with the number of messages its closed chunks (MCAP) or
    commits (SQLite 3) held at that moment, as the storage counted them.
    """
    root = tmp_path_factory.mktemp('salvage')
    out = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(bag_module, 'MAX_BLOCK_FRAMES', 13)   # many blocks, several chunks
        patch.setattr(block_storage, 'CHUNK_BYTES', 2 ** 17)
        for storage in ('mcap', 'sqlite3'):
            path = root / storage / 'bag'
            copies = []
            with BagRecorder(path, topic_table(LAYOUT), storage) as bag:
                for k, frame in enumerate(frames(FRAMES)):
                    bag.write(frame)
                    if k % 53 == 52:
                        copy = root / storage / f'killed{k}'
                        shutil.copytree(path, copy)
                        copies.append((copy, _durable(bag)))
            out[storage] = path, copies
    return out


def _durable(bag: BagRecorder) -> int:
    storage = bag._writer.storage
    written = sum(bag._writer.counts.values())
    if isinstance(storage, block_storage.McapBlockStorage):
        return written - sum(len(c) for c in storage.chunk.channels)
    assert isinstance(storage, block_storage.SqliteBlockStorage)
    return written - storage.uncommitted


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_kill_keeps_every_closed_chunk_or_commit(snapshots, storage, caplog):
    path, copies = snapshots[storage]
    whole = _read(path)
    counts = [durable for _, durable in copies]
    assert counts == sorted(counts) and counts[-1] > counts[0] > 0   # chunks were closed
    for copy, durable in copies:
        assert not (copy / 'metadata.yaml').exists()   # as a kill leaves it
        part = _salvaged(next(p for p in copy.iterdir() if p.suffix in ('.mcap', '.db3')))
        assert _assert_prefix(part, whole) == durable, copy.name
        with caplog.at_level(logging.WARNING, logger='ttb_sim.io.reader'):
            caplog.clear()
            arrays = read_bag(copy)      # the bag reader reads it directly, with a warning
        assert sum(len(a) for a in arrays.values()) == durable
        [warning] = [r.getMessage() for r in caplog.records]
        assert 'was not closed' in warning and f'{durable} messages' in warning
        assert '\n' not in warning and '`ttb-sim recover' in warning


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_the_original_is_left_as_it_was(snapshots, storage):
    _, copies = snapshots[storage]
    copy = copies[1][0]
    before = {p.name: p.read_bytes() for p in copy.iterdir()}
    read_bag(copy)
    salvage(next(p for p in copy.iterdir() if p.suffix in ('.mcap', '.db3')))
    assert {p.name: p.read_bytes() for p in copy.iterdir()} == before


@pytest.mark.parametrize('storage', ['mcap', 'sqlite3'])
def test_a_recovered_bag_is_closed_and_holds_the_same_messages(snapshots, storage, tmp_path):
    path, copies = snapshots[storage]
    copy, durable = copies[-1]
    found = salvage(next(p for p in copy.iterdir() if p.suffix in ('.mcap', '.db3')))
    assert not found.closed
    out = tmp_path / 'recovered'
    assert write_closed(found, out) == durable
    assert (out / 'metadata.yaml').is_file()
    recovered = _read(out)             # rosbags' own reader, with the fresh metadata.yaml
    assert _assert_prefix(recovered, _read(path)) == durable
    again = salvage(next(p for p in out.iterdir() if p.suffix in ('.mcap', '.db3')))
    assert again.closed and again.stop == ''


@pytest.fixture(scope='module')
def complete(tmp_path_factory) -> Path:
    """Write a complete MCAP bag of several 128 KiB chunks."""
    path = tmp_path_factory.mktemp('cut') / 'bag'
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(block_storage, 'CHUNK_BYTES', 2 ** 17)
        with BagRecorder(path, topic_table(LAYOUT), 'mcap') as bag:
            for frame in frames(FRAMES):
                bag.write(frame)
    return path


def _chunks(file: Path) -> list[tuple[int, int]]:
    """(end offset, messages) of every chunk: the summary's index, the chunks' own records."""
    with file.open('rb') as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    with file.open('rb') as stream:
        records = [r for r in StreamReader(stream, emit_chunks=True).records
                   if isinstance(r, Chunk)]
    counts = [sum(isinstance(r, Message) for r in breakup_chunk(c)) for c in records]
    assert len(counts) == len(summary.chunk_indexes)
    return [(c.chunk_start_offset + c.chunk_length, n)
            for c, n in zip(summary.chunk_indexes, counts)]


def test_a_cut_file_reads_up_to_the_last_complete_chunk(complete, tmp_path):
    """Cut at any byte: exactly the messages of the chunks that end before the cut."""
    source = complete / 'bag.mcap'
    data = source.read_bytes()
    whole = _read(complete)
    chunks = _chunks(source)
    assert len(chunks) > 3
    ends = [end for end, _ in chunks[:3] + chunks[-1:]]     # at a chunk's end, a byte short
    cuts = sorted({*ends, *(end - 1 for end in ends), len(data) - 1,
                   *(len(data) * k // 7 for k in range(1, 7))})
    for cut in cuts:
        folder = tmp_path / f'cut{cut}'
        folder.mkdir()
        (folder / 'bag.mcap').write_bytes(data[:cut])
        expected = sum(n for end, n in chunks if end <= cut)
        if expected == 0:
            with pytest.raises(BagError, match=r'did not finish .*and nothing to recover in '
                                               r'.*no message in a complete chunk'):
                read_bag(folder)
            continue
        assert _assert_prefix(_salvaged(folder / 'bag.mcap'), whole) == expected, cut
        if cut in ends:                 # the bag reader too (slower: it decodes)
            assert sum(len(a) for a in read_bag(folder).values()) == expected


def test_nothing_to_recover_is_one_line(tmp_path):
    for name, data in (('empty.mcap', b''), ('header.mcap', b'\x89MCAP0\r\n\x01\x03'),
                       ('noise.mcap', bytes(range(256)) * 4), ('noise.db3', b'x' * 5000)):
        folder = tmp_path / name.replace('.', '_')
        folder.mkdir()
        (folder / name).write_bytes(data)
        with pytest.raises(BagError) as info:
            read_bag(folder)
        assert '\n' not in str(info.value) and 'did not finish' in str(info.value), name


def test_a_lean_bag_closes_a_chunk_every_second_of_log_time(tmp_path):
    """Under 1 MiB a second: a chunk (so what a kill can lose) spans less than 1 s of stamps."""
    items = [replace(f, time=k * 0.01) for k, f in enumerate(frames(FRAMES))]   # 4.2 s
    path = tmp_path / 'lean'
    with BagRecorder(path, topic_table(LAYOUT), 'mcap') as bag:
        for frame in items:
            bag.write(frame)
    with (path / 'lean.mcap').open('rb') as stream:
        summary = make_reader(stream).get_summary()
    assert summary is not None
    spans = [(c.message_start_time, c.message_end_time) for c in summary.chunk_indexes]
    assert len(spans) == 5                       # 0-1, 1-2, 2-3, 3-4, 4-4.19 s
    assert all(end - start < 10 ** 9 for start, end in spans)
    assert [start // 10 ** 9 for start, _ in spans] == [0, 1, 2, 3, 4]
    assert sum(map(len, _read(path).values())) == FRAMES * len(topic_table(LAYOUT))
