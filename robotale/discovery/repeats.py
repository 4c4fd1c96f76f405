"""Activities a robot repeats the same number of times whenever it repeats them.

The inductive miner makes a loop of an activity done several times in a row, and a loop
drawn at random repeats it any number of times. Where the log shows the same count every
time (a worker cuts three times per weed: a loop with a maximum, or a multi-instance activity
of the driving model), the discovered activity is a sequential multi-instance activity of
that count instead, which repeats it exactly so.
"""

from __future__ import annotations

import itertools

import pandas as pd

from robotale.discovery.collaboration import Collaboration
from robotale.discovery.filters import LogFilter
from robotale.discovery.layout import Block, Leaf, Operator, Tau
from robotale.discovery.signal_starts import selected_instances
from robotale.eventlog.schema import ACTIVITY, CASE, ROBOT, ROBOT_TYPE


def constant_repeats(
    collaboration: Collaboration, log: pd.DataFrame, selection: LogFilter | None = None
) -> dict[tuple[str, str], int]:
    """(pool, activity) -> how many times in a row its robots did it, for each activity of
    a pool's process that is a loop of itself alone and always ran that many times in a row
    (at least twice)."""
    looped = {
        (pool.name, label) for pool in collaboration.pools for label in self_loops(pool.block)
    }
    if not looped:
        return {}
    instances = selected_instances(log, selection)
    runs: dict[tuple[str, str], set[int]] = {}
    for (kind, _, _), trace in instances.groupby([ROBOT_TYPE, CASE, ROBOT], sort=False):
        for label, group in itertools.groupby(trace[ACTIVITY].astype(str)):
            if (str(kind), label) in looped:
                runs.setdefault((str(kind), label), set()).add(sum(1 for _ in group))
    return {key: next(iter(n)) for key, n in runs.items() if len(n) == 1 and min(n) > 1}


def self_loops(block: Block) -> list[str]:
    """The activities that ``block`` repeats alone: a loop of one activity, nothing to redo."""
    if not isinstance(block, Operator):
        return []
    if _alone(block):
        return [block.children[0].label]
    return [label for child in block.children for label in self_loops(child)]


def once(block: Block, labels: set[str]) -> Block:
    """``block`` with the self-loops of ``labels`` made single activities (the activity
    repeats itself as a multi-instance one)."""
    if not isinstance(block, Operator):
        return block
    if _alone(block) and block.children[0].label in labels:
        return block.children[0]
    return Operator(block.kind, [once(child, labels) for child in block.children])


def _alone(block: Operator) -> bool:
    """Whether ``block`` is a loop of one activity with nothing to redo."""
    return (
        block.kind == "loop"
        and isinstance(block.children[0], Leaf)
        and all(isinstance(c, Tau) for c in block.children[1:])
    )
