"""A robot's BPMN process as a Petri net whose labels are the activities its tags carry.

Labels are the engine's tags (:func:`robotale.fame_runtime.labels.element_label`): an activity
is tagged with its name, a signal throw with ``<signal>!`` and a catch with ``<signal>?``, an
error with its name. Events of other kinds (timers, conditions, none events) are tagged by
some sources and not by others, so they are visible only when the robot's log contains their
label; otherwise they are silent.

The translation follows BPMN's token semantics where a place/transition net can:

- a sequence flow is a place; an activity or event with several incoming flows starts once
  per token (uncontrolled merge); several outgoing flows all get a token (a parallel split),
  or any non-empty subset of them when they carry conditions;
- exclusive and event-based gateways choose one flow, parallel gateways split and join all,
  inclusive gateways any non-empty subset;
- a process whose start events wait for a trigger (a signal start, as the agricultural
  tractors' ``weed_position``) starts a new instance every time one fires, as does an event
  sub-process while its parent runs; a process with a none start event runs once;
- the net has no end place: a process is finished when no token is left (its final marking is
  empty), so branches may end at different end events;
- an activity with a loop marker is tagged once per pass: a multi-instance one of a written
  cardinality (and no completion condition) is that many steps in a row, any other marker
  repeats it at will;
- a sub-process or a resolved call activity is expanded in place; it completes when one of its
  end events is reached (a branch still running inside it may finish later);
- terminate end events, interrupting event sub-processes and interrupting boundary events on
  a sub-process cancel the scope: silent transitions drain its tokens first.

Two over-approximations remain, and say so here so nobody relies on them: an event sub-process
may start even when its parent is not running, and an inclusive join may fire before every
branch that could reach it has done so.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from robotale.fame_runtime.kinds import ACTIVITIES, EventKind, Kind
from robotale.fame_runtime.labels import element_label

CHOICE_GATEWAYS = frozenset({Kind.EXCLUSIVE_GATEWAY, Kind.EVENT_BASED_GATEWAY})
SUBSET_GATEWAYS = frozenset({Kind.INCLUSIVE_GATEWAY, Kind.COMPLEX_GATEWAY})
MAX_SUBSET_BRANCHES = 6  # 63 transitions: beyond that a gateway is modelled as a choice

#: finds the process a call activity calls (``None`` when it is a skill or unknown).
Resolver = Callable[[str], Any]


@dataclass
class _Scope:
    """The places a scope's cancellation must drain, and where its end events lead."""

    done: Any | None  # None at the top level: an end event just removes its token
    places: list[Any] = field(default_factory=list)
    cancel: Any | None = None


def process_net(
    process: Any,
    observed: set[str] | frozenset[str] = frozenset(),
    resolve: Resolver | None = None,
) -> tuple[Any, Any, Any]:
    """The Petri net, initial marking and (empty) final marking of ``process``.

    ``observed`` are the activity labels in the robot's log (they decide which events are
    visible); ``resolve`` finds the process a call activity calls.
    """
    builder = _Builder(observed, resolve or (lambda _name: None))
    return builder.build(process)


class _Builder:
    def __init__(self, observed, resolve: Resolver) -> None:
        # pm4py is imported here, when a net is built, not with the module: importing it takes
        # over 2 s and prints a banner, and whatever imports robotale.discovery (commands, the
        # dashboard) imports this module. Its parts are kept for the methods below.
        from pm4py.objects.petri_net.obj import Marking, PetriNet
        from pm4py.objects.petri_net.utils.petri_utils import add_arc_from_to, remove_transition
        from pm4py.objects.petri_net.utils.reduction import apply_simple_reduction

        self.Place, self.Transition, self.Marking = PetriNet.Place, PetriNet.Transition, Marking
        self.add_arc, self.remove_transition = add_arc_from_to, remove_transition
        self.reduce = apply_simple_reduction
        self.net = PetriNet("process")
        self.initial = Marking()
        self.observed = set(observed)
        self.merged: set[str] = set()  # event sub-process starts translated before it
        self.resolve = resolve
        self.counter = itertools.count()
        self.calling: list[str] = []  # call activities being expanded (stops recursion)
        self.cancellations: list[tuple[list, Any, list]] = []  # drained after reduction

    def build(self, process):
        self.scope(process, _Scope(done=None), entry=None)
        # Silent steps that only pass a token on are merged away: every silent step is a
        # state more for the alignment search, and the language stays the same. Drains come
        # after, for the places that remain (a drain on a place would keep it from merging);
        # the places a cancellation ends in are held in place meanwhile.
        holds = [
            self.transition("hold", "hold", inputs=[place])
            for _, _, after in self.cancellations
            for place in after
        ]
        self.reduce(self.net)
        for hold in holds:
            self.remove_transition(self.net, hold)
        for places, signal, after in self.cancellations:
            self.drain([p for p in places if p in self.net.places], signal, after)
        return self.net, self.initial, self.Marking()

    # -- places, transitions, arcs -------------------------------------------------------------

    def place(self, scope: _Scope, name: str):
        place = self.Place(f"{name}#{next(self.counter)}")
        self.net.places.add(place)
        scope.places.append(place)
        return place

    def transition(self, name: str, label: str | None, inputs=(), outputs=()):
        transition = self.Transition(f"{name}#{next(self.counter)}", label)
        self.net.transitions.add(transition)
        for place in inputs:
            self.add_arc(place, transition, self.net)
        for place in outputs:
            self.add_arc(transition, place, self.net)
        return transition

    # -- scopes ----------------------------------------------------------------------------------

    def scope(self, content, scope: _Scope, entry, entries=None) -> None:
        """Translate the nodes and flows of a process or sub-process.

        ``entry`` is the place a token enters the scope through; ``entries`` gives start
        events their own (an event sub-process's triggers). Without either (the top level) a
        none start event gets the initial token and a triggered start needs none.
        """
        flows = {fid: self.place(scope, f"flow_{fid}") for fid in content.flows}
        incoming = _by(content.flows.values(), "target")
        outgoing = _by(content.flows.values(), "source")
        attached = _by(
            (n for n in content.nodes.values() if n.kind == Kind.BOUNDARY_EVENT), "attached_to"
        )
        for node in content.nodes.values():
            ins = [flows[f.id] for f in incoming.get(node.id, [])]
            outs = [flows[f.id] for f in outgoing.get(node.id, [])]
            conditional = any(f.condition is not None for f in outgoing.get(node.id, []))
            if node.kind == Kind.START_EVENT:
                self.start(node, scope, (entries or {}).get(node.id, entry), outs)
            elif node.kind == Kind.BOUNDARY_EVENT:
                continue  # translated with the activity it is attached to
            elif node.kind == Kind.SUB_PROCESS and node.triggered_by_event:
                self.event_subprocess(node, scope)
            elif node.kind in ACTIVITIES or node.kind not in _EVENT_AND_GATEWAY_KINDS:
                ready = self.merge(scope, node.id, ins, entry)
                boundaries = [
                    (b, [flows[f.id] for f in outgoing.get(b.id, [])])
                    for b in attached.get(node.id, [])
                ]
                done = self.activity(node, scope, ready, boundaries)
                self.split(scope, node.id, done, outs, conditional)
            else:
                self.flow_node(node, scope, entry, ins, outs, conditional)
        if scope.cancel is not None:
            after = [scope.done] if scope.done else []
            self.cancellations.append((scope.places, scope.cancel, after))

    def event_subprocess(self, node, parent: _Scope) -> None:
        """An event sub-process starts each time one of its start events' triggers fires:
        the trigger is tagged first, then the sub-process under its own name (the engine's
        order); an interrupting one cancels its parent scope."""
        inner = _Scope(done=None)
        entries = {}
        label = element_label(node)
        for start in (n for n in node.scope.nodes.values() if n.kind == Kind.START_EVENT):
            entries[start.id] = self.place(inner, f"triggered_{start.id}")
            cancels = [self.cancel(parent)] if start.interrupting else []
            trigger = self.event_label(start)
            if trigger is None:
                # an untagged trigger: the sub-process' own tag is the first sign of it
                self.transition(f"esp_{node.id}", label, [], [entries[start.id], *cancels])
                continue
            # the start event is translated here, before its sub-process; in the scope below
            # it only passes the token on
            self.merged.add(start.id)
            if label not in self.observed:
                # a source that does not tag the sub-process itself (the thesis' log) tags
                # only its trigger
                self.transition(f"esp_{node.id}", trigger, [], [entries[start.id], *cancels])
                continue
            caught = self.place(inner, f"caught_{start.id}")
            self.transition(f"catch_{start.id}", trigger, [], [caught, *cancels])
            self.transition(f"esp_{node.id}", label, [caught], [entries[start.id]])
        self.scope(node.scope, inner, entry=None, entries=entries)

    def flow_node(self, node, scope: _Scope, entry, ins, outs, conditional: bool) -> None:
        """End events, gateways and intermediate events."""
        kind = node.kind
        if kind == Kind.END_EVENT:
            self.end(node, scope, ins)
        elif kind == Kind.PARALLEL_GATEWAY:
            self.transition(f"and_{node.id}", None, ins, outs)
        elif kind in SUBSET_GATEWAYS:
            joined = self.place(scope, f"or_{node.id}")
            for subset in _subsets(ins):
                self.transition(f"or_join_{node.id}", None, subset, [joined])
            for subset in _subsets(outs):
                self.transition(f"or_split_{node.id}", None, [joined], subset)
        elif kind in CHOICE_GATEWAYS:
            middle = self.merge(scope, node.id, ins, entry)
            for out in outs:
                self.transition(f"xor_{node.id}", None, [middle], [out])
        else:  # intermediate throw and catch events
            ready = self.merge(scope, node.id, ins, entry)
            done = self.place(scope, f"after_{node.id}")
            self.transition(node.id, self.event_label(node), [ready], [done])
            self.split(scope, node.id, done, outs, conditional)

    def start(self, node, scope: _Scope, entry, outs) -> None:
        label = None if node.id in self.merged else self.event_label(node)
        if entry is not None:
            self.transition(f"start_{node.id}", label, [entry], outs)
        elif node.event_kind == EventKind.NONE:
            source = self.place(scope, f"source_{node.id}")
            self.initial[source] = 1
            self.transition(f"start_{node.id}", label, [source], outs)
        else:
            # a triggered process start: one more instance each time its trigger fires. It
            # stays visible even if never tagged: a silent transition that can always fire
            # would let the alignment search wander without end.
            label = label or element_label(node)
            self.transition(f"start_{node.id}", label, [], outs)

    def end(self, node, scope: _Scope, ins) -> None:
        if node.event_kind == EventKind.TERMINATE:
            outputs = [self.cancel(scope)]
        else:
            outputs = [scope.done] if scope.done is not None else []
        for place in ins:
            self.transition(f"end_{node.id}", self.event_label(node), [place], outputs)

    def activity(self, node, scope: _Scope, ready, boundaries):
        """The activity's own visible transition, its content (sub-process, resolved call) and
        its boundary events; returns the place holding the token once it is done."""
        label = element_label(node)
        done = self.place(scope, f"done_{node.id}")
        content = self.content(node)
        if content is None:
            self.repeated(node, label, scope, ready, done)
            for boundary, outs in boundaries:  # it fired while the activity ran
                stays = [] if boundary.cancel_activity else [done]
                self.transition(boundary.id, self.event_label(boundary), [done], [*stays, *outs])
            return done
        inner = _Scope(done=self.place(scope, f"inner_done_{node.id}"))
        entry = self.place(inner, f"entry_{node.id}")
        active = self.place(scope, f"active_{node.id}")
        self.transition(node.id, label, [ready], [entry, active])
        self.calling.append(node.id)
        try:
            self.scope(content, inner, entry)
        finally:
            self.calling.pop()
        self.transition(f"complete_{node.id}", None, [inner.done, active], [done])
        for boundary, outs in boundaries:
            name, boundary_label = boundary.id, self.event_label(boundary)
            if boundary.cancel_activity:
                killed = self.place(scope, f"killed_{node.id}")
                self.transition(name, boundary_label, [active], [*outs, killed])
                self.cancellations.append(([*inner.places, inner.done], killed, []))
            else:
                self.transition(name, boundary_label, [active], [active, *outs])
        scope.places.extend(inner.places)
        return done

    def repeated(self, node, label: str, scope: _Scope, ready, done) -> None:
        """The activity's transition from ``ready`` to ``done``, as many times as its loop
        marker runs it: the engine tags each pass, so a multi-instance activity of a fixed
        cardinality (a discovered model's repeats, ``loopCardinality`` 3) is that many
        transitions in a row (parallel instances of an atomic step interleave to the same
        language); any other marker (a standard loop, a cardinality read from data) repeats it
        at will, none at all when it may test before the first pass."""
        loop = node.loop
        if loop is None:
            self.transition(node.id, label, [ready], [done])
            return
        times = _fixed_cardinality(loop)
        if times is not None:
            here = ready
            for _ in range(times - 1):
                after = self.place(scope, f"pass_{node.id}")
                self.transition(node.id, label, [here], [after])
                here = after
            self.transition(node.id, label, [here], [done])
            return
        self.transition(node.id, label, [ready], [done])
        self.transition(f"again_{node.id}", None, [done], [ready])
        if loop.test_before or loop.kind != "standard":
            self.transition(f"skip_{node.id}", None, [ready], [done])

    def content(self, node):
        if node.kind != Kind.CALL_ACTIVITY:
            return node.scope
        if node.embedded_process is not None:
            return node.embedded_process
        name = node.called_element
        if not name or name in self.calling:
            return None
        return self.resolve(name)

    # -- merges, splits, cancellations --------------------------------------------------------

    def merge(self, scope: _Scope, node_id: str, ins, entry):
        """One place holding a token for the node: its incoming flows merged (or the scope's
        entry, for a node nothing flows into)."""
        if len(ins) == 1:
            return ins[0]
        ready = self.place(scope, f"ready_{node_id}")
        if not ins and entry is not None:
            self.transition(f"enter_{node_id}", None, [entry], [ready])
        for place in ins:
            self.transition(f"merge_{node_id}", None, [place], [ready])
        return ready

    def split(self, scope: _Scope, node_id: str, done, outs, conditional: bool) -> None:
        if not outs:  # a node without outgoing flow ends its branch
            self.transition(f"finish_{node_id}", None, [done], [scope.done] if scope.done else [])
        elif conditional and len(outs) > 1:
            for subset in _subsets(outs):
                self.transition(f"or_{node_id}", None, [done], subset)
        else:
            self.transition(f"leave_{node_id}", None, [done], outs)

    def cancel(self, scope: _Scope):
        if scope.cancel is None:
            scope.cancel = self.place(scope, "cancel")
        return scope.cancel

    def drain(self, places, signal, after) -> None:
        """While ``signal`` holds a token any token in ``places`` may be removed; then the
        signal itself is consumed, producing ``after``."""
        for place in places:
            if place is not signal and place not in after:
                self.transition("drain", None, [place, signal], [signal])
        self.transition("drained", None, [signal], after)

    def event_label(self, node) -> str | None:
        """Signal and error events are always visible; other events only when tagged."""
        label = element_label(node)
        if node.event_kind in (EventKind.SIGNAL, EventKind.ERROR) or label in self.observed:
            return label
        return None


_EVENT_AND_GATEWAY_KINDS = frozenset(
    {
        Kind.START_EVENT,
        Kind.END_EVENT,
        Kind.INTERMEDIATE_THROW_EVENT,
        Kind.INTERMEDIATE_CATCH_EVENT,
        Kind.BOUNDARY_EVENT,
        Kind.PARALLEL_GATEWAY,
        *CHOICE_GATEWAYS,
        *SUBSET_GATEWAYS,
    }
)


def _fixed_cardinality(loop) -> int | None:
    """A multi-instance marker's cardinality when it is a whole number written out (at least
    1) and no completion condition may cut the passes short, else ``None``."""
    if loop.kind == "standard" or loop.cardinality is None or loop.collection or loop.condition:
        return None
    text = loop.cardinality.text.strip()
    return int(text) if text.isdigit() and int(text) >= 1 else None


def _by(items, attribute: str) -> dict[str, list]:
    grouped: dict[str, list] = {}
    for item in items:
        grouped.setdefault(getattr(item, attribute), []).append(item)
    return grouped


def _subsets(places: list) -> list[list]:
    if len(places) > MAX_SUBSET_BRANCHES:
        return [[p] for p in places]
    return [
        list(chosen)
        for size in range(1, len(places) + 1)
        for chosen in itertools.combinations(places, size)
    ]
