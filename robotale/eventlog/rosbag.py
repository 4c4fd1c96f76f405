"""rosbag2 recordings as tables: one pandas DataFrame per topic.

A recording is read with ``rosbags`` (sqlite3 or MCAP storage, any ROS 2 distribution) without a
ROS installation. Message types come, in this order of precedence, from ``.msg`` / ``.idl`` files
the user names, from the definitions the bag carries (Iron and later embed them), from the ROS 2
distribution the user names or the bag was recorded with (Humble when neither says), and
robotale's own ``robotale_msgs/msg/Tag``.

Bags robotale did not write are read defensively: a stored definition that cannot be parsed
only matters for the topics asked for (a service-event topic nobody reads does not stop the
preparation); messages are read from the storage files by topic and type, so a metadata.yaml
whose QoS differs from its storage's does not hide them; and each topic's first message is
checked against its definition, so a wrong stored definition is named instead of trusted.

What each type is, :mod:`robotale.eventlog.typesys` resolves; this module reads the storage.

Every table has a ``time`` column (tz-aware UTC): the message's own stamp (``header.stamp`` or a
top-level ``stamp``) when it has a non-zero one, else the time the bag recorded it. The other
columns are the message fields asked for, by dotted path (``pose.pose.position.x``).
"""

from __future__ import annotations

import contextlib
import struct
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any

import apsw  # rosbags' SQLite binding: a damaged database raises its errors
import numpy as np
import pandas as pd
from rosbags.interfaces import Connection
from rosbags.rosbag2 import Reader, ReaderError
from rosbags.serde import SerdeError
from rosbags.typesys.store import Typestore
from tqdm import tqdm

from robotale.errors import InputError
from robotale.eventlog.bagfiles import RECORDED, TIME, is_bag, without_metadata
from robotale.eventlog.cdrlayout import Layout, columns
from robotale.eventlog.interfaces import (
    definition_file,
    message_types,
    normalized,
)
from robotale.eventlog.messages import Batch, MalformedMcap, decompressed, gathered, mcap_batches
from robotale.eventlog.typesys import (
    all_fields,
    bag_definitions,
    check_distro,
    field_type,
    missing_type,
    release_of,
    scalar_fields,
    stamp_path,
    typestore_for,
)

if TYPE_CHECKING:
    from rosbags.interfaces.typing import Typesdict


@dataclass
class Bag:
    """An open rosbag2 directory; use as a context manager.

    ``distro`` names the ROS 2 distribution whose standard types complete what the bag does not
    define (default: the one the bag names, else Humble).

    ``topics`` maps each topic to its message type; :meth:`tables` decodes the chosen topics'
    fields in one pass over the recording.
    """

    path: Path
    extra_types: Typesdict = field(default_factory=dict)
    #: the ROS 2 distribution whose standard types fill in what the bag does not define
    distro: str | None = None
    _reader: Reader | None = field(default=None, init=False, repr=False)
    _typestore: Typestore | None = field(default=None, init=False, repr=False)
    _definitions: Typesdict = field(default_factory=dict, init=False, repr=False)
    _topics: dict[str, str] = field(default_factory=dict, init=False, repr=False)
    #: topic -> why its stored definition cannot be used (reported only if it is read)
    unparsed: dict[str, str] = field(default_factory=dict, init=False, repr=False)
    #: topics whose QoS in metadata.yaml differs from their storage's (read from the storage)
    qos_mismatch: list[str] = field(default_factory=list, init=False, repr=False)
    #: the distribution whose standard and shipped types fill in what the bag does not define
    release: str = field(default="", init=False, repr=False)

    def __enter__(self) -> Bag:
        if not self.path.exists():
            raise InputError(f"{self.path} does not exist.")
        if not is_bag(self.path):
            raise InputError(without_metadata(self.path))
        try:
            reader = Reader(self.path)
            reader.open()
        # MemoryError, OverflowError: a damaged MCAP index names a record of exabytes, which
        # rosbags tries to read; apsw.Error: a damaged SQLite file.
        except (
            ReaderError,
            OSError,
            KeyError,
            ValueError,
            MemoryError,
            OverflowError,
            apsw.Error,
        ) as error:
            reason = " ".join(str(error).split()) or "a damaged index names an impossible size"
            raise InputError(f"{self.path} is not a readable rosbag2 directory: {reason}") from None
        self._reader = reader
        self._topics = {n: normalized(i.msgtype or "") for n, i in sorted(reader.topics.items())}
        try:
            self.release = release_of(self.distro or reader.ros_distro)
            self._definitions = bag_definitions(
                reader, self.extra_types, self.release, self.unparsed
            )
            roots = {
                normalized(c.msgtype) for c in reader.connections if c.topic not in self.unparsed
            }
            self._typestore = typestore_for(self._definitions, roots, self.path)
            self.qos_mismatch = _qos_mismatches(reader)
        except BaseException:
            self.__exit__()
            raise
        return self

    def __exit__(self, *exc: object) -> None:
        if self._reader is not None:
            self._reader.close()
            self._reader = None

    @property
    def reader(self) -> Reader:
        if self._reader is None:
            raise RuntimeError("the bag is not open; use it in a with statement")
        return self._reader

    @property
    def typestore(self) -> Typestore:
        """The types of the bag's topics (those with every definition they need)."""
        if self._typestore is None:
            raise RuntimeError("the bag is not open; use it in a with statement")
        return self._typestore

    @property
    def name(self) -> str:
        return self.path.name

    @property
    def topics(self) -> dict[str, str]:
        """Topic name -> message type, in the order of the topic names."""
        self.reader  # noqa: B018 -- raises when the bag is not open
        return self._topics

    def fields(self, topic: str) -> list[str]:
        """The dotted paths of every scalar field of a topic's message type (arrays left out)."""
        return scalar_fields(self._decodable(self.topics[topic], topic), self.typestore)

    def tables(
        self,
        columns: Mapping[str, Mapping[str, str]],
        *,
        bag_time: bool = False,
        recorded: bool = False,
        progress: tqdm | None = None,
    ) -> dict[str, pd.DataFrame]:
        """One table per topic: ``time`` plus ``columns[topic]`` (column name -> field path).

        ``bag_time`` uses the recording time instead of the message stamps; ``recorded`` adds
        the :data:`RECORDED` column. ``progress`` is a tqdm bar to advance by one per message
        read.
        """
        unknown = [topic for topic in columns if topic not in self.topics]
        if unknown:
            raise InputError(f"{self.path} has no topic {unknown[0]}.")
        connections = [c for c in self.reader.connections if c.topic in columns]
        rows = {topic: self._rows(topic, paths) for topic, paths in columns.items()}
        for topic, batch in self._batches(connections, progress):
            rows[topic].add(batch)
        tables = {}
        for topic, topic_rows in rows.items():
            table = topic_rows.table(list(columns[topic]), bag_time, recorded)
            msgtype = self.topics[topic]
            for column, path in columns[topic].items():
                if field_type(msgtype, path, self.typestore) == "float32":
                    table[column] = _shortest_float32(table[column])
            tables[topic] = table
        return tables

    def _rows(self, topic: str, paths: Mapping[str, str]) -> _TopicRows:
        msgtype = self._decodable(self.topics[topic], topic)
        field_paths, stamped = self._field_paths(topic, paths)
        decode, check = self._decoder(topic), self._checker(topic)
        return _TopicRows(msgtype, field_paths, stamped, self.typestore, decode, check)

    def _field_paths(self, topic: str, paths: Mapping[str, str]) -> tuple[list[str], bool]:
        """The field paths to read from a topic's messages, and whether they lead with a stamp."""
        msgtype = self._decodable(self.topics[topic], topic)
        known = set(all_fields(msgtype, self.typestore))
        for column, path in paths.items():
            if path not in known:
                raise InputError(
                    f"{self.path}: {topic} ({msgtype}) has no field {path!r} for column "
                    f"{column!r}; its fields are "
                    f"{', '.join(scalar_fields(msgtype, self.typestore))}."
                )
        stamp = stamp_path(msgtype, self.typestore)
        stamp_paths = [f"{stamp}.sec", f"{stamp}.nanosec"] if stamp else []
        return [*stamp_paths, *paths.values()], bool(stamp)

    def _decodable(self, msgtype: str, topic: str) -> str:
        if topic in self.unparsed:
            raise InputError(
                f"{self.path}: the definition of {msgtype} stored in the bag for {topic} cannot "
                f"be parsed ({self.unparsed[topic]}); give it with --msg "
                f"{definition_file(msgtype)}."
            )
        if msgtype not in self.typestore.fielddefs:
            missing = missing_type(self._definitions, msgtype) or msgtype
            part = "" if missing == msgtype else f", which {msgtype} contains,"
            file = definition_file(missing)
            raise InputError(
                f"{self.path}: cannot decode {topic}: the message type {missing}{part} is "
                f"defined neither in the bag nor among the {self.release.title()} types robotale "
                f"knows; give its definition with --msg {file} (a file at that path, or a "
                f"folder holding {file})."
            )
        return msgtype

    def _decoder(self, topic: str) -> Callable[[bytes], Any]:
        msgtype, deserialize = self.topics[topic], self.typestore.deserialize_cdr

        def decode(raw: bytes) -> Any:  # a message of a generated class
            try:
                return deserialize(raw, msgtype)
            except (SerdeError, struct.error, IndexError, ValueError, AssertionError) as error:
                reason = str(error).strip().rstrip(".") or type(error).__name__
                raise InputError(
                    f"{self.path}: a message on {topic} cannot be decoded as {msgtype} "
                    f"({reason}); the definition registered for it does not match the "
                    f"recording (give the right one with --msg {definition_file(msgtype)}, or "
                    "the bag's distribution with --distro)."
                ) from None

        return decode

    def _checker(self, topic: str) -> Callable[[bytes, Any], None]:
        """A check of a topic's first message against the definition it is decoded with.

        Decoding alone trusts too much: a definition shorter than the message (a stored
        ``uint8 level`` for a whole ``rcl_interfaces/msg/Log``) decodes without an error. The
        decoded message written back must take the bytes it was read from, up to CDR's final
        alignment padding.
        """
        msgtype, store = self.topics[topic], self.typestore

        def check(raw: bytes, message: Any) -> None:
            again = len(store.serialize_cdr(message, msgtype))
            if abs(len(raw) - again) > 3:  # CDR pads a message to a multiple of 4 bytes
                raise InputError(
                    f"{self.path}: the messages on {topic} do not match the definition of "
                    f"{msgtype} they are read with ({len(raw)} bytes, the definition accounts "
                    f"for {again}); give the right one with --msg {definition_file(msgtype)}, "
                    "or the bag's distribution with --distro."
                )

        return check

    def _batches(
        self, connections: list[Connection], progress: tqdm | None
    ) -> Iterator[tuple[str, Batch]]:
        """The messages of ``connections`` in batches, a storage file after another, and an
        error if a file's messages start before the previous file's end."""
        spans: dict[str, list[Any]] = {}  # file -> [first time, its topic, last time]
        try:
            for file, connection, batch in _storage_batches(self.reader, connections):
                if progress is not None:
                    progress.update(len(batch))
                first, last = int(batch.recorded[0]), int(batch.recorded[-1])
                span = spans.setdefault(file, [first, connection.topic, last])
                if first < span[0]:
                    span[0], span[1] = first, connection.topic
                span[2] = max(span[2], last)
                yield connection.topic, batch
        except ReaderError as error:
            raise InputError(f"{self.path} cannot be read: {error}") from None
        except MalformedMcap as error:
            raise InputError(f"{self.path} cannot be read: {error}.") from None
        except (apsw.Error, OverflowError, MemoryError) as error:  # damaged storage
            reason = " ".join(str(error).split()) or type(error).__name__
            raise InputError(
                f"{self.path} cannot be read: its storage is damaged ({reason})."
            ) from None
        latest: int | None = None
        for first, topic, end in spans.values():
            if latest is not None and first < latest:
                raise InputError(_out_of_order(self.reader, self.path, topic, first, latest))
            latest = end if latest is None else max(latest, end)


class _TopicRows:
    """The recording times and field values of one topic's messages, gathered batch by batch.

    Numeric fields are read in bulk from the raw bytes of every message that shares the first
    message's layout (:mod:`robotale.eventlog.cdrlayout`), checked for a whole batch at once;
    other messages, and other fields, are decoded one by one with rosbags.
    """

    def __init__(
        self,
        msgtype: str,
        paths: list[str],
        stamped: bool,
        typestore: Typestore,
        decode: Callable[[bytes], Any],
        check: Callable[[bytes, Any], None],
    ) -> None:
        self.msgtype, self.paths, self.stamped = msgtype, paths, stamped
        self.typestore, self.decode, self.check = typestore, decode, check
        self.extract = _extractor(paths)
        self.layout: Layout | None = None
        self.recorded: list[np.ndarray] = []
        self.count = 0
        self.bulk: list[np.ndarray] = []  # the fitting messages' first layout.end bytes
        self.bulk_at: list[int] = []
        self.one_by_one: list[tuple[Any, ...]] = []
        self.one_by_one_at: list[int] = []

    def add(self, batch: Batch) -> None:
        if not len(batch):
            return
        if not self.count:
            first = batch.message(0)
            self.check(first, self.decode(first))
            if self.paths:
                self.layout = self._checked_layout(first)
        positions = np.arange(self.count, self.count + len(batch))
        self.recorded.append(batch.recorded)
        self.count += len(batch)
        if not self.paths:
            return
        fits = np.zeros(0, dtype=np.int64)
        if self.layout is not None:
            fits, heads = self.layout.fitting(batch)
            self.bulk.append(heads)
            self.bulk_at.extend(positions[fits].tolist())
        rest = np.ones(len(batch), dtype=bool)
        rest[fits] = False
        for k in np.flatnonzero(rest).tolist():
            self.one_by_one.append(self.extract(self.decode(batch.message(k))))
            self.one_by_one_at.append(int(positions[k]))

    def _checked_layout(self, raw: bytes) -> Layout | None:
        """The first message's layout, if reading it in bulk gives what rosbags decodes."""
        layout = Layout.of(raw, self.msgtype, self.paths, self.typestore.fielddefs)
        if layout is None:
            return None
        bulk = [values[0].item() for values in columns(layout, raw[: layout.end])]
        decoded = self.extract(self.decode(raw))
        same = all(a == b or (a != a and b != b) for a, b in zip(bulk, decoded, strict=True))
        return layout if same else None

    def table(self, names: list[str], bag_time: bool, with_recorded: bool = False) -> pd.DataFrame:
        count = self.count
        recorded = np.concatenate(self.recorded) if self.recorded else np.zeros(0, np.int64)
        bulk = (
            columns(self.layout, np.concatenate(self.bulk))
            if self.bulk_at and self.layout is not None
            else None
        )
        values = {}
        for k, name in enumerate(["_sec", "_nanosec"][: 2 * self.stamped] + names):
            if not self.one_by_one_at:
                values[name] = bulk[k] if bulk is not None else np.empty(count, dtype=object)
                continue
            column = np.empty(count, dtype=object)
            if bulk is not None:
                column[self.bulk_at] = bulk[k]
            for position, row in zip(self.one_by_one_at, self.one_by_one, strict=True):
                column[position] = row[k]  # one at a time: a value may itself be an array
            values[name] = pd.Series(column).infer_objects().to_numpy()
        # batches come a storage chunk at a time; chunks of a file may overlap in time
        order = np.argsort(recorded, kind="stable")
        if (order != np.arange(count)).any():
            recorded = recorded[order]
            values = {name: column[order] for name, column in values.items()}
        table = _table(recorded, values, names, bag_time)
        if with_recorded:
            table[RECORDED] = recorded.astype(np.int64, copy=False)
        return table


def read_bag(
    path: Path,
    topics: Sequence[str] | None = None,
    *,
    msg_files: Sequence[Path] = (),
    bag_time: bool = False,
    distro: str | None = None,
) -> dict[str, pd.DataFrame]:
    """Every scalar field of every topic (or of ``topics``), one DataFrame per topic."""
    with Bag(Path(path), message_types(msg_files), check_distro(distro)) as bag:
        chosen = list(bag.topics) if topics is None else list(topics)
        columns = {topic: {f: f for f in bag.fields(topic)} for topic in chosen}
        return bag.tables(columns, bag_time=bag_time)


def _extractor(paths: list[str]) -> Callable[[Any], tuple[Any, ...]]:
    """A function from a message to the tuple of its values at ``paths``."""
    if not paths:
        return lambda message: ()
    get = attrgetter(*paths)
    return get if len(paths) > 1 else lambda message: (get(message),)


def _table(
    recorded: np.ndarray, values: dict[str, np.ndarray], names: list[str], bag_time: bool
) -> pd.DataFrame:
    nanos = recorded
    if "_sec" in values and not bag_time:
        stamps = values["_sec"].astype(np.int64) * 1_000_000_000 + values["_nanosec"].astype(
            np.int64
        )
        # real robots often leave stamps unset (zero): the recording time is the next best.
        nanos = np.where(stamps > 0, stamps, recorded)
    frame = pd.DataFrame({name: values[name] for name in names})
    frame.insert(0, TIME, pd.to_datetime(nanos, unit="ns", utc=True))
    return frame


def _out_of_order(reader: Reader, path: Path, topic: str, recorded: int, last: int) -> str:
    files = ", ".join(Path(f).name for f in _storage_files(reader)) or "its storage files"
    at, before = (pd.Timestamp(t, unit="ns", tz="UTC").isoformat() for t in (recorded, last))
    return (
        f"{path}: timestamps are out of order across its files ({files}): a message on {topic} "
        f"at {at} comes after one at {before}; the files overlap or are listed out of order in "
        "metadata.yaml."
    )


def _storage_files(reader: Reader) -> list[str]:
    with contextlib.suppress(AttributeError):
        return [str(storage.path) for storage in _storages(reader)]
    return []


def _qos_mismatches(reader: Reader) -> list[str]:
    """Topics whose QoS (or type hash) in metadata.yaml differs from what their storage says.

    rosbags pairs metadata and storage connections on those too, so it would read no message
    of such a topic; :func:`_storage_batches` pairs them on topic and type only.
    """
    storage_ext = {
        (c.topic, c.msgtype): (c.ext, c.digest)
        for storage in _storages(reader)
        for c in storage.connections
    }
    mismatched = set()
    for c in reader.connections:
        ext, digest = storage_ext.get((c.topic, c.msgtype), (c.ext, c.digest))
        if ext != c.ext or (digest and c.digest and digest != c.digest):
            mismatched.add(c.topic)
    return sorted(mismatched)


def _storages(reader: Reader) -> list[Any]:
    """The storage files of a directory reader (rosbags' own objects, not part of its typed
    interface), or none."""
    with contextlib.suppress(AttributeError):
        return list(getattr(reader.storage, "storages"))  # noqa: B009 -- untyped in rosbags
    return []


def _storage_batches(
    reader: Reader, connections: list[Connection]
) -> Iterator[tuple[str, Connection, Batch]]:
    """The messages of ``connections``, read from each storage file by topic and type, in
    batches: (file, connection, batch)."""
    storages = _storages(reader)
    if not storages:  # not a directory reader: rosbags' own pairing is all there is
        found = {c.id: c for c in connections}
        plain = ((c.id, t, raw) for c, t, raw in reader.messages(connections=connections))
        for key, batch in gathered(plain):
            yield "", found[key], batch
        return
    wanted = {(c.topic, c.msgtype): c for c in connections}
    compressed = reader.compression_mode == "message"
    for storage in storages:
        mine = {
            c.id: wanted[(c.topic, c.msgtype)]
            for c in storage.connections
            if (c.topic, c.msgtype) in wanted
        }
        if not mine:
            continue
        file = str(getattr(storage, "path", ""))
        for key, batch in _file_batches(storage, mine, compressed):
            yield file, mine[key], batch


def _file_batches(
    storage: Any, mine: Mapping[int, Connection], compressed: bool
) -> Iterator[tuple[int, Batch]]:
    """One storage file's batches: straight from an indexed MCAP file's chunks, else from
    rosbags' reading message by message."""
    path = getattr(storage, "path", None)
    if not compressed and isinstance(path, Path) and path.suffix == ".mcap":
        batches = mcap_batches(path, mine)
        if batches is not None:
            yield from batches
            return
    own = [c for c in storage.connections if c.id in mine]
    plain = (
        (c.id, t, decompressed(raw) if compressed else raw)
        for c, t, raw in storage.messages(own, None, None)
    )
    yield from gathered(plain)


def _shortest_float32(values: pd.Series) -> pd.Series:
    """float32 readings as the decimals they were written as (0.98, not 0.9800000190734863)."""
    as_text = values.to_numpy(np.float32).astype(str)
    return pd.Series(as_text.astype(np.float64), index=values.index)
