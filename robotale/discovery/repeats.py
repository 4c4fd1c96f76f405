"""Activities a robot repeats the same number of times whenever it repeats them.

The inductive miner makes a loop of an activity done several times in a row, and a loop
drawn at random repeats it any number of times. Where the log shows the same count every
time (a worker cuts three times per weed: a loop with a maximum, or a multi-instance activity
of the driving model), the discovered activity is a sequential multi-instance activity of
that count instead, which repeats it exactly so.

A loop of several steps in a row (a coordinator asks, waits in vain and counts the try, three
times; it takes the next task, asks and gets the answer, until the third task) that always
went round the same number of times is written out that many times in sequence: the driving
model's counters (``tries < 3``) are not in the log, their effect is.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping

import pandas as pd

from robotale.discovery.collaboration import Collaboration
from robotale.discovery.filters import LogFilter
from robotale.discovery.layout import Block, Leaf, Operator, Tau, leaves, simplify
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
    rounds = {pool.name: steps_loops(pool.block) for pool in collaboration.pools}
    if not looped and not any(rounds.values()):
        return {}
    instances = selected_instances(log, selection)
    runs: dict[tuple[str, str], set[int]] = {}
    for (kind, _, _), trace in instances.groupby([ROBOT_TYPE, CASE, ROBOT], sort=False):
        labels = trace[ACTIVITY].astype(str).tolist()
        for label, group in itertools.groupby(labels):
            if (str(kind), label) in looped:
                runs.setdefault((str(kind), label), set()).add(sum(1 for _ in group))
        for loop in rounds[str(kind)]:
            body, redo = _steps(loop)
            found = _rounds(labels, body, redo)
            if not found and set(body) <= set(labels):
                # the trace did the loop's steps, never in a row: it went round in another
                # order (steps interleaved), so no count holds for every trace
                found = [0]
            for times in found:
                runs.setdefault((str(kind), loop_key(loop)), set()).add(times)
    return {key: next(iter(n)) for key, n in runs.items() if len(n) == 1 and min(n) > 1}


def steps_loops(block: Block) -> list[Operator]:
    """The loops of ``block`` whose body and redo part are steps in a row (no choice, no
    parallelism, no inner loop), other than a loop of one activity alone."""
    if not isinstance(block, Operator):
        return []
    if block.kind == "loop" and not _alone(block) and all(map(_in_a_row, block.children)):
        return [block]
    return [loop for child in block.children for loop in steps_loops(child)]


def loop_key(loop: Operator) -> str:
    """The name a loop of steps is repeated under: its body and redo part (no activity label
    has the arrow)."""
    body, redo = _steps(loop)
    return f"\u21bb {' '.join(body)} / {' '.join(redo)}"


def _in_a_row(block: Block) -> bool:
    if isinstance(block, Operator):
        return block.kind == "seq" and all(isinstance(c, Leaf) for c in block.children)
    return True


def _steps(loop: Operator) -> tuple[list[str], list[str]]:
    redo = loop.children[1] if len(loop.children) > 1 else Tau()
    return leaves(loop.children[0]), leaves(redo)


def _rounds(labels: list[str], body: list[str], redo: list[str]) -> list[int]:
    """How many times the body ran in each run of the loop in ``labels``: each place the
    body's steps come in a row, followed by redo and body again as long as they come."""
    found = []
    again = redo + body
    position = 0
    while position < len(labels):
        if labels[position : position + len(body)] != body:
            position += 1
            continue
        times, position = 1, position + len(body)
        while labels[position : position + len(again)] == again:
            times, position = times + 1, position + len(again)
        found.append(times)
    return found


def unrolled(block: Block, repeats: Mapping[str, int]) -> Block:
    """``block`` with each loop of steps that ``repeats`` names written out its number of
    times in sequence (body, redo, body ...)."""
    if not isinstance(block, Operator):
        return block
    times = repeats.get(loop_key(block)) if block.kind == "loop" else None
    if times is not None:
        body, redo = block.children[0], block.children[1]
        return simplify(Operator("seq", [body, *[redo, body] * (times - 1)]))
    return Operator(block.kind, [unrolled(child, repeats) for child in block.children])


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
