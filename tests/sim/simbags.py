"""Helpers of the simulation tests: run a world into a real rosbag2 and read it back with
rosbags."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from robotale.fame_runtime.manifest import MANIFEST
from robotale.fame_runtime.tags import register_tag_type
from robotale.sim.batch import run_into
from robotale.sim.run import RunPlan
from robotale.sim.worldspec import World


def full_batteries(world: World) -> World:
    """The world with every battery charged and slow to drain, so no low_battery interferes."""
    robots = tuple(
        replace(r, battery=replace(r.battery, level=(1.0, 1.0), drain=(0.0005, 0.0005)))
        for r in world.robots
    )
    return replace(world, robots=robots)


def record(world: World, folder: Path, *, seed: int = 1, index: int = 1, **options) -> Path:
    """Simulate run ``index`` of a batch with ``seed`` into ``folder``; its bag directory."""
    folder.mkdir(parents=True, exist_ok=True)
    plan = RunPlan(world, index, seed, world.file.stem, **options)
    run_into(plan, folder)
    return folder / plan.case


def manifest(bag: Path) -> dict:
    return json.loads((bag / MANIFEST).read_text(encoding="utf-8"))


def typestore():
    """ROS 2 Humble's types and the Tag, as any reader of robotale's bags sets them up."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    register_tag_type(store)
    return store


def messages(bag: Path, topics: set[str] | None = None) -> list[tuple[str, int, object]]:
    """(topic, timestamp ns, decoded message) of every message, in the bag's order."""
    store = typestore()
    with Reader(bag) as reader:
        chosen = [c for c in reader.connections if topics is None or c.topic in topics]
        return [
            (c.topic, t, store.deserialize_cdr(raw, c.msgtype))
            for c, t, raw in reader.messages(connections=chosen)
        ]


def tags(bag: Path) -> list:
    """Every tag of the run, in time order (robot order breaks ties as recorded)."""
    with Reader(bag) as reader:
        topics = {c.topic for c in reader.connections if c.topic.endswith("/tag")}
    found = [m for _, _, m in messages(bag, topics)]
    return sorted(found, key=lambda t: (t.stamp.sec, t.stamp.nanosec))


def seconds(tag) -> float:
    return tag.stamp.sec + tag.stamp.nanosec * 1e-9
