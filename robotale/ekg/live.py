"""A live run's log in Neo4j: the tags stored as they are heard, a few at a time, each batch a
transaction of its own, so the run is queryable while it goes on; and the alerts raised about
it."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from neo4j import Driver

from robotale.ekg.build import check_log_name, ensure_schema
from robotale.ekg.connection import database
from robotale.fame_runtime.tags import Tag, text_fields
from robotale.queries import cypher


@dataclass(frozen=True, slots=True)
class Alert:
    """Something an operator should know now: ``kind`` names the rule that raised it."""

    stamp: float
    kind: str
    robot: str
    text: str


@dataclass(frozen=True, slots=True)
class Pose:
    """Where ``robot`` was at ``stamp`` (seconds since the Unix epoch), by its odometry."""

    stamp: float
    robot: str
    x: float
    y: float
    z: float


class LiveLog:
    """The growing log ``name``: tags appended a few at a time, each batch a transaction,
    numbered as heard."""

    def __init__(self, driver: Driver, name: str) -> None:
        check_log_name(name)
        self.driver, self.name, self.count, self.pose_count = driver, name, 0, 0
        ensure_schema(driver)  # the (log, seq) indexes a following reader looks up by
        delete_live(driver, name)  # a new run of that name starts empty

    def append(self, tag: Tag) -> None:
        self.append_tags([tag])

    def append_tags(self, tags: Sequence[Tag]) -> None:
        """Store ``tags`` (in the order they were heard), all in one transaction."""
        if not tags:
            return
        fields = [text_fields(tag) for tag in tags]
        self._run(
            "live_append_tags",
            seqs=list(range(self.count + 1, self.count + len(tags) + 1)),
            stamps=[tag.stamp for tag in tags],
            **{name: [f[key] for f in fields] for key, name in _NAMES.items()},
        )
        self.count += len(tags)

    def alert(self, alert: Alert) -> None:
        self.alerts([alert])

    def alerts(self, alerts: Sequence[Alert]) -> None:
        """Store ``alerts``, all in one transaction."""
        if alerts:
            self._run(
                "live_append_alerts",
                stamps=[a.stamp for a in alerts],
                kinds=[a.kind for a in alerts],
                robots=[a.robot for a in alerts],
                texts=[a.text for a in alerts],
            )

    def poses(self, poses: list[Pose]) -> None:
        """Store odometry samples, all in one transaction."""
        if poses:
            self._run(
                "live_append_poses",
                seqs=list(range(self.pose_count + 1, self.pose_count + len(poses) + 1)),
                stamps=[p.stamp for p in poses],
                robots=[p.robot for p in poses],
                xs=[p.x for p in poses],
                ys=[p.y for p in poses],
                zs=[p.z for p in poses],
            )
            self.pose_count += len(poses)

    def _run(self, query: str, **parameters: Any) -> None:
        self.driver.execute_query(
            cypher(query), {"log": self.name, **parameters}, database_=database()
        )


def delete_live(driver: Driver, name: str) -> None:
    """Forget the live run ``name``: its tags, odometry samples and alerts."""
    driver.execute_query(cypher("live_delete"), {"log": name}, database_=database())


def live_tags(driver: Driver, name: str, after: int = 0) -> list[Tag]:
    """The tags stored for the live run ``name``, in the order they were heard (those after
    the first ``after``)."""
    records, _, _ = driver.execute_query(
        cypher("live_tags"), {"log": name, "after": after}, database_=database()
    )
    return [
        Tag(
            r["stamp"],
            r["robot"],
            r["activity"],
            r["lifecycle"],
            r["msgId"],
            r["msgRole"],
            r["payload"],
        )
        for r in records
    ]


def live_poses(driver: Driver, name: str, after: int = 0) -> list[Pose]:
    """The odometry samples stored so far for the live run ``name`` (those after the first
    ``after``), in the order they were stored."""
    records, _, _ = driver.execute_query(
        cypher("live_poses"), {"log": name, "after": after}, database_=database()
    )
    return [Pose(r["stamp"], r["robot"], r["x"], r["y"], r["z"]) for r in records]


def live_since(driver: Driver, name: str, tags: int, poses: int) -> tuple[list[Tag], list[Pose]]:
    """The tags and the odometry samples stored for the live run ``name`` after the first
    ``tags`` and the first ``poses``, each in the order stored: both in one round trip."""
    records, _, _ = driver.execute_query(
        cypher("live_since"),
        {"log": name, "tags": tags, "poses": poses},
        database_=database(),
    )
    found = records[0]
    return [Tag(*row) for row in found["tags"]], [Pose(*row) for row in found["poses"]]


def live_alerts(driver: Driver, name: str) -> list[Alert]:
    """The alerts raised so far about the live run ``name``, oldest first."""
    records, _, _ = driver.execute_query(cypher("live_alerts"), {"log": name}, database_=database())
    return [Alert(r["stamp"], r["kind"], r["robot"], r["text"]) for r in records]


#: a tag's text fields under the Cypher parameter names of their lists
_NAMES = {
    "robot": "robots",
    "activity": "activities",
    "lifecycle": "lifecycles",
    "msg_id": "msgIds",
    "msg_role": "msgRoles",
    "payload": "payloads",
}
