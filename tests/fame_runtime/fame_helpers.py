"""Helpers for the FAME runtime tests: run a model of the suite, read its tags."""

from pathlib import Path

from robotale.fame_runtime.mission import Mission

MODELS = Path(__file__).resolve().parent / "models"


def trace(tags, *, messages: bool = False) -> list[tuple]:
    """Tags as (time, robot, activity, lifecycle[, msg_id, msg_role]) tuples."""
    if messages:
        return [(t.stamp, t.robot, t.activity, t.lifecycle, t.msg_id, t.msg_role) for t in tags]
    return [(t.stamp, t.robot, t.activity, t.lifecycle) for t in tags]


def run(model, *, robots=None, skills=None, until=None, variables=None, latency=0.0, **kw):
    """Run a model of the suite on a fresh clock and in-process bus; returns (mission, tags)."""
    from robotale.fame_runtime.bus import InProcessBus
    from robotale.fame_runtime.clock import SimClock

    tags: list = []
    clock = SimClock()
    bus = InProcessBus(clock, latency=latency)
    path = model if isinstance(model, Path) else MODELS / model
    mission = Mission(
        path,
        robots=robots,
        clock=clock,
        bus=bus,
        skills=skills,
        library=kw.pop("library", MODELS / "library"),
        tag_sink=tags.append,
        variables=variables,
    )
    mission.run(until=until)
    return mission, tags
