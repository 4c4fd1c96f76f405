"""rosbag2 recordings as tables: one pandas DataFrame per topic.

A recording is read with ``rosbags`` (sqlite3 or MCAP storage, any ROS 2 distribution) without a
ROS installation. Message types come, in this order of precedence, from the definitions the bag
carries (Iron and later embed them), from ``.msg`` / ``.idl`` files the user names, from the ROS 2
distribution the bag was recorded with (Humble when the bag does not say), and robotale's own
``robotale_msgs/msg/Tag``.

Every table has a ``time`` column (tz-aware UTC): the message's own stamp (``header.stamp`` or a
top-level ``stamp``) when it has a non-zero one, else the time the bag recorded it. The other
columns are the message fields asked for, by dotted path (``pose.pose.position.x``).
"""

from __future__ import annotations

import contextlib
import functools
import struct
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from operator import attrgetter
from pathlib import Path

import numpy as np
import pandas as pd
from rosbags.interfaces import Connection, MessageDefinitionFormat
from rosbags.rosbag2 import Reader, ReaderError
from rosbags.serde import SerdeError
from rosbags.typesys import (
    Stores,
    TypesysError,
    get_types_from_idl,
    get_types_from_msg,
    get_typestore,
)
from rosbags.typesys.store import Typestore

from robotale.errors import InputError
from robotale.eventlog.cdrlayout import Layout, columns
from robotale.fame_runtime.tags import TAG_MSGDEF, TAG_TYPE

TIME = "time"
HEADER_TYPE = "std_msgs/msg/Header"
TIME_TYPE = "builtin_interfaces/msg/Time"

# rosbags' field descriptors are (nodetype, detail); NAME is a nested message type.
_BASE, _NAME, _ARRAY, _SEQUENCE = 1, 2, 3, 4


def is_bag(path: Path) -> bool:
    """Whether ``path`` is a rosbag2 directory (it has a ``metadata.yaml``)."""
    return path.is_dir() and (path / "metadata.yaml").is_file()


def message_types(paths: Sequence[Path]) -> dict:
    """Type definitions from ``.msg`` / ``.idl`` files, or folders holding them.

    A ``.msg`` file's type is named by where it lives, as in a ROS package:
    ``my_pkg/msg/Event.msg`` defines ``my_pkg/msg/Event``.
    """
    typs: dict = {}
    for path in paths:
        files = (
            sorted(path.rglob("*.msg")) + sorted(path.rglob("*.idl")) if path.is_dir() else [path]
        )
        if not files:
            raise InputError(f"{path} holds no .msg or .idl files.")
        for file in files:
            typs.update(_types_from_file(file))
    return typs


def _types_from_file(file: Path) -> dict:
    if not file.is_file():
        raise InputError(f"Message definition {file} does not exist.")
    try:
        text = file.read_text(encoding="utf-8")
        if file.suffix == ".idl":
            return get_types_from_idl(text)
        if file.suffix != ".msg" or file.parent.name != "msg":
            raise InputError(
                f"Cannot tell the type name of {file}: put it at <package>/msg/<Type>.msg."
            )
        return get_types_from_msg(text, f"{file.parent.parent.name}/msg/{file.stem}")
    except (TypesysError, UnicodeDecodeError) as error:
        reason = " ".join(str(error).split())
        raise InputError(f"Message definition {file} cannot be parsed: {reason}") from None


@dataclass
class Bag:
    """An open rosbag2 directory; use as a context manager.

    ``topics`` maps each topic to its message type; :meth:`tables` decodes the chosen topics'
    fields in one pass over the recording.
    """

    path: Path
    extra_types: Mapping = field(default_factory=dict)
    _reader: Reader | None = field(default=None, init=False, repr=False)
    typestore: Typestore | None = field(default=None, init=False, repr=False)
    _definitions: Mapping = field(default_factory=dict, init=False, repr=False)
    _topics: dict[str, str] = field(default_factory=dict, init=False, repr=False)

    def __enter__(self) -> Bag:
        if not self.path.exists():
            raise InputError(f"{self.path} does not exist.")
        if not is_bag(self.path):
            raise InputError(f"{self.path} is not a rosbag2 directory (it has no metadata.yaml).")
        try:
            reader = Reader(self.path)
            reader.open()
        except (ReaderError, OSError, KeyError, ValueError) as error:
            reason = " ".join(str(error).split())
            raise InputError(f"{self.path} is not a readable rosbag2 directory: {reason}") from None
        self._reader = reader
        self._topics = {n: i.msgtype or "" for n, i in sorted(reader.topics.items())}
        try:
            self._definitions = _definitions(reader, self.extra_types, self.path)
            roots = {c.msgtype for c in reader.connections}
            self.typestore = _typestore(self._definitions, roots, self.path)
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
        progress=None,
    ) -> dict[str, pd.DataFrame]:
        """One table per topic: ``time`` plus ``columns[topic]`` (column name -> field path).

        ``bag_time`` uses the recording time instead of the message stamps. ``progress`` is a
        tqdm bar to advance by one per message read.
        """
        unknown = [topic for topic in columns if topic not in self.topics]
        if unknown:
            raise InputError(f"{self.path} has no topic {unknown[0]}.")
        connections = [c for c in self.reader.connections if c.topic in columns]
        rows = {topic: self._rows(topic, paths) for topic, paths in columns.items()}
        for topic, recorded, raw in self._raw_messages(connections, progress):
            rows[topic].add(recorded, raw)
        tables = {}
        for topic, topic_rows in rows.items():
            table = topic_rows.table(list(columns[topic]), bag_time)
            msgtype = self.topics[topic]
            for column, path in columns[topic].items():
                if field_type(msgtype, path, self.typestore) == "float32":
                    table[column] = _shortest_float32(table[column])
            tables[topic] = table
        return tables

    def _rows(self, topic: str, paths: Mapping[str, str]) -> _TopicRows:
        msgtype = self._decodable(self.topics[topic], topic)
        field_paths, stamped = self._field_paths(topic, paths)
        return _TopicRows(msgtype, field_paths, stamped, self.typestore, self._decoder(topic))

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
        if msgtype not in self.typestore.fielddefs:
            missing = _missing(self._definitions, msgtype) or msgtype
            package, _, name = missing.rpartition("/msg/")
            part = "" if missing == msgtype else f", which {msgtype} contains,"
            raise InputError(
                f"{self.path}: cannot decode {topic}: the message type {missing}{part} is not "
                f"defined in the bag; register it with --msg {package or 'my_pkg'}/msg/{name}.msg "
                "(or a folder of .msg files)."
            )
        return msgtype

    def _decoder(self, topic: str):
        msgtype, deserialize = self.topics[topic], self.typestore.deserialize_cdr

        def decode(raw: bytes) -> object:
            try:
                return deserialize(raw, msgtype)
            except (SerdeError, struct.error, IndexError, ValueError, AssertionError) as error:
                raise InputError(
                    f"{self.path}: a message on {topic} cannot be decoded as {msgtype} "
                    f"({error or type(error).__name__}); the definition registered for it does "
                    "not match the recording."
                ) from None

        return decode

    def _raw_messages(
        self, connections: list[Connection], progress
    ) -> Iterator[tuple[str, int, bytes]]:
        last = -1
        try:
            for connection, recorded, raw in self.reader.messages(connections=connections):
                if recorded < last:
                    raise InputError(
                        _out_of_order(self.reader, self.path, connection.topic, recorded, last)
                    )
                last = recorded
                if progress is not None:
                    progress.update()
                yield connection.topic, recorded, raw
        except ReaderError as error:
            raise InputError(f"{self.path} cannot be read: {error}") from None


class _TopicRows:
    """The recording times and field values of one topic's messages.

    Numeric fields are read in bulk from the raw bytes of every message that shares the first
    message's layout (:mod:`robotale.eventlog.cdrlayout`); other messages, and other fields, are
    decoded one by one with rosbags.
    """

    def __init__(self, msgtype, paths: list[str], stamped: bool, typestore, decode) -> None:
        self.msgtype, self.paths, self.stamped = msgtype, paths, stamped
        self.typestore, self.decode = typestore, decode
        self.extract = _extractor(paths)
        self.layout: Layout | None = None
        self.recorded: list[int] = []
        self.bulk = bytearray()
        self.bulk_at: list[int] = []
        self.one_by_one: list[tuple] = []
        self.one_by_one_at: list[int] = []

    def add(self, recorded: int, raw: bytes) -> None:
        if not self.recorded and self.paths:
            self.layout = self._checked_layout(raw)
        position = len(self.recorded)
        self.recorded.append(recorded)
        if not self.paths:
            return
        if self.layout is not None and self.layout.fits(raw):
            self.bulk += raw[: self.layout.end]
            self.bulk_at.append(position)
        else:
            self.one_by_one.append(self.extract(self.decode(raw)))
            self.one_by_one_at.append(position)

    def _checked_layout(self, raw: bytes) -> Layout | None:
        """The first message's layout, if reading it in bulk gives what rosbags decodes."""
        layout = Layout.of(raw, self.msgtype, self.paths, self.typestore.fielddefs)
        if layout is None:
            return None
        bulk = [values[0].item() for values in columns(layout, raw[: layout.end])]
        decoded = self.extract(self.decode(raw))
        same = all(a == b or (a != a and b != b) for a, b in zip(bulk, decoded, strict=True))
        return layout if same else None

    def table(self, names: list[str], bag_time: bool) -> pd.DataFrame:
        count = len(self.recorded)
        bulk = columns(self.layout, self.bulk) if self.bulk_at else None
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
        return _table(np.asarray(self.recorded, dtype=np.int64), values, names, bag_time)


def read_bag(
    path: Path,
    topics: Sequence[str] | None = None,
    *,
    msg_files: Sequence[Path] = (),
    bag_time: bool = False,
) -> dict[str, pd.DataFrame]:
    """Every scalar field of every topic (or of ``topics``), one DataFrame per topic."""
    with Bag(Path(path), message_types(msg_files)) as bag:
        chosen = list(bag.topics) if topics is None else list(topics)
        columns = {topic: {f: f for f in bag.fields(topic)} for topic in chosen}
        return bag.tables(columns, bag_time=bag_time)


def _extractor(paths: list[str]):
    """A function from a message to the tuple of its values at ``paths``."""
    if not paths:
        return lambda message: ()
    get = attrgetter(*paths)
    return get if len(paths) > 1 else lambda message: (get(message),)


def _table(recorded: np.ndarray, values: dict, names: list[str], bag_time: bool) -> pd.DataFrame:
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
        return [str(storage.path) for storage in reader.storage.storages]
    return []


def _definitions(reader: Reader, extra: Mapping, path: Path) -> dict:
    """The types the bag carries, then the user's, then the distribution's, then robotale's."""
    typs: dict = {}
    for connection in reader.connections:
        typs.update(_embedded_types(connection, path))
    for source in (extra, _distribution_types(reader), get_types_from_msg(TAG_MSGDEF, TAG_TYPE)):
        typs.update({name: spec for name, spec in source.items() if name not in typs})
    return typs


def _typestore(definitions: Mapping, roots: set[str], path: Path) -> Typestore:
    """A store of the types ``roots`` need whose definitions are all there.

    Only those: a distribution has hundreds of types. Stores are shared between bags that
    need the same definitions (the runs of a batch), as building one generates code.
    """
    needed = _closure(definitions, roots)
    usable = {n: spec for n, spec in needed.items() if _missing(definitions, n) is None}
    key = repr(sorted(usable.items()))
    if key not in _STORES:
        store = get_typestore(Stores.EMPTY)
        try:
            store.register(usable)
        except TypesysError as error:
            raise InputError(f"{path}: its message definitions cannot be used: {error}") from None
        if len(_STORES) >= 32:
            _STORES.clear()
        _STORES[key] = store
    return _STORES[key]


_STORES: dict[str, Typestore] = {}


def _closure(typs: Mapping, roots: set[str]) -> dict:
    """The definitions of ``roots`` and of every type they contain (those there are)."""
    needed: dict = {}
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name in needed or name not in typs:
            continue
        needed[name] = typs[name]
        todo.extend(ref for _, desc in typs[name][1] for ref in _references(desc))
    return needed


def _missing(typs: Mapping, msgtype: str) -> str | None:
    """The first type ``msgtype`` needs (itself included) that has no definition, if any."""
    seen, todo = set(), [msgtype]
    while todo:
        name = todo.pop(0)
        if name in seen:
            continue
        if name not in typs:
            return name
        seen.add(name)
        todo.extend(ref for _, desc in typs[name][1] for ref in _references(desc))
    return None


def _references(desc: tuple) -> list[str]:
    nodetype, detail = desc
    if nodetype == _NAME:
        return [detail]
    if nodetype in (_ARRAY, _SEQUENCE):
        return _references(detail[0])
    return []


def _embedded_types(connection: Connection, path: Path) -> dict:
    definition = connection.msgdef
    try:
        return dict(_parsed(definition.format, definition.data, connection.msgtype))
    except TypesysError as error:
        reason = " ".join(str(error).split())
        raise InputError(
            f"{path}: the definition of {connection.msgtype} stored in the bag cannot be parsed: "
            f"{reason}"
        ) from None


@functools.lru_cache(maxsize=256)
def _parsed(kind: MessageDefinitionFormat, data: str, msgtype: str) -> tuple:
    """A stored definition parsed once: the runs of a batch all store the same ones."""
    if kind == MessageDefinitionFormat.MSG:
        return tuple(get_types_from_msg(data, msgtype).items())
    if kind == MessageDefinitionFormat.IDL:
        separator = "=" * 80 + "\n"
        typs: dict = {}
        for part in data.split(separator)[1:] or [data]:
            typs.update(
                get_types_from_idl(part.split("\n", 1)[1] if part.startswith("IDL: ") else part)
            )
        return tuple(typs.items())
    return ()


def _distribution_types(reader: Reader) -> Mapping:
    distro = (reader.ros_distro or "humble").lower()
    store = getattr(Stores, f"ROS2_{distro.upper()}", Stores.ROS2_HUMBLE)
    return get_typestore(store).fielddefs


def all_fields(msgtype: str, typestore: Typestore, prefix: str = "") -> list[str]:
    """Dotted paths of every field, nested messages included as well as their leaves."""
    paths = []
    for name, (nodetype, detail) in typestore.fielddefs[msgtype][1]:
        path = f"{prefix}{name}"
        paths.append(path)
        if nodetype == _NAME:
            paths.extend(all_fields(detail, typestore, f"{path}."))
    return paths


def scalar_fields(msgtype: str, typestore: Typestore, prefix: str = "") -> list[str]:
    """Dotted paths of the scalar leaves (numbers, strings, booleans) of a message type."""
    paths = []
    for name, (nodetype, detail) in typestore.fielddefs[msgtype][1]:
        if nodetype == _BASE:
            paths.append(f"{prefix}{name}")
        elif nodetype == _NAME:
            paths.extend(scalar_fields(detail, typestore, f"{prefix}{name}."))
    return paths


def field_type(msgtype: str, path: str, typestore: Typestore) -> str | None:
    """The base type (``float32``, ``string`` ...) of a scalar field, ``None`` for others."""
    head, _, rest = path.partition(".")
    for name, (nodetype, detail) in typestore.fielddefs[msgtype][1]:
        if name == head:
            if rest:
                return field_type(detail, rest, typestore) if nodetype == _NAME else None
            return detail[0] if nodetype == _BASE else None
    return None


def _shortest_float32(values: pd.Series) -> pd.Series:
    """float32 readings as the decimals they were written as (0.98, not 0.9800000190734863)."""
    as_text = values.to_numpy(np.float32).astype(str)
    return pd.Series(as_text.astype(np.float64), index=values.index)


def stamp_path(msgtype: str, typestore: Typestore) -> str | None:
    """Where a message type keeps its time: ``header.stamp``, ``stamp``, or nowhere."""
    for name, (nodetype, detail) in typestore.fielddefs[msgtype][1]:
        if nodetype == _NAME and name == "header" and detail == HEADER_TYPE:
            return "header.stamp"
    for name, (nodetype, detail) in typestore.fielddefs[msgtype][1]:
        if nodetype == _NAME and name == "stamp" and detail == TIME_TYPE:
            return "stamp"
    return None


def namespace(topic: str) -> str:
    """The namespace of a topic: ``/tractor_1/odom`` -> ``tractor_1``; ``/odom`` -> ``""``."""
    return topic.strip("/").rpartition("/")[0]
