"""The entity columns and aggregation keys a log gets when nobody names them: one owner for
the command line, the dashboard, the demo and discovery."""

from __future__ import annotations

from collections.abc import Collection, Sequence

from robotale.eventlog import schema

#: entity columns used when none are named: those of these the log has, else the case
DEFAULT_ENTITIES = ("robot", "msg_id")
#: the class graphs ``robotale ingest`` builds when no ``--aggregate`` is given
DEFAULT_AGGREGATE = ("activity",)
#: the key a class graph is discovered by when none is named: each robot's own activities
DISCOVERY_KEY = "activity,robot"


def default_entities(columns: Collection[str]) -> list[str]:
    """The default entity columns of a log with these (canonical) columns."""
    present = [e for e in DEFAULT_ENTITIES if e in columns]
    return present or [schema.CSV_NAMES[schema.CASE]]


def built_keys(entities: Sequence[str]) -> list[str]:
    """The class graphs built with a log by the dashboard and the demo: by activity, and by
    activity and robot (the Discover page's first view) when robots are entities; others
    are built when asked for."""
    return ["activity", DISCOVERY_KEY] if "robot" in entities else ["activity"]
