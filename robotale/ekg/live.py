"""A live run's log in Neo4j: each tag stored the moment it is heard, in a transaction of
its own, so the run is queryable while it goes on; and the alerts raised about it."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from neo4j import Driver

from robotale.ekg.build import check_log_name
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
    """The growing log ``name``: tags appended one transaction each, numbered as heard."""

    def __init__(self, driver: Driver, name: str) -> None:
        check_log_name(name)
        self.driver, self.name, self.count = driver, name, 0
        delete_live(driver, name)  # a new run of that name starts empty

    def append(self, tag: Tag) -> None:
        self.count += 1
        self._run("live_append_tag", seq=self.count, stamp=tag.stamp, **_names(text_fields(tag)))

    def alert(self, alert: Alert) -> None:
        self._run(
            "live_append_alert",
            stamp=alert.stamp,
            kind=alert.kind,
            robot=alert.robot,
            text=alert.text,
        )

    def poses(self, poses: list[Pose]) -> None:
        """Store odometry samples, all in one transaction."""
        if poses:
            self._run(
                "live_append_poses",
                stamps=[p.stamp for p in poses],
                robots=[p.robot for p in poses],
                xs=[p.x for p in poses],
                ys=[p.y for p in poses],
                zs=[p.z for p in poses],
            )

    def _run(self, query: str, **parameters: Any) -> None:
        self.driver.execute_query(
            cypher(query), {"log": self.name, **parameters}, database_=database()
        )


def delete_live(driver: Driver, name: str) -> None:
    """Forget the live run ``name``: its tags, odometry samples and alerts."""
    driver.execute_query(cypher("live_delete"), {"log": name}, database_=database())


def live_tags(driver: Driver, name: str) -> list[Tag]:
    """The tags stored for the live run ``name``, in the order they were heard."""
    records, _, _ = driver.execute_query(cypher("live_tags"), {"log": name}, database_=database())
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


def live_poses(driver: Driver, name: str) -> list[Pose]:
    """The odometry samples stored so far for the live run ``name``, oldest first."""
    records, _, _ = driver.execute_query(cypher("live_poses"), {"log": name}, database_=database())
    return [Pose(r["stamp"], r["robot"], r["x"], r["y"], r["z"]) for r in records]


def live_alerts(driver: Driver, name: str) -> list[Alert]:
    """The alerts raised so far about the live run ``name``, oldest first."""
    records, _, _ = driver.execute_query(cypher("live_alerts"), {"log": name}, database_=database())
    return [Alert(r["stamp"], r["kind"], r["robot"], r["text"]) for r in records]


def _names(fields: dict[str, str]) -> dict[str, str]:
    """A tag's text fields under their Cypher parameter names (camel case)."""
    return {
        "robot": fields["robot"],
        "activity": fields["activity"],
        "lifecycle": fields["lifecycle"],
        "msgId": fields["msg_id"],
        "msgRole": fields["msg_role"],
        "payload": fields["payload"],
    }
