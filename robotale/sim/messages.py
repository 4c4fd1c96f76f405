"""ROS 2 messages as the bus carries them (plain dicts with ROS field names) and as a bag stores
them (rosbags message objects, serialized to CDR).

The simulated world, the skills and the engines exchange dicts such as
``{"linear": {"x": 0.5}, "angular": {"z": 0.1}}`` for ``geometry_msgs/msg/Twist``; a field
left out takes the ROS default (zero, empty text, an empty sequence). :func:`to_message` builds
the typed message a rosbags writer serializes, checking every field name against the type.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from typing import Any

import numpy as np
from rosbags.typesys import Stores, get_typestore
from rosbags.typesys.store import Typestore

from robotale.errors import ModelError
from robotale.fame_runtime.tags import TAG_TYPE, Tag, register_tag_type, text_fields

_NUMPY = {
    "bool": np.bool_,
    "int8": np.int8,
    "uint8": np.uint8,
    "byte": np.uint8,
    "char": np.uint8,
    "int16": np.int16,
    "uint16": np.uint16,
    "int32": np.int32,
    "uint32": np.uint32,
    "int64": np.int64,
    "uint64": np.uint64,
    "float32": np.float32,
    "float64": np.float64,
}
_BASE, _NAME, _ARRAY, _SEQUENCE = 1, 2, 3, 4  # rosbags' Nodetype values


@cache
def typestore() -> Typestore:
    """ROS 2 Humble's standard messages plus robotale's Tag (one store per process)."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    register_tag_type(store)
    return store


def stamp(seconds: float) -> dict[str, int]:
    """A ``builtin_interfaces/msg/Time`` for seconds since the Unix epoch."""
    nanoseconds = round(seconds * 1e9)
    return {"sec": nanoseconds // 1_000_000_000, "nanosec": nanoseconds % 1_000_000_000}


def header(seconds: float, frame_id: str) -> dict[str, Any]:
    return {"stamp": stamp(seconds), "frame_id": frame_id}


def known(msgtype: str) -> bool:
    return msgtype in typestore().fielddefs


def to_message(msgtype: str, data: Any, where: str = "") -> Any:
    """The rosbags message of type ``msgtype`` holding ``data`` (a dict, or a Tag).

    A field the type does not have is a ModelError naming ``where`` (the topic) and the field.
    """
    if isinstance(data, Tag):
        data = tag_fields(data)
    store = typestore()
    if msgtype not in store.fielddefs:
        raise ModelError(f"{where}: the message type {msgtype} is not a ROS 2 Humble type")
    return _build(store, msgtype, data if isinstance(data, Mapping) else {}, where)


def serialize(msgtype: str, data: Any, where: str = "") -> bytes:
    """CDR bytes of ``data`` as a ``msgtype`` message (what a rosbag2 file stores)."""
    return bytes(typestore().serialize_cdr(to_message(msgtype, data, where), msgtype))


def tag_fields(tag: Tag) -> dict[str, Any]:
    """A Tag as ``robotale_msgs/msg/Tag`` fields."""
    return {
        "stamp": stamp(tag.stamp),
        **text_fields(tag),
    }


def _build(store: Typestore, msgtype: str, data: Mapping[str, Any], where: str) -> Any:
    _, fields = store.fielddefs[msgtype]
    names = {name for name, _ in fields}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ModelError(
            f"{where}: {msgtype} has no field {', '.join(unknown)} "
            f"(its fields: {', '.join(sorted(names)) or 'none'})"
        )
    values = {
        name: _value(store, kind, data.get(name), f"{where}.{name}" if where else name)
        for name, kind in fields
    }
    return store.types[msgtype](**values)


def _value(store: Typestore, kind: tuple, value: Any, where: str) -> Any:
    nodetype, detail = kind
    if nodetype == _BASE:
        return _base(detail[0], value, where)
    if nodetype == _NAME:
        return _build(store, detail, value if isinstance(value, Mapping) else {}, where)
    element, length = detail
    items = list(value) if value is not None else []
    if nodetype == _ARRAY and not items:
        items = [None] * length
    if element[0] == _BASE and element[1][0] in _NUMPY:
        return np.array([0 if v is None else v for v in items], dtype=_NUMPY[element[1][0]])
    return [_value(store, element, item, f"{where}[{i}]") for i, item in enumerate(items)]


def _base(name: str, value: Any, where: str) -> Any:
    try:
        if name == "string" or name == "wstring":
            return "" if value is None else str(value)
        if name == "bool":
            return bool(value)
        if name.startswith("float"):
            return 0.0 if value is None else float(value)
        return 0 if value is None else int(value)
    except (TypeError, ValueError):
        raise ModelError(f"{where}: {value!r} is not a {name}") from None


__all__ = ["TAG_TYPE", "header", "known", "serialize", "stamp", "to_message", "typestore"]
