"""Tags: the events a running mission leaves behind (TALE's tags, emitted by the engines).

Every activity start and completion and every signal throw and catch becomes a :class:`Tag`.
On a bus and in a rosbag2 recording a tag is the ROS 2 message ``robotale_msgs/msg/Tag`` on the
topic ``/<robot>/tag``; :data:`TAG_MSGDEF` is its definition and :func:`register_tag_type`
adds it to a rosbags type store so bags can be written and read without a ROS installation.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, fields
from enum import StrEnum
from typing import Any

from robotale.fame_runtime.bus import Bus
from robotale.fame_runtime.clock import Clock

TAG_TYPE = "robotale_msgs/msg/Tag"


class Lifecycle(StrEnum):
    """The lifecycles of activity tags: started, completed, and ended without completing
    (interrupted by a boundary event or an event sub-process, or cancelled)."""

    START = "start"
    COMPLETE = "complete"
    ABORT = "ate_abort"


#: the lifecycles as the plain text a tag carries
START, COMPLETE, ABORT = Lifecycle.START.value, Lifecycle.COMPLETE.value, Lifecycle.ABORT.value
#: the roles of message tags
SEND, RECEIVE = "send", "receive"


@dataclass(frozen=True, slots=True)
class Tag:
    """One tagged event.

    ``stamp`` is seconds since the Unix epoch on the engine's clock (simulated time in a
    simulation). ``lifecycle`` is ``start``, ``complete``, ``ate_abort`` (an activity that was
    interrupted or cancelled ends with it instead of ``complete``: XES' standard transition for
    an aborted activity) or ``none`` (instant events such as a timer firing). Message events
    name the message: ``msg_role`` is ``send`` or ``receive`` and every receive carries the
    ``msg_id`` of the send it caught, whether a catching event or a skill consumed it;
    ``payload`` is JSON text.
    """

    stamp: float
    robot: str
    activity: str
    lifecycle: str
    msg_id: str = ""
    msg_role: str = ""
    payload: str = ""


def tag_nanoseconds(stamp: float) -> int:
    """A tag's stamp in whole nanoseconds since the Unix epoch, as its message carries it."""
    return round(stamp * 1e9)


def tag_stamp(nanoseconds: int) -> float:
    """The stamp whose :func:`tag_nanoseconds` are ``nanoseconds``: a float holds a stamp of
    today only to about 240 ns, and the nearest one to ``nanoseconds`` may give others, so
    its neighbours are tried too. A tag received keeps its stamp to the nanosecond when sent
    on (a recorder's bag), and a live run's events have the times of its recording's."""
    nearest = nanoseconds / 1_000_000_000  # int / int: correctly rounded
    candidate = below = above = nearest
    for _ in range(4):
        for candidate in (below, above):
            if tag_nanoseconds(candidate) == nanoseconds:
                return candidate
        below, above = math.nextafter(below, -math.inf), math.nextafter(above, math.inf)
    return nearest  # a writer that is not robotale's chose nanoseconds no float gives


#: the tag's fields besides its stamp, in its order: the message's ``string`` fields, the columns
#: of a printed tag line and the fields a bag's tag message is read by (``TagFields``)
TEXT_FIELDS: tuple[str, ...] = tuple(f.name for f in fields(Tag) if f.name != "stamp")

#: the ROS 2 message definition of a tag, derived from :class:`Tag`
TAG_MSGDEF = "".join(
    [
        "# One tagged event of a robot's mission (TALE).\n",
        "builtin_interfaces/Time stamp\n",
        *(f"string {name}\n" for name in TEXT_FIELDS),
    ]
)


def text_fields(tag: Tag) -> dict[str, str]:
    """The tag's fields besides its stamp, by name (as its message carries them)."""
    return {name: getattr(tag, name) for name in TEXT_FIELDS}


#: where engines deliver tags: a recorder, a list's ``append``, a printer ...
TagSink = Callable[[Tag], None]


class Tagger:
    """Tags one robot's events on its clock, and numbers its messages when the bus does not."""

    def __init__(
        self, robot: str, clock: Clock, sink: TagSink | None, bus: Bus | None = None
    ) -> None:
        self.robot, self.clock, self.sink = robot, clock, sink
        self._bus_ids: Callable[[], str] | None = getattr(bus, "new_msg_id", None)
        self._count = 0

    def __call__(
        self,
        activity: str,
        lifecycle: Lifecycle,
        msg_id: str = "",
        role: str = "",
        payload: str = "",
    ) -> None:
        if self.sink is not None:
            stamp = self.clock.now()
            # the plain text: a tag is written to bags and logs as it is
            self.sink(Tag(stamp, self.robot, activity, lifecycle.value, msg_id, role, payload))

    def pair(self, activity: str, msg_id: str = "", role: str = "", payload: str = "") -> None:
        """A start and a complete tag at the same instant (events, messages)."""
        self(activity, Lifecycle.START, msg_id, role, payload)
        self(activity, Lifecycle.COMPLETE, msg_id, role, payload)

    def new_msg_id(self) -> str:
        """The bus's next message id, or ``m_<robot>_<n>``: robot namespaces are unique in a
        mission, so that is unique on any bus."""
        if self._bus_ids is not None:
            return self._bus_ids()
        self._count += 1
        return f"m_{self.robot}_{self._count}"


def payload_text(data: Any) -> str:  # any message: JSON text, else its str
    """A message's data as the JSON text tags carry."""
    return json.dumps(data, default=str, separators=(",", ":"))


def tag_topic(robot: str) -> str:
    """The topic a robot's tags are published on."""
    return f"/{robot}/tag"


def bus_sink(bus: Bus) -> TagSink:
    """A tag sink that publishes every tag on its robot's ``/<robot>/tag`` topic, where a
    recorder tapping the bus writes it to a bag like any other message."""

    def publish(tag: Tag) -> None:
        bus.publish(tag_topic(tag.robot), tag, msgtype=TAG_TYPE, sender=tag.robot)

    return publish


def register_tag_type(typestore: Any) -> None:  # rosbags has no type information
    """Add ``robotale_msgs/msg/Tag`` to a rosbags type store (idempotent)."""
    # rosbags is imported here, by those who read or write bags, not with the module: every
    # engine imports this module, and rosbags would add a fifth (about 30 ms) to its import
    from rosbags.typesys import get_types_from_msg

    if TAG_TYPE not in typestore.fielddefs:
        typestore.register(get_types_from_msg(TAG_MSGDEF, TAG_TYPE))


def tag_line(tag: Tag, begin: float = 0.0) -> str:
    """A tag as one tab-separated line, its stamp in seconds since ``begin``."""
    cells = (f"{tag.stamp - begin:10.3f}", *(getattr(tag, name) for name in TEXT_FIELDS))
    return "\t".join(cells).rstrip()
