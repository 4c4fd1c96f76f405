"""Breadth-first exploration of the collaboration's states, and what is wrong in them.

Every state is reached first by a shortest sequence of steps, so the trace kept for each
finding (the tags of those steps) is a shortest one. After the exploration the graph of states
is read backwards to find the states from which a robot can no longer finish.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from robotale.fame_runtime.kinds import EventKind, Kind, Run
from robotale.fame_runtime.plan import FlowPlan, NodePlan
from robotale.fame_runtime.tags import Tag
from robotale.fame_runtime.verify.registry import ElementKey, element_key
from robotale.fame_runtime.verify.space import ASSUMED, Space
from robotale.fame_runtime.verify.state import (
    Choices,
    Decision,
    NeedChoice,
    Outcome,
    Robot,
    State,
    scopes,
)
from robotale.fame_runtime.verify.step import Step
from robotale.fame_runtime.verify.values import UNKNOWN

#: what a loop without exit that never waits adds to its sentence
BUSY = " without ever waiting (the engine stops it with a model error after 1,000,000 steps)"
#: the kinds of finding, in the order a report lists them
KINDS = ("deadlock", "no_exit", "lost_signal", "never_fires", "unreachable", "uncaught", "stuck")


@dataclass
class Finding:
    kind: str  # one of KINDS
    sentence: str
    robot: str = ""
    elements: list[str] = field(default_factory=list)  # element ids to highlight
    trace: list[Tag] = field(default_factory=list)

    def as_dict(self) -> dict[str, object]:
        return {
            "kind": self.kind,
            "robot": self.robot,
            "sentence": self.sentence,
            "elements": self.elements,
            "trace": [
                {
                    "step": int(t.stamp),
                    "robot": t.robot,
                    "activity": t.activity,
                    "lifecycle": t.lifecycle,
                    "msg_id": t.msg_id,
                    "msg_role": t.msg_role,
                }
                for t in self.trace
            ],
        }


@dataclass
class Exploration:
    """The explored graph: states, for each its shortest way in, and its steps out."""

    space: Space
    states: list[State] = field(default_factory=list)
    index: dict[State, int] = field(default_factory=dict)
    parent: list[tuple[int, Outcome] | None] = field(default_factory=list)
    edges: list[list[tuple[int, Outcome]]] = field(default_factory=list)
    waiting: dict[int, list[str]] = field(default_factory=dict)  # deadlocks: who waits
    reached: set[ElementKey] = field(default_factory=set)
    fired: set[ElementKey] = field(default_factory=set)
    first_armed: dict[ElementKey, int] = field(default_factory=dict)  # state it is armed in
    firsts: dict[tuple[Any, ...], tuple[int, Outcome, NodePlan]] = field(default_factory=dict)
    frontier: set[int] = field(default_factory=set)  # not expanded (a bound was hit)
    bound: str = ""
    capped: bool = False  # some step left a catcher out (TOKEN_CAP, INSTANCE_CAP)
    steps: int = 0
    seconds: float = 0.0

    def add(self, state: State, parent: tuple[int, Outcome] | None) -> int:
        found = self.index.get(state)
        if found is not None:
            return found
        self.index[state] = len(self.states)
        self.states.append(state)
        self.parent.append(parent)
        self.edges.append([])
        return len(self.states) - 1

    def trace(self, state: int) -> list[Tag]:
        """The tags of the shortest sequence of steps to ``state``."""
        parts = []
        while (link := self.parent[state]) is not None:
            state, outcome = link
            parts.append(outcome.tags)
        return [tag for tags in reversed(parts) for tag in tags]


def explore(space: Space, *, max_states: int, timeout: float) -> Exploration:
    """Every state reachable from the start, breadth first, until ``max_states`` states or
    ``timeout`` seconds."""
    began = time.perf_counter()
    graph = Exploration(space)
    graph.add(space.initial(), None)
    depth = [0]
    queue = deque([0])
    while queue:
        if len(graph.states) >= max_states:
            graph.bound = f"--max-states {max_states} reached"
        elif time.perf_counter() - began > timeout:
            graph.bound = f"--timeout {timeout:g} s reached"
        if graph.bound:
            graph.frontier = set(queue)
            break
        current = queue.popleft()
        for outcome in _successors(space, graph.states[current], depth[current] + 1, graph):
            graph.steps += 1
            before = len(graph.states)
            target = graph.add(outcome.state, (current, outcome))
            if len(graph.states) > before:
                depth.append(depth[current] + 1)
                queue.append(target)
            graph.edges[current].append((target, outcome))
            _note(graph, current, outcome)
    graph.seconds = time.perf_counter() - began
    return graph


def _successors(space: Space, state: State, stamp: int, graph: Exploration) -> Iterator[Outcome]:
    robots = space.thaw(state)
    events = space.events(robots)
    if not events:
        blocked = [_waits(robot) for robot in robots if robot.instances]
        if blocked:
            graph.waiting[graph.index[state]] = [w for ws in blocked for w in ws]
        return
    for number in range(len(events)):
        pending: list[tuple[int, ...]] = [()]
        while pending:
            answers = pending.pop()
            step = Step(space, state, Choices(answers), float(stamp))
            try:
                yield step.run(space.event(step.robots, number))
            except NeedChoice as need:
                pending += [(*answers, option) for option in range(need.options)]


def _note(graph: Exploration, source: int, outcome: Outcome) -> None:
    """Keep what a step shows: elements reached and armed, signals lost, errors uncaught."""
    graph.reached |= outcome.reached
    graph.capped |= outcome.capped
    graph.fired |= outcome.fired
    for key in outcome.armed:
        graph.first_armed.setdefault(key, source)
    for robot, node, topic in outcome.lost:
        graph.firsts.setdefault(("lost", robot, element_key(node), topic), (source, outcome, node))
    for kind, robot, node, sentence in outcome.failures:
        graph.firsts.setdefault((kind, robot, sentence), (source, outcome, node))


def _waits(robot: Robot) -> list[str]:
    """What each token of a blocked robot waits for, one phrase each."""
    phrases = []
    for scope in scopes(robot):
        for token in scope.tokens:
            node = token.node
            if token.child is not None:
                continue
            phrases.append(f"{robot.name} waits at {_describe(node)}{_for(node, token.waiting)}")
    return phrases


def _describe(node: NodePlan) -> str:
    return f"{node.node.kind} {node.node.describe()}"


def _for(node: NodePlan, waiting: str) -> str:
    if waiting == "join":
        return " for tokens on all its incoming flows"
    trigger = node.trigger
    if trigger is not None and trigger.kind == EventKind.SIGNAL:
        return f" for signal {trigger.topic}"
    if trigger is not None and trigger.kind == EventKind.CONDITIONAL:
        return " for its condition, which never holds"
    if node.behaviour == Run.EVENT_BASED_GATEWAY:
        wanted = [f.target.trigger.topic for f in node.outgoing if f.target.trigger is not None]
        return f" for {', '.join(w for w in wanted if w)}"
    return ""


# -- findings ------------------------------------------------------------------------------------


def findings(graph: Exploration) -> list[Finding]:
    found: list[Finding] = []
    found += _deadlocks(graph)
    found += _no_exits(graph)
    found += _lost(graph)
    complete = not graph.bound
    if complete:
        found += _unreached(graph)
    found += _uncaught(graph)
    return sorted(found, key=lambda f: KINDS.index(f.kind))


def _deadlocks(graph: Exploration) -> list[Finding]:
    seen: set[tuple[str, ...]] = set()
    found = []
    for state in sorted(graph.waiting):
        phrases = tuple(graph.waiting[state])
        if phrases in seen:
            continue
        seen.add(phrases)
        robots = sorted({p.split(" ", 1)[0] for p in phrases})
        found.append(
            Finding(
                "deadlock",
                "deadlock: every robot still working waits for something nobody will do: "
                + "; ".join(phrases),
                robot=",".join(robots),
                elements=_waiting_elements(graph, state),
                trace=graph.trace(state),
            )
        )
    return found


def _waiting_elements(graph: Exploration, state: int) -> list[str]:
    robots = graph.space.thaw(graph.states[state])
    return sorted(
        {t.node.node.id for r in robots for s in scopes(r) for t in s.tokens if t.child is None}
    )


def _no_exits(graph: Exploration) -> list[Finding]:
    """For each robot, the first state (breadth first) from which it can never finish, though
    it keeps moving: a loop without exit."""
    reverse: list[list[int]] = [[] for _ in graph.states]
    for source, edges in enumerate(graph.edges):
        for target, _ in edges:
            reverse[target].append(source)
    to_deadlock = _backwards(reverse, set(graph.waiting))
    found = []
    for position, (name, _) in enumerate(graph.space.robots):
        goals = {
            i
            for i, state in enumerate(graph.states)
            if state[position][0] and not state[position][1]
        }
        can_end = _backwards(reverse, goals | graph.frontier)
        for state, frozen in enumerate(graph.states):
            if frozen[position][1] and state not in can_end and state not in to_deadlock:
                found.append(_no_exit(graph, name, state))
                break
    return found


def _backwards(reverse: list[list[int]], goals: set[int]) -> set[int]:
    seen = set(goals)
    stack = list(goals)
    while stack:
        for source in reverse[stack.pop()]:
            if source not in seen:
                seen.add(source)
                stack.append(source)
    return seen


def _no_exit(graph: Exploration, robot: str, state: int) -> Finding:
    region = _forwards(graph, state)
    decisions = [
        d
        for s in region
        for _, outcome in graph.edges[s]
        for d in outcome.decisions
        if d.robot == robot
    ]
    closed = _closed_gateways(decisions)
    loop: list[Outcome] = []
    for candidate in sorted(region)[:500]:  # a state of the region on a loop through them
        found = _cycle(graph, candidate, region)
        through = any(d.node in closed for o in found for d in o.decisions if d.robot == robot)
        if found and (through or not closed or not loop):
            loop, state = found, candidate
            if through or not closed:
                break
    after = max((t.stamp for t in graph.trace(state)), default=0.0)
    tags = _restamp([t for o in loop for t in o.tags], after)
    labels = list(dict.fromkeys(t.activity for t in tags if t.robot == robot))
    why = _why(decisions)
    busy = bool(loop) and all(o.urgent for o in loop)
    sentence = (
        f"robot {robot} can never finish: it goes round "
        f"{' -> '.join(labels) if labels else 'the same states'} for ever"
        + (BUSY if busy else "")
        + (f"; {why}" if why else "")
    )
    elements = sorted({d.node.node.id for d in decisions if d.node in closed})
    elements += sorted({k[1] for o in loop for k in o.reached} - set(elements))
    return Finding("no_exit", sentence, robot, elements, graph.trace(state) + tags)


def _forwards(graph: Exploration, state: int) -> set[int]:
    seen = {state}
    stack = [state]
    while stack:
        for target, _ in graph.edges[stack.pop()]:
            if target not in seen:
                seen.add(target)
                stack.append(target)
    return seen


def _cycle(graph: Exploration, state: int, region: set[int]) -> list[Outcome]:
    """The steps of a shortest way from ``state`` back to it (one round of the loop)."""
    back: dict[int, tuple[int, Outcome]] = {}
    queue = deque([state])
    seen = {state}
    while queue:
        current = queue.popleft()
        for target, outcome in graph.edges[current]:
            if target == state:
                steps = [outcome]
                while current != state:
                    current, step = back[current]
                    steps.append(step)
                return steps[::-1]
            if target in region and target not in seen:
                seen.add(target)
                back[target] = (current, outcome)
                queue.append(target)
    return []


def _closed_gateways(decisions: list[Decision]) -> list[NodePlan]:
    """Gateways that, in these decisions, never take some outgoing flow."""
    taken: dict[int, set[str]] = {}
    nodes: dict[int, NodePlan] = {}
    for decision in decisions:
        taken.setdefault(id(decision.node), set()).update(decision.taken)
        nodes[id(decision.node)] = decision.node
    return [
        node for key, node in nodes.items() if any(f.id not in taken[key] for f in node.outgoing)
    ]


def _restamp(tags: list[Tag], after: float) -> list[Tag]:
    """Tags of steps after the trace's end, numbered on from it."""
    if not tags:
        return []
    stamps = sorted({t.stamp for t in tags})
    number = {stamp: after + i + 1 for i, stamp in enumerate(stamps)}
    return [
        Tag(number[t.stamp], t.robot, t.activity, t.lifecycle, t.msg_id, t.msg_role) for t in tags
    ]


def _loop_elements(graph: Exploration, region: set[int], robot: str) -> set[str]:
    return {
        key[1]
        for s in region
        for _, outcome in graph.edges[s]
        for key in outcome.reached
        if any(t.robot == robot for t in outcome.tags)
    }


def _why(decisions: list[Decision]) -> str:
    """Which gateways never open their way out, and what they read."""
    reasons = []
    by_node: dict[int, list[Decision]] = {}
    for decision in decisions:
        by_node.setdefault(id(decision.node), []).append(decision)
    for group in by_node.values():
        node = group[0].node
        taken = {flow for d in group for flow in d.taken}
        never = [f for f in node.outgoing if f.id not in taken]
        if not never:
            continue
        names = ", ".join(_flow_name(f) for f in never)
        reads = {r for d in group for r in d.reads}
        read_text = "; ".join(_read(r) for r in sorted(reads, key=str))
        reasons.append(
            f"{_describe(node)} never takes {names}"
            + (f": it reads {read_text}" if read_text else "")
        )
    return "; ".join(reasons)


def _flow_name(flow: FlowPlan) -> str:
    name = next(
        (f.name for f in flow.target.scope.process.flows.values() if f.id == flow.id and f.name),
        "",
    )
    return f"{flow.id} ({name})" if name else flow.id


def _read(read: tuple[str, Any, str, bool]) -> str:
    name, value, setter, same_step = read
    if value is UNKNOWN:
        return f"{name} (unknown)"
    shown = _shown(value)
    if not setter:
        return f"{name} = {shown}"
    if setter.startswith(ASSUMED):
        where = setter.removeprefix(ASSUMED)
        return f"{name} = {shown}, as {where} found it before, and nothing has set it since"
    when = (
        " in the same step, with no wait between, so no callback can change it first"
        if same_step
        else ""
    )
    return f"{name} = {shown}, set by {setter}{when}"


def _shown(value: object) -> str:
    """A value as a model writes it (``1`` is not ``true``, though Python finds them equal)."""
    if value is True or value is False or value is None:
        return {True: "true", False: "false", None: "null"}[value]
    return repr(value)


def _lost(graph: Exploration) -> list[Finding]:
    found = []
    for key, (source, outcome, node) in graph.firsts.items():
        if key[0] != "lost":
            continue
        _, robot, _, topic = key
        found.append(
            Finding(
                "lost_signal",
                f"robot {robot} throws signal {topic} at {_describe(node)} when no robot "
                "waits for it: nobody catches it",
                robot,
                [node.node.id],
                graph.trace(source) + outcome.tags,
            )
        )
    return found


def _uncaught(graph: Exploration) -> list[Finding]:
    return [
        Finding(key[0], key[2], key[1], [node.node.id], graph.trace(source) + outcome.tags)
        for key, (source, outcome, node) in graph.firsts.items()
        if key[0] in ("uncaught", "stuck")
    ]


def _unreached(graph: Exploration) -> list[Finding]:
    """Catches armed but never fired, and elements no token ever reached."""
    found = []
    seen: set[ElementKey] = set()
    for node in graph.space.registry.nodes:
        key = element_key(node)
        if key in seen or node.behaviour == Run.EVENT_SUBPROCESS:
            continue
        catching = node.trigger is not None and node.behaviour != Run.SKILL
        if (key in graph.fired) or (key in graph.reached and not catching):
            continue
        seen.add(key)
        if catching and (key in graph.first_armed or _always_armed(node)):
            state = graph.first_armed.get(key, 0)
            found.append(
                Finding(
                    "never_fires",
                    f"{_describe(node)} of {node.scope.process.describe()} never fires: "
                    f"{_never_because(node)}",
                    elements=[node.node.id],
                    trace=graph.trace(state),
                )
            )
        else:
            found.append(
                Finding(
                    "unreachable",
                    f"{_describe(node)} of {node.scope.process.describe()} is never reached",
                    elements=[node.node.id],
                )
            )
    return found


def _always_armed(node: NodePlan) -> bool:
    """Start events of a process or event sub-process wait as long as it runs."""
    return node.node.kind == Kind.START_EVENT


def _never_because(node: NodePlan) -> str:
    trigger = node.caught
    if trigger.kind == EventKind.SIGNAL:
        return f"no robot throws signal {trigger.topic} while it waits"
    if trigger.kind == EventKind.CONDITIONAL:
        return "its condition never holds while it waits"
    if trigger.kind == EventKind.ERROR:
        return f"no error {trigger.topic or ''} is thrown where it catches".replace("  ", " ")
    return f"nothing {trigger.kind} reaches it while it waits"
