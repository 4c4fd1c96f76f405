"""Numeric fields of many CDR messages read at once, without decoding each message.

A perspective needs a few numbers from each of a million odometry messages; decoding every
message with rosbags costs ~7 us, most of it for fields nobody asked for (two 36-float
covariance matrices per odometry message). In CDR a field's byte offset depends only on the
lengths of the strings and sequences before it, so when those lengths are the same as in a
topic's first message (they are: frame ids do not change), every wanted field sits at the same
offset and a whole column is one numpy view.

:class:`Layout` finds the offsets in a first message and checks, per message, that the lengths
it depends on are the same; :func:`columns` then reads the columns. Messages that do not fit
are decoded the ordinary way by the caller.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from rosbags.interfaces import Nodetype

if TYPE_CHECKING:
    from rosbags.interfaces.typing import BaseDesc, NameDesc, Typesdict

    from robotale.eventlog.messages import Batch

#: CDR primitive sizes; every primitive is aligned to its size, counted from the payload start.
_SIZES = {
    "bool": 1, "byte": 1, "char": 1, "int8": 1, "uint8": 1, "int16": 2, "uint16": 2,
    "int32": 4, "uint32": 4, "int64": 8, "uint64": 8, "float32": 4, "float64": 8,
}  # fmt: skip
_HEADER = 4  # encapsulation: 0x00 0x01 for little-endian CDR
_LITTLE_ENDIAN = b"\x00\x01"


class _Unsupported(Exception):
    """A message this module does not read (big-endian, wide strings ...)."""


@dataclass(frozen=True)
class Layout:
    """Where the wanted fields are in messages shaped like a first one."""

    header: bytes
    checks: tuple[tuple[int, bytes], ...]  # (offset, the length bytes found there)
    fields: tuple[tuple[int, str], ...]  # (offset, primitive type), in the order asked
    end: int  # bytes a message needs to hold every wanted field

    @classmethod
    def of(
        cls, raw: bytes, msgtype: str, paths: Sequence[str], fielddefs: Typesdict
    ) -> Layout | None:
        """The layout of ``paths`` in ``raw``, or ``None`` if they cannot be read in bulk."""
        if raw[:2] != _LITTLE_ENDIAN:
            return None
        walker = _Walker(raw, fielddefs, set(paths))
        try:
            walker.walk(msgtype, _HEADER, "")
        except (_Unsupported, struct.error, KeyError, TypeError, ValueError):
            return None
        if set(walker.found) != set(paths):
            return None
        fields = tuple(walker.found[p] for p in paths)
        end = max((offset + _SIZES[kind] for offset, kind in fields), default=_HEADER)
        if end > len(raw):
            return None
        return cls(raw[:_HEADER], tuple(walker.checks), fields, end)

    def fits(self, raw: bytes) -> bool:
        """Whether the wanted fields of ``raw`` are where this layout says."""
        if len(raw) < self.end or raw[:_HEADER] != self.header:
            return False
        for offset, length in self.checks:  # noqa: SIM110 -- a plain loop: it runs per message
            if raw[offset : offset + 4] != length:
                return False
        return True

    def fitting(self, batch: Batch) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`fits` for every message of a :class:`~robotale.eventlog.messages.Batch` at
        once: the rows that fit, and their first :attr:`end` bytes (what :func:`columns`
        reads), one message per row."""
        rows = np.flatnonzero(batch.lengths >= self.end)
        heads = batch.heads(rows, self.end)
        fits = (heads[:, :_HEADER] == np.frombuffer(self.header, dtype=np.uint8)).all(axis=1)
        for offset, length in self.checks:
            found = heads[:, offset : offset + 4] == np.frombuffer(length, dtype=np.uint8)
            fits &= found.all(axis=1)
        return rows[fits], heads[fits]


def columns(layout: Layout, data: bytes | bytearray | np.ndarray) -> list[np.ndarray]:
    """One array per wanted field from messages that fit ``layout``, each cut to
    ``layout.end`` bytes and laid end to end in ``data`` (or one per row of a matrix)."""
    matrix = np.frombuffer(data, dtype=np.uint8) if not isinstance(data, np.ndarray) else data
    matrix = matrix.reshape(-1, layout.end)
    arrays = []
    for offset, kind in layout.fields:
        size = _SIZES[kind]
        dtype = np.dtype(_numpy_type(kind)).newbyteorder("<")
        values = np.ascontiguousarray(matrix[:, offset : offset + size]).view(dtype)[:, 0]
        arrays.append(
            values.astype(bool) if kind == "bool" else values.astype(dtype.newbyteorder("="))
        )
    return arrays


def _numpy_type(kind: str) -> str:
    return {"bool": "uint8", "byte": "uint8", "char": "uint8"}.get(kind, kind)


class _Walker:
    """Walks one message's bytes as CDR, noting wanted offsets and the lengths before them."""

    def __init__(self, raw: bytes, fielddefs: Typesdict, wanted: set[str]) -> None:
        self.raw, self.fielddefs, self.wanted = raw, fielddefs, wanted
        self.found: dict[str, tuple[int, str]] = {}
        self.checks: list[tuple[int, bytes]] = []

    def walk(self, msgtype: str, pos: int, prefix: str) -> int:
        for name, desc in self.fielddefs[msgtype][1]:
            if len(self.found) == len(self.wanted):
                return pos  # what follows the last wanted field does not matter
            path = prefix + name
            if desc[0] == Nodetype.BASE:
                pos = self._base(desc[1][0], pos, path)
            elif desc[0] == Nodetype.NAME:
                pos = self.walk(desc[1], pos, f"{path}.")
            elif desc[0] == Nodetype.ARRAY:
                pos = self._items(desc[1][0], desc[1][1], pos)
            elif desc[0] == Nodetype.SEQUENCE:
                pos = self._items(desc[1][0], self._length(pos), _align(pos, 4) + 4)
            else:
                raise _Unsupported(desc[0])
        return pos

    def _base(self, kind: str, pos: int, path: str | None) -> int:
        if kind == "string":
            return _align(pos, 4) + 4 + self._length(pos)
        if kind not in _SIZES:
            raise _Unsupported(kind)
        pos = _align(pos, _SIZES[kind])
        if path in self.wanted:
            self.found[path] = (pos, kind)
        return pos + _SIZES[kind]

    def _items(self, desc: BaseDesc | NameDesc, count: int, pos: int) -> int:
        if desc[0] == Nodetype.BASE and desc[1][0] in _SIZES:
            size = _SIZES[desc[1][0]]
            return _align(pos, size) + count * size if count else pos
        for _ in range(count):
            pos = (
                self._base(desc[1][0], pos, None)
                if desc[0] == Nodetype.BASE
                else self.walk(desc[1], pos, "\0")
            )
        return pos

    def _length(self, pos: int) -> int:
        """A string's or sequence's length, which later offsets depend on."""
        pos = _align(pos, 4)
        length: int = struct.unpack_from("<I", self.raw, pos)[0]
        self.checks.append((pos, self.raw[pos : pos + 4]))
        return length


def _align(pos: int, size: int) -> int:
    """``pos`` rounded up to a multiple of ``size``, counted from the end of the header."""
    return _HEADER + (pos - _HEADER + size - 1) // size * size
