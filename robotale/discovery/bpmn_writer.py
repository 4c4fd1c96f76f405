"""A discovered collaboration as a BPMN 2.0 file with its diagram (BPMN DI).

The file is what a FAME designer would write (thesis 4.1.1): a participant per pool (with a
multiplicity where robots share it), each activity a call activity of the skill its name
says (``take_off`` calls ``TakeOff``), each message a signal throw or catch event, each
handler an event sub-process. Activities, signals and handlers carry what the log says about
them as ``documentation``: how often, by whom, how long. Choices are drawn at random when the
model runs (a Python condition on each branch of an exclusive split, the last one the default),
loops repeated as often on average as the log did; the engine needs some rule and the log
says how often, not why.
"""

from __future__ import annotations

import itertools
import keyword
import re
from xml.sax.saxutils import escape, quoteattr

from robotale.discovery.binding import ONE_INSTANCE, Bindings, Bound, skill_name
from robotale.discovery.collaboration import Collaboration, Handler, Pool, signal_of
from robotale.discovery.layout import (
    EVENT,
    GAP_X,
    GAP_Y,
    Block,
    Builder,
    Flow,
    Fragment,
    Kind,
    Leaf,
    Operator,
    Shape,
    Tau,
    leaves,
    simplify,
)
from robotale.discovery.payload_choices import separating
from robotale.discovery.repeats import once, unrolled
from robotale.eventlog.schema import RECEIVE, SEND
from robotale.fame_runtime.labels import activity_label

POOL_HEADER = 30  # the band bpmn-js draws a pool's name in
PADDING = 20  # inside an event sub-process' box
NS = (
    'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
    'xmlns:bpmndi="http://www.omg.org/spec/BPMN/20100524/DI" '
    'xmlns:dc="http://www.omg.org/spec/DD/20100524/DC" '
    'xmlns:di="http://www.omg.org/spec/DD/20100524/DI" '
    'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
)
__all__ = ["display_name", "lacking_skills", "skill_name", "write_bpmn"]


def display_name(label: str) -> str:
    """``take_off`` -> ``Take Off`` where the engine would tag that name as ``label`` again."""
    name = " ".join(part[:1].upper() + part[1:] for part in label.split("_") if part)
    return name if activity_label(name) == label else label


class _Ids:
    def __init__(self, prefix: str) -> None:
        self.prefix = prefix
        self.counter = itertools.count(1)

    def __call__(self, kind: str) -> str:
        return f"{self.prefix}_{kind}_{next(self.counter)}"


class _PoolDrawing:
    """One pool's process: the shapes and flows of its main flow and of each handler."""

    def __init__(self, pool: Pool, key: str, bindings: Bindings) -> None:
        self.pool = pool
        self.key = key
        self.bindings = bindings
        self.builder = Builder(_Ids(key), self.kind_of)
        self.conditions: dict[str, str] = {}
        self.defaults: dict[str, str] = {}
        self.event_based: set[str] = set()
        outside = self._outside()
        repeats = {label: n for (name, label), n in bindings.repeats.items() if name == pool.name}
        self.main = self.framed(
            once(without(unrolled(pool.block, repeats), outside), set(repeats)),
            self.builder.node("start", pool.starts_on or ""),
            pool.traces,
        )
        self.handlers = [
            (
                handler,
                self.framed(
                    without(handler.block, outside),
                    self.builder.node("start", handler.trigger),
                    handler.count,
                ),
            )
            for handler in pool.handlers
        ]
        self.boxes: list[Shape] = []
        self.w = self.h = self.y = 0.0

    def _outside(self) -> set[str]:
        """The pool's messages a skill of the driving model sends or consumes itself: the
        driving pool has no event for them (none when no driving model binds the pool)."""
        if self.pool.name not in self.bindings.outside:
            return set()
        events = self.bindings.outside[self.pool.name]
        return {
            label
            for label, stats in self.pool.stats.items()
            if stats.role in (SEND, RECEIVE) and label not in events
        }

    def host(self, handler: Handler) -> str | None:
        """The id of the activity a handler's trigger is a boundary timer of: the driving
        model times it, and it cut short one activity only, drawn once in the main flow
        (``None`` otherwise: the handler is an event sub-process)."""
        if not self.bindings.is_timer(self.pool.name, handler.trigger):
            return None
        if len(handler.abandoned) != 1 or not handler.interrupting:
            return None
        (label,) = handler.abandoned
        hosts = [s.id for s in self.main.shapes if s.kind == "task" and s.label == label]
        return hosts[0] if len(hosts) == 1 else None

    def bound(self, label: str) -> Bound | None:
        return self.bindings.of(self.pool.name, label)

    def kind_of(self, label: str) -> Kind:
        role = self.pool.stats[label].role if label in self.pool.stats else None
        kind: Kind = {SEND: "throw", RECEIVE: "catch"}.get(role or "", "task")  # type: ignore[assignment]
        bound = self.bound(label)
        if kind == "task" and bound is not None and bound.tag == "intermediateCatchEvent":
            return "catch"  # a timer the engine tags as an activity
        return kind

    def framed(self, block: Block, start: Fragment, traces: int) -> Fragment:
        """``block`` drawn from ``start`` to an end; ``traces``: how many runs of it the log
        has (the process' traces, or how often a handler ran)."""
        body = self.builder.fragment(block)
        fragment = self.builder.sequence([start, body, self.builder.node("end")])
        self._choose(block, fragment, traces)
        return fragment

    def _choose(self, block: Block, fragment: Fragment, traces: int) -> None:
        """Conditions for the exclusive splits of ``fragment`` (built from ``block``)."""
        splits = [s for s in fragment.shapes if s.kind == "xor"]
        outgoing: dict[str, list[Flow]] = {}
        for flow in fragment.flows:
            outgoing.setdefault(flow.source, []).append(flow)
        kinds = {s.id: s.kind for s in fragment.shapes}
        for split in splits:
            flows = outgoing.get(split.id, [])
            if len(flows) < 2:
                continue
            if all(kinds.get(flow.target) == "catch" for flow in flows):
                # a choice between waits: the first signal or timer to come decides, as an
                # event-based gateway, not a draw that may wait for what never comes
                self.event_based.add(split.id)
                continue
            if self._payload_choice(split, flows, fragment, outgoing):
                continue
            back = _back_flow(split.id, flows, outgoing)
            if back is not None:  # a loop's split: round again with the log's share, else on
                redo = self._redo_share(block, split, fragment, traces)
                share = 0.5 if redo is None else redo
                self.conditions[back.id] = f'__import__("random").random() < {share:.3f}'
                self.defaults[split.id] = next(f.id for f in flows if f is not back)
                continue
            for number, flow in enumerate(flows[:-1]):
                share = 1 / (len(flows) - number)
                self.conditions[flow.id] = f'__import__("random").random() < {share:.3f}'
            self.defaults[split.id] = flows[-1].id

    def _payload_choice(
        self, split: Shape, flows: list[Flow], fragment: Fragment, outgoing: dict[str, list[Flow]]
    ) -> bool:
        """Conditions on a two-way choice made after a catch, when a test of the caught
        payload separates the branches in every catch of the log (:mod:`payload_choices`);
        False when there is no such test."""
        if len(flows) != 2 or not self.pool.caught or split.id not in self.builder.joins:
            return False  # a loop's split is no choice
        catch = _nearest_catch(split, fragment, outgoing, set(self.pool.caught))
        variable = signal_of(catch.label).replace("/", "_") if catch else ""
        if catch is None or not variable.isidentifier() or keyword.iskeyword(variable):
            return False
        join = self.builder.joins.get(split.id)
        labels = {s.id: s.label for s in fragment.shapes if s.kind in ("task", "throw", "catch")}
        branches = [frozenset(_inside(flow.target, join, outgoing, labels)) for flow in flows]
        found = separating(self.pool.caught[catch.label], branches)
        if found is None:
            return False
        test, chosen = found
        for number, flow in enumerate(flows):
            self.conditions[flow.id] = test.expression(variable, holds=number == chosen)
        return True

    def _redo_share(
        self, block: Block, split: Shape, fragment: Fragment, traces: int
    ) -> float | None:
        """For a loop's split: the share of passes that went round again, from the counts of
        the first activity of the body against the fragment's ``traces`` (capped so a run
        ends)."""
        ids = [s.id for s in fragment.shapes]
        position = ids.index(split.id)
        before = [s for s in fragment.shapes[:position] if s.kind in ("task", "throw", "catch")]
        loop = _loop_of(block, before[-1].label if before else None)
        if loop is None or not traces:
            return None
        first = leaves(loop.children[0]) or leaves(loop.children[1])
        if not first or first[0] not in self.pool.stats:
            return None
        passes = self.pool.stats[first[0]].count / traces
        return min(0.9, max(0.0, 1 - 1 / passes)) if passes > 1 else 0.1


def without(block: Block, labels: set[str]) -> Block:
    """``block`` with the activities ``labels`` left out."""
    if not labels:
        return block
    if isinstance(block, Leaf):
        return Tau() if block.label in labels else block
    if isinstance(block, Operator):
        kept = simplify(Operator(block.kind, [without(c, labels) for c in block.children]))
        return kept if leaves(kept) else Tau()  # nothing left to do, not a loop of gateways
    return block


def _back_flow(split: str, flows: list[Flow], outgoing: dict[str, list[Flow]]) -> Flow | None:
    """The flow of ``split`` that goes round its loop again: the one from which the split is
    reached again soonest (leaving the loop, it is reached again only through an enclosing
    loop, which takes longer); ``None`` when no flow comes back (a choice)."""
    best: tuple[int, int] | None = None
    for number, flow in enumerate(flows):
        steps = _steps_to(flow.target, split, outgoing)
        if steps is not None and (best is None or steps < best[0]):
            best = (steps, number)
    return None if best is None else flows[best[1]]


def _nearest_catch(
    split: Shape, fragment: Fragment, outgoing: dict[str, list[Flow]], labels: set[str]
) -> Shape | None:
    """The catch of one of ``labels`` nearest before ``split`` that every path from the
    fragment's entry to the split passes (so the message was caught when the choice is
    made); ``None`` when there is none."""
    best: tuple[int, Shape] | None = None
    for shape in fragment.shapes:
        if shape.kind != "catch" or shape.label not in labels or fragment.entry is None:
            continue
        if _reaches(fragment, split.id, avoiding=shape.id):
            continue  # a way round the catch
        steps = _steps_to(shape.id, split.id, outgoing)
        if steps is not None and (best is None or steps < best[0]):
            best = (steps, shape)
    return None if best is None else best[1]


def _reaches(fragment: Fragment, goal: str, *, avoiding: str) -> bool:
    """Whether a token can reach ``goal`` from the fragment's entry without passing
    ``avoiding``: a parallel join goes on only once all its incoming flows are reached."""
    kinds = {shape.id: shape.kind for shape in fragment.shapes}
    incoming: dict[str, set[str]] = {}
    for flow in fragment.flows:
        incoming.setdefault(flow.target, set()).add(flow.source)
    reached = {fragment.entry}
    grew = True
    while grew:
        grew = False
        for flow in fragment.flows:
            node = flow.target
            if node in reached or node == avoiding or flow.source not in reached:
                continue
            if kinds.get(node) == "and" and not incoming[node] <= reached:
                continue
            reached.add(node)
            grew = True
    return goal in reached


def _inside(
    start: str, join: str | None, outgoing: dict[str, list[Flow]], labels: dict[str, str]
) -> set[str]:
    """The activities and events of a branch: what is reached from its first element before
    the gateway joining the branches."""
    found: set[str] = set()
    seen, frontier = {start}, [start]
    while frontier:
        node = frontier.pop()
        if node == join:
            continue
        if node in labels:
            found.add(labels[node])
        for flow in outgoing.get(node, []):
            if flow.target not in seen:
                seen.add(flow.target)
                frontier.append(flow.target)
    return found


def _steps_to(start: str, goal: str, outgoing: dict[str, list[Flow]]) -> int | None:
    seen, frontier, steps = {start}, [start], 0
    while frontier:
        if goal in frontier:
            return steps
        steps += 1
        frontier = [
            f.target for node in frontier for f in outgoing.get(node, []) if f.target not in seen
        ]
        seen.update(frontier)
    return None


def _loop_of(block: Block, label: str | None) -> Operator | None:
    """The innermost loop whose body holds ``label`` last (the loop a split closes)."""
    if label is None or not isinstance(block, Operator):
        return None
    for child in block.children:
        found = _loop_of(child, label)
        if found is not None:
            return found
    if block.kind == "loop" and (leaves(block.children[0])[-1:] == [label]):
        return block
    return None


def write_bpmn(collaboration: Collaboration, bindings: Bindings | None = None) -> str:
    """The collaboration as BPMN XML text with its diagram; ``bindings`` say what each
    activity runs (by default the simulator's skill of its name, see :mod:`binding`)."""
    if bindings is None:  # every activity calls the skill of its name
        bindings = Bindings(frozenset())
    drawings = [
        _PoolDrawing(pool, f"P{n}", bindings) for n, pool in enumerate(collaboration.pools, 1)
    ]
    _place(drawings)
    signals = sorted(collaboration.signals)
    errors = sorted({h.name for d in drawings for h in d.pool.handlers if h.kind == "error"})
    parts = ['<?xml version="1.0" encoding="UTF-8"?>']
    parts.append(
        f'<bpmn:definitions {NS} id="Definitions_discovered" '
        'targetNamespace="http://bpmn.io/schema/bpmn" exporter="robotale discover bpmn">'
    )
    parts.append('<bpmn:collaboration id="Collaboration_discovered">')
    parts.append(_documentation(_summary(collaboration)))
    for drawing in drawings:
        parts.append(_participant(drawing))
    parts.append("</bpmn:collaboration>")
    for drawing in drawings:
        parts.append(_process(drawing, collaboration))
    for name in signals:
        parts.append(f'<bpmn:signal id="{_signal_id(name)}" name={quoteattr(name)} />')
    for name in errors:
        parts.append(
            f'<bpmn:error id="{_error_id(name)}" name={quoteattr(name)} '
            f"errorCode={quoteattr(name)} />"
        )
    parts.append(_diagram(drawings))
    parts.append("</bpmn:definitions>")
    return "\n".join(parts) + "\n"


def lacking_skills(collaboration: Collaboration, bindings: Bindings) -> list[str]:
    """One sentence per skill the written model calls that the skill registry lacks."""
    sentences = []
    for pool in collaboration.pools:
        drawing_kinds = _PoolDrawing(pool, "P", bindings)
        labels = [
            shape.label
            for fragment in [drawing_kinds.main, *(f for _, f in drawing_kinds.handlers)]
            for shape in fragment.shapes
            if shape.kind == "task"
        ]
        for skill, calling in sorted(bindings.lacking(pool.name, labels).items()):
            sentences.append(
                f"pool {pool.name}: {', '.join(sorted(set(calling)))} calls the skill {skill}, "
                "which the simulation does not have (give --bind a driving model that says "
                "what it runs)"
            )
    return sentences


def _summary(collaboration: Collaboration) -> str:
    info = collaboration.info
    return (
        f"Discovered by robotale from {info.get('events')} events in {info.get('cases')} "
        f"runs with the {info.get('miner')}."
    )


def _participant(drawing: _PoolDrawing) -> str:
    pool = drawing.pool
    robots = len(pool.robots)
    multiplicity = (
        f'<bpmn:participantMultiplicity minimum="1" maximum="{robots}" />'
        if pool.multi_instance
        else ""
    )
    return (
        f'<bpmn:participant id="Pool_{drawing.key}" name={quoteattr(pool.name)} '
        f'processRef="Process_{drawing.key}">'
        + _documentation(f"robots {', '.join(pool.robots)}; {pool.traces} traces")
        + multiplicity
        + "</bpmn:participant>"
    )


def _process(drawing: _PoolDrawing, collaboration: Collaboration) -> str:
    pool = drawing.pool
    out = [
        f'<bpmn:process id="Process_{drawing.key}" name={quoteattr(pool.name)} isExecutable="true">'
    ]
    out += _elements(drawing, drawing.main, collaboration, None)
    out += _data_objects(drawing)
    for (handler, fragment), box in zip(drawing.handlers, drawing.boxes, strict=True):
        host = drawing.host(handler)
        if host is not None:  # the driving model's timer on the activity it cut short
            out += _elements(drawing, fragment, collaboration, handler)
            continue
        out.append(
            f'<bpmn:subProcess id="{box.id}" name={quoteattr(box.label)} triggeredByEvent="true">'
        )
        out.append(_documentation(handler.text()))
        out += _elements(drawing, fragment, collaboration, handler)
        out.append("</bpmn:subProcess>")
    out.append("</bpmn:process>")
    return "\n".join(out)


def _data_objects(drawing: _PoolDrawing) -> list[str]:
    """The driving model's data objects the bound elements read or fill, each once."""
    labels = [s.label for _, f in [(None, drawing.main), *drawing.handlers] for s in f.shapes]
    found: dict[str, str] = {}
    for label in labels:
        bound = drawing.bound(label) if label else None
        for ident, text in bound.data if bound else ():
            found.setdefault(ident, text)
    return list(found.values())


def _elements(
    drawing: _PoolDrawing, fragment: Fragment, collaboration: Collaboration, handler: Handler | None
) -> list[str]:
    out = []
    for shape in fragment.shapes:
        out.append(_element(drawing, shape, collaboration, handler))
    for flow in fragment.flows:
        condition = drawing.conditions.get(flow.id)
        body = (
            '<bpmn:conditionExpression xsi:type="bpmn:tFormalExpression" language="python">'
            f"{escape(condition)}</bpmn:conditionExpression>"
            if condition
            else ""
        )
        out.append(
            f'<bpmn:sequenceFlow id="{flow.id}" sourceRef="{flow.source}" '
            f'targetRef="{flow.target}">{body}</bpmn:sequenceFlow>'
        )
    return out


def _element(
    drawing: _PoolDrawing, shape: Shape, collaboration: Collaboration, handler: Handler | None
) -> str:
    stats = drawing.pool.stats.get(shape.label)
    doc = _documentation(stats.text()) if stats and shape.kind in ("task", "throw", "catch") else ""
    ident = shape.id
    # a start event keeps its trigger: a timer the driving model attaches to an activity is
    # no event sub-process' timer (it counts from the activity's start, not the process')
    bound = drawing.bound(shape.label) if shape.kind in ("task", "throw", "catch") else None
    if shape.kind == "task" or (bound is not None and bound.tag == "intermediateCatchEvent"):
        bound = bound or drawing.bindings.skill(shape.label)
        attrs = "".join(f" {k}={quoteattr(v)}" for k, v in bound.attributes)
        name = quoteattr(display_name(shape.label))
        tag = bound.tag
        body = _repeated(bound.body, drawing.bindings.repeats.get((drawing.pool.name, shape.label)))
        body = _own_ids(body, ident)
        return f'<bpmn:{tag} id="{ident}" name={name}{attrs}>{doc}{body}</bpmn:{tag}>'
    if shape.kind in ("throw", "catch"):
        tag = "intermediateThrowEvent" if shape.kind == "throw" else "intermediateCatchEvent"
        name = signal_of(shape.label)
        signal = collaboration.signals.get(name)
        if signal is not None:
            doc = _documentation(f"{stats.text() if stats else ''}. Signal {name}: {signal.text()}")
        body = _own_ids(bound.body, ident) if bound is not None else ""
        return (
            f'<bpmn:{tag} id="{ident}" name={quoteattr(name)}>{doc}{body}'
            f'<bpmn:signalEventDefinition signalRef="{_signal_id(name)}" /></bpmn:{tag}>'
        )
    if shape.kind == "start":
        if handler is None and shape.label:  # an instance per message of this signal
            name = signal_of(shape.label)
            bound = drawing.bound(shape.label)
            return (
                f'<bpmn:startEvent id="{ident}" name={quoteattr(name)}>'
                f"{_own_ids(bound.body, ident) if bound is not None else ''}"
                f'<bpmn:signalEventDefinition signalRef="{_signal_id(name)}" /></bpmn:startEvent>'
            )
        if handler is None or not shape.label:
            return f'<bpmn:startEvent id="{ident}" />'
        interrupting = "true" if handler.interrupting else "false"
        host = drawing.host(handler)
        if host is not None:
            timer = drawing.bound(handler.trigger)
            return (
                f'<bpmn:boundaryEvent id="{ident}" name={quoteattr(display_name(handler.name))} '
                f'attachedToRef="{host}" cancelActivity="true">'
                f"{timer.body if timer else ''}</bpmn:boundaryEvent>"
            )
        after = drawing.bindings.timers.get((drawing.pool.name, handler.trigger))
        if after is not None:  # the driving model's timer, fired when the log has it fire
            definition = (
                '<bpmn:timerEventDefinition><bpmn:timeDuration xsi:type="bpmn:tFormalExpression">'
                f"PT{after:.3f}S</bpmn:timeDuration></bpmn:timerEventDefinition>"
            )
        elif handler.kind == "signal":
            # the driving model's catch of the signal: the data its message fills
            caught = drawing.bound(handler.trigger)
            definition = (_own_ids(caught.body, ident) if caught is not None else "") + (
                f'<bpmn:signalEventDefinition signalRef="{_signal_id(handler.name)}" />'
            )
        else:
            definition = f'<bpmn:errorEventDefinition errorRef="{_error_id(handler.name)}" />'
        return (
            f'<bpmn:startEvent id="{ident}" name={quoteattr(handler.name)} '
            f'isInterrupting="{interrupting}">{definition}</bpmn:startEvent>'
        )
    if shape.kind == "end":
        return f'<bpmn:endEvent id="{ident}" />'
    tag = {"xor": "exclusiveGateway", "and": "parallelGateway", "or": "inclusiveGateway"}[
        shape.kind
    ]
    if ident in drawing.event_based:
        return f'<bpmn:eventBasedGateway id="{ident}" />'
    default = drawing.defaults.get(ident)
    attr = f' default="{default}"' if default else ""
    return f'<bpmn:{tag} id="{ident}"{attr} />'


def _own_ids(body: str, owner: str) -> str:
    """``body`` copied into the element ``owner`` with the ids it defines (an input's
    placeholder property) made its own, and the references to them: a driving element
    copied twice must not give one id twice."""
    for ident in re.findall(r'\bid="([^"]+)"', body):
        body = body.replace(f'id="{ident}"', f'id="{ident}_{owner}"')
        body = body.replace(f">{ident}<", f">{ident}_{owner}<")
    return body


def _repeated(body: str, times: int | None) -> str:
    """``body`` with a sequential multi-instance marker of ``times`` instead of any other."""
    if times is None:
        return body
    body = body.replace(ONE_INSTANCE, "")
    marker = (
        '<bpmn:multiInstanceLoopCharacteristics isSequential="true">'
        f"<bpmn:loopCardinality>{times}</bpmn:loopCardinality>"
        "</bpmn:multiInstanceLoopCharacteristics>"
    )
    script = body.find("<bpmn:script")
    return body + marker if script < 0 else body[:script] + marker + body[script:]


def _documentation(text: str) -> str:
    return f"<bpmn:documentation>{escape(text)}</bpmn:documentation>" if text else ""


def _signal_id(name: str) -> str:
    return "Signal_" + re.sub(r"[^0-9A-Za-z_]", "_", name)


def _error_id(name: str) -> str:
    return "Error_" + re.sub(r"[^0-9A-Za-z_]", "_", name)


# -- placing pools and handlers ----------------------------------------------------------------


def _place(drawings: list[_PoolDrawing]) -> None:
    """Pools one below the other; in each, the main flow on top and the event sub-processes
    below it, left to right as the main flow."""
    y = 0.0
    for drawing in drawings:
        left = POOL_HEADER + GAP_X
        top = y + GAP_Y
        drawing.main.moved(left, top)
        bottom = top + drawing.main.h
        right = left + drawing.main.w
        x = left
        for handler, fragment in drawing.handlers:
            box_top = bottom + GAP_Y
            fragment.moved(x + PADDING, box_top + PADDING + EVENT / 2)
            box = Shape(
                drawing.builder.ids("subprocess"),
                "subprocess",
                display_name(handler.tag) if handler.tag else f"on {handler.name}",
                x,
                box_top,
                fragment.w + 2 * PADDING,
                fragment.h + 2 * PADDING + EVENT / 2,
            )
            drawing.boxes.append(box)
            x += box.w + GAP_X
            right = max(right, x - GAP_X)
        if drawing.boxes:
            bottom = max(b.y + b.h for b in drawing.boxes)
        drawing.w = right + GAP_X
        drawing.h = bottom + GAP_Y - y
        drawing.y = y
        y += drawing.h + GAP_Y
    width = max(d.w for d in drawings)
    for drawing in drawings:
        drawing.w = width


def _diagram(drawings: list[_PoolDrawing]) -> str:
    out = ['<bpmndi:BPMNDiagram id="Diagram_discovered">']
    out.append('<bpmndi:BPMNPlane id="Plane_discovered" bpmnElement="Collaboration_discovered">')
    for drawing in drawings:
        out.append(
            _bounds(f"Pool_{drawing.key}", 0, drawing.y, drawing.w, drawing.h, horizontal=True)
        )
        fragments = [drawing.main] + [fragment for _, fragment in drawing.handlers]
        for (handler, _), box in zip(drawing.handlers, drawing.boxes, strict=True):
            if drawing.host(handler) is None:
                out.append(_bounds(box.id, box.x, box.y, box.w, box.h, expanded=True))
        for fragment in fragments:
            for shape in fragment.shapes:
                out.append(_bounds(shape.id, shape.x, shape.y, shape.w, shape.h))
            for flow in fragment.flows:
                points = "".join(f'<di:waypoint x="{x:.0f}" y="{y:.0f}" />' for x, y in flow.points)
                edge = f'<bpmndi:BPMNEdge id="{flow.id}_di" bpmnElement="{flow.id}">'
                out.append(f"{edge}{points}</bpmndi:BPMNEdge>")
    out.append("</bpmndi:BPMNPlane>")
    out.append("</bpmndi:BPMNDiagram>")
    return "\n".join(out)


def _bounds(
    ident: str,
    x: float,
    y: float,
    w: float,
    h: float,
    *,
    horizontal: bool = False,
    expanded: bool = False,
) -> str:
    attrs = ' isHorizontal="true"' if horizontal else ""
    attrs += ' isExpanded="true"' if expanded else ""
    return (
        f'<bpmndi:BPMNShape id="{ident}_di" bpmnElement="{ident}"{attrs}>'
        f'<dc:Bounds x="{x:.0f}" y="{y:.0f}" width="{w:.0f}" height="{h:.0f}" />'
        "</bpmndi:BPMNShape>"
    )
