"""Message types of a rosbag2 recording, apart from reading its storage: which definitions a
bag's types take (the user's, the bag's own, its distribution's, those robotale ships, the
tag's), a type store of just those, and the fields of a type.

As rosbags keeps its type system (``rosbags.typesys``) apart from its storage readers
(``rosbags.rosbag2``), :mod:`robotale.eventlog.rosbag` asks this module what a type is and
reads the messages itself.
"""

from __future__ import annotations

import functools
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

from rosbags.interfaces import MessageDefinitionFormat, Nodetype
from rosbags.typesys import (
    Stores,
    TypesysError,
    get_types_from_idl,
    get_types_from_msg,
    get_typestore,
)
from rosbags.typesys.store import Typestore

from robotale.errors import InputError
from robotale.eventlog.interfaces import RELEASES, normalized, shipped, stored_types
from robotale.fame_runtime.tags import TAG_MSGDEF, TAG_TYPE

if TYPE_CHECKING:
    # a bag's reader and connections only typed here: the reader (rosbags.rosbag2, its
    # storages and YAML) is not imported where a CSV is prepared
    from rosbags.interfaces import Connection
    from rosbags.interfaces.typing import FieldDesc, Typesdict
    from rosbags.rosbag2 import Reader


HEADER_TYPE = "std_msgs/msg/Header"


TIME_TYPE = "builtin_interfaces/msg/Time"


def bag_definitions(
    reader: Reader, extra: Typesdict, release: str, unparsed: dict[str, str]
) -> Typesdict:
    """The user's types, then the bag's, then the distribution's (rosbags' store), then those
    robotale ships for it, then robotale's Tag.

    The user's come first: they are given to correct or complete what the bag says. A stored
    definition that cannot be parsed is noted in ``unparsed`` (topic -> reason) and left out.
    """
    typs: Typesdict = dict(extra)
    for connection in reader.connections:
        try:
            embedded = _embedded_types(connection)
        except TypesysError as error:
            reason = " ".join(str(error).split())
            unparsed[connection.topic] = reason if len(reason) < 160 else f"{reason[:157]}..."
            continue
        typs.update({name: spec for name, spec in embedded.items() if name not in extra})
    # a release rosbags has no store of yet (rolling) takes the latest it has
    standard = get_typestore(DISTROS.get(release, [*DISTROS.values()][-1])).fielddefs
    for source in (standard, shipped(release), get_types_from_msg(TAG_MSGDEF, TAG_TYPE)):
        typs.update({name: spec for name, spec in source.items() if name not in typs})
    return typs


def typestore_for(definitions: Typesdict, roots: set[str], path: Path) -> Typestore:
    """A store of the types ``roots`` need whose definitions are all there.

    Only those: a distribution has hundreds of types. Stores are shared between bags that
    need the same definitions (the runs of a batch), as building one generates code.
    """
    needed = _closure(definitions, roots)
    usable = {n: spec for n, spec in needed.items() if missing_type(definitions, n) is None}
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


def _closure(typs: Typesdict, roots: set[str]) -> Typesdict:
    """The definitions of ``roots`` and of every type they contain (those there are)."""
    needed: Typesdict = {}
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name in needed or name not in typs:
            continue
        needed[name] = typs[name]
        todo.extend(ref for _, desc in typs[name][1] for ref in _references(desc))
    return needed


def missing_type(typs: Typesdict, msgtype: str) -> str | None:
    """The first type ``msgtype`` needs (itself included) that has no definition, if any."""
    seen: set[str] = set()
    todo = [msgtype]
    while todo:
        name = todo.pop(0)
        if name in seen:
            continue
        if name not in typs:
            return name
        seen.add(name)
        todo.extend(ref for _, desc in typs[name][1] for ref in _references(desc))
    return None


def _references(desc: FieldDesc) -> list[str]:
    if desc[0] == Nodetype.NAME:
        return [desc[1]]
    if desc[0] in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return _references(cast("tuple[FieldDesc, int]", desc[1])[0])
    return []


def _nested(desc: FieldDesc) -> str | None:
    """The message type of a nested message's field, else None."""
    return desc[1] if desc[0] == Nodetype.NAME else None


def _base(desc: FieldDesc) -> str | None:
    """The base type (``float32`` ...) of a scalar field, else None."""
    return cast("tuple[str, int]", desc[1])[0] if desc[0] == Nodetype.BASE else None


def _embedded_types(connection: Connection) -> Typesdict:
    definition = connection.msgdef
    if not definition.data.strip():  # what rosbag2 stores for a type it found no file of
        return {}
    try:
        return dict(_parsed(definition.format, definition.data, connection.msgtype))
    except (KeyError, IndexError, ValueError) as error:  # malformed IDL the parser trips on
        raise TypesysError(f"{type(error).__name__}: {error}") from None


@functools.lru_cache(maxsize=256)
def _parsed(kind: MessageDefinitionFormat, data: str, msgtype: str) -> tuple[tuple[str, Any], ...]:
    """A stored definition parsed once: the runs of a batch all store the same ones."""
    if kind == MessageDefinitionFormat.MSG:
        return tuple(stored_types(data, normalized(msgtype)).items())
    if kind == MessageDefinitionFormat.IDL:
        separator = "=" * 80 + "\n"
        typs: Typesdict = {}
        for part in data.split(separator)[1:] or [data]:
            typs.update(
                get_types_from_idl(part.split("\n", 1)[1] if part.startswith("IDL: ") else part)
            )
        return tuple(typs.items())
    return ()


#: the distributions whose standard types rosbags provides, by the name users give them
DISTROS = {
    name.removeprefix("ROS2_").lower(): store
    for name, store in Stores.__members__.items()
    if name.startswith("ROS2_")
}


DEFAULT_DISTRO = "humble"


def release_of(name: str | None) -> str:
    """The distribution a bag's types are completed from: ``name`` if robotale knows it, else
    Humble (what a bag that names none was most likely recorded with)."""
    name = (name or DEFAULT_DISTRO).lower()
    return name if name in DISTROS or name in RELEASES else DEFAULT_DISTRO


def check_distro(name: str | None) -> str | None:
    """``name`` if rosbags knows the distribution, else an error listing those it knows."""
    if name is not None and name.lower() not in DISTROS:
        raise InputError(
            f"Unknown ROS 2 distribution {name!r}: use one of {', '.join(sorted(DISTROS))}."
        )
    return name and name.lower()


def all_fields(msgtype: str, typestore: Typestore, prefix: str = "") -> list[str]:
    """Dotted paths of every field, nested messages included as well as their leaves."""
    paths = []
    for name, desc in typestore.fielddefs[msgtype][1]:
        path = f"{prefix}{name}"
        paths.append(path)
        if (nested := _nested(desc)) is not None:
            paths.extend(all_fields(nested, typestore, f"{path}."))
    return paths


def scalar_fields(msgtype: str, typestore: Typestore, prefix: str = "") -> list[str]:
    """Dotted paths of the scalar leaves (numbers, strings, booleans) of a message type."""
    paths = []
    for name, desc in typestore.fielddefs[msgtype][1]:
        if desc[0] == Nodetype.BASE:
            paths.append(f"{prefix}{name}")
        elif (nested := _nested(desc)) is not None:
            paths.extend(scalar_fields(nested, typestore, f"{prefix}{name}."))
    return paths


def field_type(msgtype: str, path: str, typestore: Typestore) -> str | None:
    """The base type (``float32``, ``string`` ...) of a scalar field, ``None`` for others."""
    head, _, rest = path.partition(".")
    for name, desc in typestore.fielddefs[msgtype][1]:
        if name == head:
            if rest:
                nested = _nested(desc)
                return field_type(nested, rest, typestore) if nested is not None else None
            return _base(desc)
    return None


def stamp_path(msgtype: str, typestore: Typestore) -> str | None:
    """Where a message type keeps its time: ``header.stamp``, ``stamp``, or nowhere."""
    for name, desc in typestore.fielddefs[msgtype][1]:
        if name == "header" and _nested(desc) == HEADER_TYPE:
            return "header.stamp"
    for name, desc in typestore.fielddefs[msgtype][1]:
        if name == "stamp" and _nested(desc) == TIME_TYPE:
            return "stamp"
    return None
