"""A message thrown and the wait that always follows it, mined as one step.

The inductive miner sees only which step follows which. A robot that asks and waits for the
answer (``ping!``, then ``pong?`` or, the answer lost, a timeout ``no_answer``) shows
``ping!`` followed by either, in loops the miner cannot cut (a retry goes back to the ask
from the middle of the loop); its fall-through then puts ``ping!`` in parallel with the rest,
and the discovered robot asks at any moment instead of waiting for each answer.

When the log always shows the throw and what comes right after it together (every throw of
the message is directly followed by a step, and each such step comes only right after the
throw), and one of those steps receives a message (the answer), each pair becomes one unit
for the miner (``ping!`` + ``pong?``, ``ping!`` + ``no_answer``), and each unit in the tree is
expanded back to the two steps in sequence. The units replay exactly the traces the steps
do, so the miner's fitness is kept; the throw is drawn once per step that follows it.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence

from robotale.discovery.layout import Block, Leaf, Operator, simplify
from robotale.eventlog.schema import RECEIVE, SEND

#: what joins a throw and its follower in a unit's label (no activity label holds it)
_JOIN = "\x1f"


def answered(traces: Sequence[Sequence[str]], roles: Mapping[str, str | None]) -> dict[str, str]:
    """Follower -> throw, for every throw that is always directly followed by one of steps
    that each come only directly after it, one of which is a received message."""
    # the distinct pairs of steps in a row, None at each trace's start and end, found by
    # pairwise and a set over all traces laid end to end (no Python loop per step)
    flat: list[str | None] = [None]
    for trace in traces:
        flat += trace
        flat.append(None)
    after: dict[str, set[str | None]] = {}  # each throw's followers (None: the trace ends)
    before: dict[str, set[str | None]] = {}  # each step's predecessors (None: trace start)
    for first, second in set(itertools.pairwise(flat)):
        if first is not None and roles.get(first) == SEND:
            after.setdefault(first, set()).add(second)
        if second is not None:
            before.setdefault(second, set()).add(first)
    found: dict[str, str] = {}
    for throw, followers in sorted(after.items()):
        if None in followers or throw in followers:
            continue
        steps = {step for step in followers if step is not None}
        if any(before[step] != {throw} or roles.get(step) == SEND for step in steps):
            continue
        if any(roles.get(step) == RECEIVE for step in steps):
            found.update(dict.fromkeys(steps, throw))
    return found


def as_units(traces: Sequence[Sequence[str]], pairs: Mapping[str, str]) -> list[list[str]]:
    """``traces`` with each throw of ``pairs`` and its follower made one unit."""
    united = []
    for trace in traces:
        steps: list[str] = []
        for label in trace:
            if label in pairs:  # always right after its throw, which is the last step kept
                steps[-1] = f"{steps[-1]}{_JOIN}{label}"
            else:
                steps.append(label)
        united.append(steps)
    return united


def expanded(block: Block) -> Block:
    """``block`` with every unit made its throw and follower in sequence."""
    if isinstance(block, Leaf) and _JOIN in block.label:
        return Operator("seq", [Leaf(part) for part in block.label.split(_JOIN)])
    if isinstance(block, Operator):
        return simplify(Operator(block.kind, [expanded(child) for child in block.children]))
    return block
