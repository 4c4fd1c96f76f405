"""ROS 2 message types as DDS types, the way ROS 2 itself puts them on the wire.

ROS 2 (rmw_cyclonedds) names the DDS topic of ``/weed_position`` ``rt/weed_position`` and
the DDS type of ``std_msgs/msg/String`` ``std_msgs::msg::dds_::String_``, and encodes samples
as plain CDR. :func:`idl_type` builds that type as a ``cyclonedds`` IDL struct from the
message definitions rosbags knows (ROS 2 Humble's standard messages and robotale's Tag), so
a robotale signal and a ROS 2 node on the same DDS domain understand each other.

On a robotale bus messages are dicts with ROS field names (a field left out takes the ROS
default), or a :class:`~robotale.fame_runtime.tags.Tag` on tag topics; :func:`to_sample` and
:func:`to_data` convert between the two.
"""

from __future__ import annotations

from collections.abc import Mapping
from functools import cache
from typing import Any

from cyclonedds.idl import make_idl_struct
from cyclonedds.idl import types as idl_types
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from robotale.errors import ModelError
from robotale.fame_runtime.tags import (
    TAG_TYPE,
    Tag,
    register_tag_type,
    tag_nanoseconds,
    tag_stamp,
    text_fields,
)

#: cyclonedds' IDL types, made by subscripting (``array[int8, 3]``), which its annotations
#: do not express
types: Any = idl_types

_BASE, _NAME, _ARRAY, _SEQUENCE = 1, 2, 3, 4  # rosbags' Nodetype values

#: what each robot's engine process says of itself on ``/robotale/status`` (a mission run as
#: one process per robot is over when every robot has said it is idle for a while)
STATUS_TYPE = "robotale_msgs/msg/RobotStatus"
STATUS_MSGDEF = """\
string robot
bool ready
bool busy
bool timer
int32 completed
string where
"""


def dds_topic(topic: str) -> str:
    """The DDS topic of a ROS 2 topic: ``/weed_position`` -> ``rt/weed_position``."""
    return "rt/" + topic.lstrip("/")


def ros_topic(dds_name: str) -> str:
    """The ROS 2 topic of a DDS topic (``rt/a/b`` -> ``/a/b``)."""
    return "/" + dds_name.removeprefix("rt/")


def dds_type_name(msgtype: str) -> str:
    """``std_msgs/msg/String`` -> ``std_msgs::msg::dds_::String_`` (ROS 2's IDL mangling)."""
    package, kind, name = _parts(msgtype)
    return f"{package}::{kind}::dds_::{name}_"


def _parts(msgtype: str) -> tuple[str, str, str]:
    parts = msgtype.split("/")
    if len(parts) != 3 or not all(parts):
        raise ModelError(f"{msgtype!r} is not a ROS 2 message type such as std_msgs/msg/String")
    return parts[0], parts[1], parts[2]


@cache
def _store() -> Any:  # a rosbags type store: rosbags has no type information
    store = get_typestore(Stores.ROS2_HUMBLE)
    register_tag_type(store)
    if STATUS_TYPE not in store.fielddefs:
        store.register(get_types_from_msg(STATUS_MSGDEF, STATUS_TYPE))
    return store


def known(msgtype: str) -> bool:
    return msgtype in _store().fielddefs


@cache
def idl_type(msgtype: str) -> type:
    """The ``cyclonedds`` IDL struct of a ROS 2 message type (one class per type)."""
    store = _store()
    if msgtype not in store.fielddefs:
        raise ModelError(f"the message type {msgtype} is not a ROS 2 Humble type robotale knows")
    _, fields = store.fielddefs[msgtype]
    annotations = {name: _field_type(desc) for name, desc in fields}
    class_name = _parts(msgtype)[2] + "_"
    struct: type = make_idl_struct(class_name, dds_type_name(msgtype), annotations)
    return struct


def _field_type(desc: Any) -> Any:  # a rosbags field description
    kind, rest = desc
    if kind == _NAME:
        return idl_type(rest)
    if kind == _BASE:
        return _base_type(*rest)
    inner, size = rest
    element = _field_type(inner)
    if kind == _ARRAY:
        return types.array[element, size]
    return types.sequence[element, size] if size else types.sequence[element]


def _base_type(name: str, bound: int) -> Any:
    if name == "string":
        return types.bounded_str[bound] if bound else str
    scalars = {
        "bool": bool,
        "byte": types.uint8,
        "char": types.uint8,
        "int8": types.int8,
        "uint8": types.uint8,
        "int16": types.int16,
        "uint16": types.uint16,
        "int32": types.int32,
        "uint32": types.uint32,
        "int64": types.int64,
        "uint64": types.uint64,
        "float32": types.float32,
        "float64": types.float64,
    }
    if name not in scalars:
        raise ModelError(f"the ROS 2 field type {name} cannot travel over DDS with robotale")
    return scalars[name]


def to_sample(msgtype: str, data: Any, where: str = "") -> Any:
    """An IDL sample of ``msgtype`` holding ``data`` (a dict, or a Tag); a field the type
    does not have is a ModelError naming ``where`` (the topic) and the field."""
    if isinstance(data, Tag):
        data = tag_fields(data)
    return _build(msgtype, data if isinstance(data, Mapping) else {}, where)


def _build(msgtype: str, data: Mapping[str, Any], where: str) -> Any:
    _, fields = _store().fielddefs[msgtype]
    names = {name for name, _ in fields}
    unknown = sorted(set(data) - names)
    if unknown:
        listed = ", ".join(sorted(names))
        raise ModelError(f"{where}: {msgtype} has no field {unknown[0]!r} (its fields: {listed})")
    values = {name: _value(desc, data.get(name), f"{where}.{name}") for name, desc in fields}
    return idl_type(msgtype)(**values)


def _value(desc: Any, value: Any, where: str) -> Any:  # a rosbags field description
    kind, rest = desc
    if kind == _NAME:
        return _build(rest, value if isinstance(value, Mapping) else {}, where)
    if kind == _BASE:
        return _scalar(rest[0], value)
    inner, size = rest
    items = list(value) if value is not None else []
    if kind == _ARRAY:
        items = (items + [None] * size)[:size]
    return [_value(inner, item, where) for item in items]


def _scalar(name: str, value: Any) -> Any:
    if name == "string":
        return "" if value is None else str(value)
    if name == "bool":
        return bool(value)
    if name.startswith("float"):
        return float(value or 0.0)
    return int(value or 0)


def to_data(sample: Any, msgtype: str) -> Any:
    """A received sample as the bus carries it: a dict with ROS field names (a Tag on the
    tag type)."""
    data = _plain(sample)
    if msgtype == TAG_TYPE:
        stamp = data["stamp"]
        return Tag(
            tag_stamp(stamp["sec"] * 1_000_000_000 + stamp["nanosec"]),
            data["robot"],
            data["activity"],
            data["lifecycle"],
            data["msg_id"],
            data["msg_role"],
            data["payload"],
        )
    return data


def _plain(value: Any) -> Any:
    fields = getattr(value, "__dataclass_fields__", None)
    if fields is not None:
        return {name: _plain(getattr(value, name)) for name in fields}
    if isinstance(value, list | tuple):
        return [_plain(item) for item in value]
    return value


def tag_fields(tag: Tag) -> dict[str, Any]:
    """A Tag as ``robotale_msgs/msg/Tag`` fields."""
    nanoseconds = tag_nanoseconds(tag.stamp)
    return {
        "stamp": {"sec": nanoseconds // 1_000_000_000, "nanosec": nanoseconds % 1_000_000_000},
        **text_fields(tag),
    }
