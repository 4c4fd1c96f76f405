"""The preparation options: how recordings become an event log, as ``prepare``, ``ingest`` and
``annotate`` take them from the command line.

One spelling: each field is named as the command line's ``dest`` and as the keyword of
:func:`robotale.eventlog.prepare.prepare` it becomes, so adding an option is one field here,
one flag in the CLI and its use in the preparation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass
from typing import Any

from robotale.eventlog.tagrows import TagFields


@dataclass(frozen=True)
class PrepareOptions:
    """The options as given (text, as typed); one left ``None`` takes the preparation's
    default."""

    #: the glob of the tag topics
    tags: str | None = None
    #: ``KEY=FIELD`` items naming the tag message's fields
    tag_fields: Sequence[str] = ()
    #: comma-separated perspectives (``odom``, ``battery``, ``NAME=/GLOB:FIELD``)
    perspectives: str | None = None
    #: inprogress events per second of an activity
    rate: float | None = None
    #: ``.msg`` / ``.idl`` files or folders for types the bags do not define
    msg_files: Sequence[str] = ()
    #: time events by when the bag recorded them
    bag_time: bool = False
    #: how tags end activities (explicit, implicit, events)
    lifecycle: str | None = None
    #: the glob of action status topics whose goals are activities
    actions: str | None = None
    #: ``GLOB[:FIELD]`` state topics whose values are activities
    states: Sequence[str] = ()
    #: the glob of behaviour-tree logs whose nodes are activities
    bt_logs: str | None = None
    #: take activities from whatever actions, state topics and BT logs a bag holds
    auto: bool = False
    #: the ROS 2 distribution whose standard types fill in those a bag does not define
    distro: str | None = None
    #: the robot of tags and activities on topics without a namespace
    robot: str | None = None

    @classmethod
    def given(cls, options: dict[str, Any]) -> PrepareOptions:
        """From the command line's keywords (those it did not get are left out)."""
        return cls(**{key: value for key, value in options.items() if value is not None})

    def keywords(self) -> dict[str, Any]:
        """The options as :func:`~robotale.eventlog.prepare.prepare` takes them; one left
        ``None`` is not passed, so that it takes its default."""
        given = asdict(self)
        perspectives = given.pop("perspectives")
        if perspectives is not None:
            given["perspectives"] = [p for p in perspectives.split(",") if p.strip()]
        given["tag_fields"] = TagFields.parse(self.tag_fields)
        given["msg_files"] = tuple(self.msg_files)
        given["states"] = list(self.states)
        optional = ("tags", "rate")  # prepare() has its own default for these
        return {k: v for k, v in given.items() if not (k in optional and v is None)}
