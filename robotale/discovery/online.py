"""Online conformance: each robot's tags replayed on the Petri net of its pool as they
arrive. An activity's start fires the transition of its label, after any silent moves the
net allows (gateways, untagged events); a start the marking cannot reach is a deviation,
and the marking stays where it was (the tag is taken as a move of the log alone)."""

from __future__ import annotations

from collections import Counter, deque
from pathlib import Path
from typing import Any

from robotale.discovery.bpmn_net import process_net
from robotale.fame_runtime.library import find_process
from robotale.fame_runtime.parser import parse
from robotale.fame_runtime.splitter import split
from robotale.fame_runtime.tags import START, Tag

#: markings a search through silent moves looks at before it gives up
SEARCH_LIMIT = 2000

Marking = Counter


class PoolReplay:
    """One robot's place in its pool's net, moved by each activity start it is told of."""

    def __init__(self, pool: str, net: Any, initial: Any) -> None:
        self.pool = pool
        self.marking: Marking = Counter(dict(initial))
        self.labels = {t.label for t in net.transitions if t.label}
        self._transitions = list(net.transitions)

    def allows(self, tag: Tag) -> bool:
        """Move on with ``tag``; False when the model does not allow it here. Tags other
        than starts, and labels the net does not have (untagged events, a skill's own
        messages), say nothing about the model and are allowed."""
        return tag.lifecycle != START or self.allows_start(tag.activity)

    def allows_start(self, activity: str) -> bool:
        """Move on with a start of ``activity``; False when the model does not allow it
        here (a label the net does not have is allowed: it says nothing about the model)."""
        if activity not in self.labels:
            return True
        reached = self._reach(activity)
        if reached is None:
            return False
        self.marking = reached
        return True

    def _reach(self, label: str) -> Marking | None:
        """The marking after firing ``label``, through the fewest silent moves first."""
        queue: deque[Marking] = deque([self.marking])
        seen = {_key(self.marking)}
        while queue and len(seen) < SEARCH_LIMIT:
            marking = queue.popleft()
            for transition in self._transitions:
                if not _enabled(transition, marking):
                    continue
                after = _fire(transition, marking)
                if transition.label == label:
                    return after
                if transition.label is None and _key(after) not in seen:
                    seen.add(_key(after))
                    queue.append(after)
        return None


def pool_replays(model: Path, robots: list[str] | None) -> dict[str, PoolReplay]:
    """A replay for each robot the collaboration ``model`` binds among ``robots``."""
    definitions = parse(model)
    replays = {}
    for assignment in split(definitions, robots):
        net, initial, _ = process_net(
            assignment.process, resolve=lambda name: find_process(definitions, name)
        )
        replays[assignment.robot] = PoolReplay(assignment.robot_type, net, initial)
    return replays


def _enabled(transition: Any, marking: Marking) -> bool:
    return all(marking[arc.source] >= arc.weight for arc in transition.in_arcs)


def _fire(transition: Any, marking: Marking) -> Marking:
    after = Counter(marking)
    for arc in transition.in_arcs:
        after[arc.source] -= arc.weight
    for arc in transition.out_arcs:
        after[arc.target] += arc.weight
    return +after  # without the places left empty


def _key(marking: Marking) -> frozenset:
    return frozenset(marking.items())
