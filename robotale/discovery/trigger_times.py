"""When the timers that start event sub-processes fired, as the log has it.

A driving model's timer attached to an activity (an interrupting boundary timer: the scout
gives up exploring after 30 s, a worker gives up driving after 10 s) is discovered as an event
sub-process triggered by the timer's tag. The engine's event sub-process timers count from
the start of the process instance, not of an activity, so the discovered sub-process gets a
timer start event whose duration is what the log records: the mean time from the start of
the robot's instance (its trace, or the message that started it for a pool started on a
signal) to the timer's tag.
"""

from __future__ import annotations

import pandas as pd

from robotale.discovery.binding import Bindings
from robotale.discovery.collaboration import Collaboration
from robotale.discovery.filters import LogFilter
from robotale.discovery.instances import START_TIMESTAMP
from robotale.discovery.signal_starts import selected_instances
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT, ROBOT_TYPE


def timed_triggers(
    collaboration: Collaboration,
    log: pd.DataFrame,
    bindings: Bindings,
    selection: LogFilter | None = None,
) -> dict[tuple[str, str], float]:
    """(pool, trigger) -> mean seconds from an instance's start to the trigger, for each
    handler whose trigger the driving model binds to a timer."""
    wanted = {
        (pool.name, handler.trigger)
        for pool in collaboration.pools
        for handler in pool.handlers
        if bindings.is_timer(pool.name, handler.trigger)
    }
    if not wanted:
        return {}
    instances = selected_instances(log, selection)
    found = {}
    for pool in collaboration.pools:
        mine = instances[instances[ROBOT_TYPE] == pool.name]
        for trigger in sorted(t for p, t in wanted if p == pool.name):
            delays = _delays(mine, trigger, pool.starts_on)
            if delays:
                found[(pool.name, trigger)] = sum(delays) / len(delays)
    return found


def _delays(instances: pd.DataFrame, trigger: str, starts_on: str | None) -> list[float]:
    delays = []
    for _, trace in instances.groupby([CASE, ROBOT], sort=False):
        labels = trace[ACTIVITY].astype(str).tolist()
        starts = trace[START_TIMESTAMP].tolist()
        begun = starts[0]
        for label, start in zip(labels, starts, strict=True):
            if starts_on is not None and label == starts_on:
                begun = start
            elif label == trigger:
                delays.append((start - begun).total_seconds())
    return delays
