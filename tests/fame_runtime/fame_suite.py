"""Running the models of the semantics suite and reading their tags."""

from pathlib import Path

from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.tags import ABORT

MODELS = Path(__file__).resolve().parent / "models"

#: how a refusal of a user or manual task ends: what robotale runs instead
PERSON = (
    " (robotale runs a task, script task, send or receive task, or a call activity bound to a "
    "skill)"
)


def trace(tags, *, messages: bool = False, aborts: bool = False) -> list[tuple]:
    """Tags as (time, robot, activity, lifecycle[, msg_id, msg_role]) tuples.

    The ``ate_abort`` tags that end interrupted and cancelled activities are left out unless
    ``aborts``: the semantics tests follow the tokens, test_aborts.py checks those tags.
    """
    tags = [t for t in tags if aborts or t.lifecycle != ABORT]
    if messages:
        return [(t.stamp, t.robot, t.activity, t.lifecycle, t.msg_id, t.msg_role) for t in tags]
    return [(t.stamp, t.robot, t.activity, t.lifecycle) for t in tags]


def pair(time, robot, activity) -> list[tuple]:
    """The start and complete tags of an instant activity or event."""
    return [(time, robot, activity, "start"), (time, robot, activity, "complete")]


def of(tags, robot: str) -> list[tuple]:
    """One robot's trace."""
    return [t for t in trace(tags) if t[1] == robot]


def build(model, *, robots=None, skills=None, variables=None, latency=0.0, start=0.0, **kw):
    """A mission of a suite model on a fresh clock and in-process bus: (mission, tags)."""
    from robotale.fame_runtime.bus import InProcessBus
    from robotale.fame_runtime.clock import SimClock

    tags: list = []
    clock = SimClock(start)
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
    return mission, tags


def run(model, *, until=None, **kw):
    """Run a suite model until the mission is done (or ``until``): (mission, tags)."""
    mission, tags = build(model, **kw)
    mission.run(until=until)
    return mission, tags
