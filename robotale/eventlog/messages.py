"""A bag's raw messages in batches: many messages' bytes as slices of one buffer.

Reading a message at a time costs a few microseconds of Python each, more than the numbers a
perspective takes from it (:mod:`robotale.eventlog.cdrlayout`). A :class:`Batch` holds the
messages of one topic as offsets into one byte buffer, so layouts are checked and columns read
for all of them at once with numpy.

Indexed MCAP files (what rosbag2 and rosbags write) are read without going through every
record: the summary's chunk indexes say which chunks hold the channels asked for, and each
chunk's message indexes where their messages are, so the other channels' messages (camera
images, point clouds) are never copied, nor, in uncompressed chunks, even read from disk.
Other storage (sqlite3, MCAP files without indexes) is read with rosbags and gathered into
batches.
"""

from __future__ import annotations

import mmap
import zlib
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

import lz4.frame
import numpy as np
from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import ChunkIndex

try:  # the standard library's zstd from Python 3.14 on; rosbags' backport before
    from compression import zstd
except ImportError:
    from backports import zstd

_MESSAGE, _MESSAGE_INDEX = 0x05, 0x07
#: a message record: opcode, record length, channel id, sequence, log time, publish time
_MESSAGE_HEAD = 1 + 8 + 2 + 4 + 8 + 8
#: messages gathered per topic before they are handed on, when they are read one by one
GENERIC_BATCH = 20_000


class MalformedMcap(Exception):
    """An MCAP file whose index does not match its records."""


@dataclass(frozen=True)
class Batch:
    """Messages of one topic: recording times (ns) and their bytes, ``data[start:start+length]``."""

    recorded: np.ndarray  # int64
    data: np.ndarray  # uint8
    starts: np.ndarray  # int64
    lengths: np.ndarray  # int64

    def __len__(self) -> int:
        return len(self.recorded)

    @classmethod
    def of(cls, recorded: Iterable[int], raws: list[bytes]) -> Batch:
        """A batch of messages read one by one."""
        lengths = np.fromiter(map(len, raws), dtype=np.int64, count=len(raws))
        starts = np.zeros(len(raws), dtype=np.int64)
        np.cumsum(lengths[:-1], out=starts[1:])
        data = np.frombuffer(b"".join(raws), dtype=np.uint8)
        return cls(np.fromiter(recorded, dtype=np.int64, count=len(raws)), data, starts, lengths)

    def message(self, k: int) -> bytes:
        start = int(self.starts[k])
        return self.data[start : start + int(self.lengths[k])].tobytes()

    def heads(self, rows: np.ndarray, width: int) -> np.ndarray:
        """The first ``width`` bytes of the messages ``rows`` (each at least that long), one
        message per row."""
        return self.data[self.starts[rows, None] + np.arange(width)]


def mcap_batches(path: Path, channels: Iterable[int]) -> Iterator[tuple[int, Batch]] | None:
    """The messages of ``channels`` of an indexed MCAP file, a batch per channel and chunk,
    each in recording order; ``None`` if the file has no chunk and message indexes."""
    channels = set(channels)
    with path.open("rb") as file:
        try:
            summary = make_reader(file).get_summary()
        except (McapError, ValueError, EOFError, KeyError):
            return None
    chunks = summary.chunk_indexes if summary is not None else []
    if not chunks or any(not chunk.message_index_offsets for chunk in chunks):
        return None
    return _indexed(path, chunks, channels)


def _indexed(
    path: Path, chunks: list[ChunkIndex], channels: set[int]
) -> Iterator[tuple[int, Batch]]:
    with path.open("rb") as file:
        # unmapped when no batch views it any more (closing it here would break those)
        whole = np.frombuffer(mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ), np.uint8)
    for chunk in sorted(chunks, key=lambda c: (c.message_start_time, c.chunk_start_offset)):
        wanted = [c for c in chunk.message_index_offsets if c in channels]
        if wanted:
            records = _records(whole, chunk)
            for channel in wanted:
                at = chunk.message_index_offsets[channel]
                yield channel, _batch(records, _message_offsets(whole, at, channel), channel)


def _records(whole: np.ndarray, chunk: ChunkIndex) -> np.ndarray:
    """A chunk's records, uncompressed: a view of the file when they are stored so."""
    start = chunk.chunk_start_offset + 1 + 8 + 8 + 8 + 8 + 4 + 4 + len(chunk.compression) + 8
    stored = whole[start : start + chunk.compressed_size]
    if len(stored) != chunk.compressed_size:
        raise MalformedMcap(f"the chunk at byte {chunk.chunk_start_offset} is cut short")
    if not chunk.compression:
        return stored
    crc_at = chunk.chunk_start_offset + 1 + 8 + 8 + 8 + 8
    crc = int(whole[crc_at : crc_at + 4].view("<u4")[0])
    records = _decompress(chunk.compression, stored.tobytes())
    if len(records) != chunk.uncompressed_size or (crc and zlib.crc32(records) != crc):
        raise MalformedMcap(f"the chunk at byte {chunk.chunk_start_offset} is corrupt")
    return np.frombuffer(records, dtype=np.uint8)


def decompressed(raw: bytes) -> bytes:
    """A message of a bag whose messages rosbag2 compressed one by one (zstd), uncompressed."""
    return bytes(zstd.decompress(raw))


def _decompress(compression: str, data: bytes) -> bytes:
    if compression == "zstd":
        return bytes(zstd.decompress(data))
    if compression == "lz4":
        return bytes(lz4.frame.decompress(data))
    raise MalformedMcap(f"its chunks are compressed with {compression!r}, which is not supported")


def _message_offsets(whole: np.ndarray, at: int, channel: int) -> np.ndarray:
    """Where a channel's messages are in its chunk's records, from its message index."""
    head = whole[at : at + 1 + 8 + 2 + 4]
    if len(head) < 15 or head[0] != _MESSAGE_INDEX or int(head[9:11].view("<u2")[0]) != channel:
        raise MalformedMcap(f"no message index of channel {channel} at byte {at}")
    size = int(head[11:15].view("<u4")[0])
    entries = whole[at + 15 : at + 15 + size]
    if len(entries) != size or size % 16:
        raise MalformedMcap(f"the message index of channel {channel} at byte {at} is cut short")
    return entries.view("<u8").reshape(-1, 2)[:, 1].astype(np.int64)


def _batch(records: np.ndarray, offsets: np.ndarray, channel: int) -> Batch:
    """The messages at ``offsets``, checked to be ``channel``'s, in recording order (stably:
    messages of one time keep the order they were written in)."""
    offsets = np.sort(offsets)
    if len(offsets) and (offsets[0] < 0 or offsets[-1] + _MESSAGE_HEAD > len(records)):
        raise MalformedMcap(f"a message index of channel {channel} points outside its chunk")
    heads = records[offsets[:, None] + np.arange(_MESSAGE_HEAD)]
    lengths = heads[:, 1:9].copy().view("<u8")[:, 0].astype(np.int64) - (_MESSAGE_HEAD - 9)
    if (
        (heads[:, 0] != _MESSAGE).any()
        or (heads[:, 9:11].copy().view("<u2")[:, 0] != channel).any()
        or (lengths < 0).any()
        or (offsets + _MESSAGE_HEAD + lengths > len(records)).any()
    ):
        raise MalformedMcap(f"the message index of channel {channel} does not match its chunk")
    recorded = heads[:, 15:23].copy().view("<u8")[:, 0].astype(np.int64)
    order = np.argsort(recorded, kind="stable")
    return Batch(recorded[order], records, (offsets + _MESSAGE_HEAD)[order], lengths[order])


def gathered(
    messages: Iterable[tuple[int, int, bytes]], size: int = GENERIC_BATCH
) -> Iterator[tuple[int, Batch]]:
    """Batches of (key, recorded, raw) messages read one by one, per key, each at most ``size``
    long, in the order read."""
    pending: dict[int, tuple[list[int], list[bytes]]] = {}
    for key, recorded, raw in messages:
        times, raws = pending.setdefault(key, ([], []))
        times.append(recorded)
        raws.append(raw)
        if len(raws) >= size:
            yield key, Batch.of(times, raws)
            del pending[key]
    for key, (times, raws) in pending.items():
        yield key, Batch.of(times, raws)
