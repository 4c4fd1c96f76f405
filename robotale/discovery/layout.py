"""Block-structured process fragments with their diagram positions.

The inductive miner returns a process tree: every operator a block with one entry and one
exit. Each block becomes a BPMN fragment (tasks, events, gateways, flows) laid out left to
right in the order things happen: a sequence side by side, the branches of a choice or of a
parallel split one below the other between their split and join gateways, a loop's body on
the main line and its redo part below it, the flow back running in the free band between
them. Every fragment is a rectangle no other fragment enters, so no two shapes overlap, and
its entry and exit sit on one horizontal line (``mid``), so a sequence is a straight line.
Coordinates are relative to the fragment's top left corner until :func:`place` moves them.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

#: shape sizes as bpmn-js draws them by default
TASK_W, TASK_H = 100, 80
EVENT = 36
GATEWAY = 50
GAP_X, GAP_Y = 40, 30
#: a loop's band between its body and its redo part, where the flow back runs
LOOP_BAND = 40
#: the height of a choice's branch that does nothing (a flow from split to join)
SKIP_ROW = 30

Kind = Literal["task", "throw", "catch", "xor", "and", "or", "start", "end", "subprocess"]


@dataclass(slots=True)
class Shape:
    id: str
    kind: Kind
    label: str  # the activity (a task) or the signal (an event)
    x: float
    y: float
    w: float
    h: float

    @property
    def mid_y(self) -> float:
        return self.y + self.h / 2


@dataclass(slots=True)
class Flow:
    id: str
    source: str
    target: str
    points: list[tuple[float, float]]


@dataclass(slots=True)
class Fragment:
    """Shapes and flows of one block; ``entry``/``exit`` are shape ids (``None``: the block
    does nothing, a tau)."""

    shapes: list[Shape] = field(default_factory=list)
    flows: list[Flow] = field(default_factory=list)
    entry: str | None = None
    exit: str | None = None
    w: float = 0.0
    h: float = 0.0
    mid: float = 0.0

    def shape(self, ident: str) -> Shape:
        return next(s for s in self.shapes if s.id == ident)

    def moved(self, dx: float, dy: float) -> Fragment:
        for shape in self.shapes:
            shape.x += dx
            shape.y += dy
        for flow in self.flows:
            flow.points = [(x + dx, y + dy) for x, y in flow.points]
        return self


# -- the blocks --------------------------------------------------------------------------------


@dataclass(slots=True)
class Leaf:
    label: str


@dataclass(slots=True)
class Tau:
    pass


@dataclass(slots=True)
class Operator:
    kind: Literal["seq", "xor", "and", "or", "loop"]
    children: list[Block]


Block = Leaf | Tau | Operator


def from_process_tree(tree) -> Block:
    """pm4py's process tree as blocks; interleaving and partial orders (which the inductive
    miner does not produce) are drawn as parallel branches, which allow every order."""
    from pm4py.objects.process_tree.obj import Operator as PmOperator  # pm4py: discovery only

    if tree.operator is None:
        return Tau() if tree.label is None else Leaf(str(tree.label))
    kinds = {
        PmOperator.SEQUENCE: "seq",
        PmOperator.XOR: "xor",
        PmOperator.PARALLEL: "and",
        PmOperator.OR: "or",
        PmOperator.LOOP: "loop",
    }
    children = [from_process_tree(child) for child in tree.children]
    return simplify(Operator(kinds.get(tree.operator, "and"), children))


def simplify(block: Block) -> Block:
    """Nested operators of one kind flattened, taus dropped where they change nothing, and a
    loop whose body and redo part both may do nothing kept from spinning on gateways alone."""
    if not isinstance(block, Operator):
        return block
    children = [simplify(child) for child in block.children]
    if block.kind == "loop":
        body, redo = children[0], (children[1] if len(children) > 1 else Tau())
        if _may_skip(body) and _may_skip(redo):
            # a loop whose every cycle may do nothing is a loop of gateways for the engine:
            # the same behaviour without the empty cycle is the body optional and repeated
            redo = _without_skip(redo)
        return Operator("loop", [body, redo])
    flat: list[Block] = []
    for child in children:
        if isinstance(child, Operator) and child.kind == block.kind:
            flat += child.children  # a sequence in a sequence, a choice in a choice ...
        else:
            flat.append(child)
    if block.kind in ("seq", "and", "or"):
        flat = [child for child in flat if not isinstance(child, Tau)]
    elif sum(isinstance(child, Tau) for child in flat) > 1:  # one skip is enough
        first = next(i for i, child in enumerate(flat) if isinstance(child, Tau))
        flat = [c for i, c in enumerate(flat) if not isinstance(c, Tau) or i == first]
    if not flat:
        return Tau()
    if len(flat) == 1:
        return flat[0]
    return Operator(block.kind, flat)


def _may_skip(block: Block) -> bool:
    if isinstance(block, Tau):
        return True
    if isinstance(block, Leaf):
        return False
    if block.kind == "xor":
        return any(_may_skip(child) for child in block.children)
    if block.kind == "loop":
        return _may_skip(block.children[0])
    return all(_may_skip(child) for child in block.children)


def _without_skip(block: Block) -> Block:
    if isinstance(block, Operator) and block.kind == "xor":
        kept = [_without_skip(c) for c in block.children if not isinstance(c, Tau)]
        return kept[0] if len(kept) == 1 else Operator("xor", kept)
    return block


def leaves(block: Block) -> list[str]:
    """The activities of ``block`` in the order drawn."""
    if isinstance(block, Leaf):
        return [block.label]
    if isinstance(block, Tau):
        return []
    return [label for child in block.children for label in leaves(child)]


# -- fragments ---------------------------------------------------------------------------------


class Builder:
    """Makes fragments; ``ids`` hands out element ids, ``kind_of`` says what a leaf is."""

    def __init__(self, ids: Callable[[str], str], kind_of: Callable[[str], Kind]) -> None:
        self.ids = ids
        self.kind_of = kind_of
        #: each split gateway of :meth:`branches` and the gateway joining its branches
        self.joins: dict[str, str] = {}

    def fragment(self, block: Block) -> Fragment:
        if isinstance(block, Tau):
            return Fragment()
        if isinstance(block, Leaf):
            return self.node(self.kind_of(block.label), block.label)
        if block.kind == "seq":
            return self.sequence([self.fragment(child) for child in block.children])
        if block.kind == "loop":
            return self.loop(self.fragment(block.children[0]), self.fragment(block.children[1]))
        return self.branches(block.kind, [self.fragment(child) for child in block.children])

    def node(self, kind: Kind, label: str = "") -> Fragment:
        size = {"task": (TASK_W, TASK_H), "xor": (GATEWAY,) * 2, "and": (GATEWAY,) * 2}
        w, h = size.get(kind, (GATEWAY, GATEWAY) if kind == "or" else (EVENT, EVENT))
        shape = Shape(self.ids(kind), kind, label, 0, 0, w, h)
        return Fragment([shape], [], shape.id, shape.id, w, h, h / 2)

    def flow(self, source: Shape, target: Shape, points: list[tuple[float, float]]) -> Flow:
        return Flow(self.ids("flow"), source.id, target.id, points)

    def sequence(self, parts: list[Fragment]) -> Fragment:
        parts = [part for part in parts if part.entry is not None]
        if not parts:
            return Fragment()
        mid = max(part.mid for part in parts)
        below = max(part.h - part.mid for part in parts)
        result = Fragment(mid=mid, h=mid + below)
        x, previous = 0.0, None
        for part in parts:
            part.moved(x, mid - part.mid)
            if previous is not None:
                a, b = previous.shape(previous.exit), part.shape(part.entry)
                result.flows.append(self.flow(a, b, [(a.x + a.w, mid), (b.x, mid)]))
            result.shapes += part.shapes
            result.flows += part.flows
            x += part.w + GAP_X
            previous = part
        result.entry, result.exit, result.w = parts[0].entry, parts[-1].exit, x - GAP_X
        return result

    def branches(self, kind: Kind, parts: list[Fragment]) -> Fragment:
        """A split gateway, the branches one below the other, the join gateway."""
        split, join = self.node(kind), self.node(kind)
        inner_w = max([part.w for part in parts if part.entry] or [0.0])
        first_mid = parts[0].mid if parts[0].entry is not None else SKIP_ROW / 2
        y = max(0.0, GATEWAY / 2 - first_mid)  # room for the gateways above the first branch
        mid = y + first_mid
        result = Fragment(mid=mid)
        s, j = split.shapes[0], join.shapes[0]
        self.joins[s.id] = j.id
        s.x, s.y = 0, mid - GATEWAY / 2
        j.x, j.y = GATEWAY + 2 * GAP_X + inner_w, mid - GATEWAY / 2
        result.shapes += [s, j]
        top = y
        for part in parts:
            if part.entry is None:  # nothing to do on this branch: split straight to join
                row = y + SKIP_ROW / 2 if y > top else mid
                result.flows.append(self.flow(s, j, _elbow(s, (j.x, row), j, row)))
                y += SKIP_ROW + GAP_Y
                continue
            part.moved(GATEWAY + GAP_X + (inner_w - part.w) / 2, y)
            row = y + part.mid
            entry, exit_ = part.shape(part.entry), part.shape(part.exit)
            result.flows.append(self.flow(s, entry, _out_of(s, row, entry.x)))
            result.flows.append(self.flow(exit_, j, _into(j, row, exit_.x + exit_.w)))
            result.shapes += part.shapes
            result.flows += part.flows
            y += part.h + GAP_Y
        result.entry, result.exit = s.id, j.id
        result.w, result.h = j.x + GATEWAY, max(y - GAP_Y, mid + GATEWAY / 2)
        return result

    def loop(self, body: Fragment, redo: Fragment) -> Fragment:
        """An exclusive join, the body, an exclusive split that leaves or goes round again
        (through the redo part, below the body)."""
        join, split = self.node("xor"), self.node("xor")
        j, s = join.shapes[0], split.shapes[0]
        body_mid = body.mid if body.entry else GATEWAY / 2
        mid = max(body_mid, GATEWAY / 2)
        inner_w = max(body.w, redo.w)
        j.x, j.y = 0, mid - GATEWAY / 2
        s.x, s.y = GATEWAY + 2 * GAP_X + inner_w, mid - GATEWAY / 2
        result = Fragment(shapes=[j, s], mid=mid, entry=j.id, exit=s.id, w=s.x + GATEWAY)
        body_bottom = mid + GATEWAY / 2
        if body.entry is None:
            result.flows.append(self.flow(j, s, [(j.x + GATEWAY, mid), (s.x, mid)]))
        else:
            body.moved(GATEWAY + GAP_X + (inner_w - body.w) / 2, mid - body.mid)
            entry, exit_ = body.shape(body.entry), body.shape(body.exit)
            result.flows.append(self.flow(j, entry, [(j.x + GATEWAY, mid), (entry.x, mid)]))
            result.flows.append(self.flow(exit_, s, [(exit_.x + exit_.w, mid), (s.x, mid)]))
            result.shapes += body.shapes
            result.flows += body.flows
            body_bottom = max(body_bottom, mid - body.mid + body.h)
        band = body_bottom + LOOP_BAND / 2  # the flow back runs here
        sx, jx = s.x + GATEWAY / 2, j.x + GATEWAY / 2
        if redo.entry is None:
            points = [(sx, s.y + GATEWAY), (sx, band), (jx, band), (jx, j.y + GATEWAY)]
            result.flows.append(self.flow(s, j, points))
            result.h = band + GAP_Y / 2
            return result
        top = body_bottom + LOOP_BAND
        redo.moved(GATEWAY + GAP_X + (inner_w - redo.w) / 2, top)
        entry, exit_ = redo.shape(redo.entry), redo.shape(redo.exit)
        row, under = top + redo.mid, top + redo.h + GAP_Y / 2
        left, right = entry.x - GAP_X / 2, exit_.x + exit_.w + GAP_X / 2
        # round the redo part below to its entry, back from its exit through the band
        into_redo = [(sx, s.y + GATEWAY), (sx, under), (left, under), (left, row), (entry.x, row)]
        back = [(exit_.x + exit_.w, row), (right, row), (right, band), (jx, band)]
        result.flows.append(self.flow(s, entry, into_redo))
        result.flows.append(self.flow(exit_, j, [*back, (jx, j.y + GATEWAY)]))
        result.shapes += redo.shapes
        result.flows += redo.flows
        result.h = under + GAP_Y / 2
        return result


def _out_of(split: Shape, row: float, to_x: float) -> list[tuple[float, float]]:
    cx = split.x + split.w / 2
    if abs(row - split.mid_y) < 1:
        return [(split.x + split.w, row), (to_x, row)]
    return [(cx, split.y + split.h), (cx, row), (to_x, row)]


def _into(join: Shape, row: float, from_x: float) -> list[tuple[float, float]]:
    cx = join.x + join.w / 2
    if abs(row - join.mid_y) < 1:
        return [(from_x, row), (join.x, row)]
    return [(from_x, row), (cx, row), (cx, join.y + join.h)]


def _elbow(split: Shape, _to: tuple[float, float], join: Shape, row: float):
    if abs(row - split.mid_y) < 1:
        return [(split.x + split.w, row), (join.x, row)]
    sx, jx = split.x + split.w / 2, join.x + join.w / 2
    return [(sx, split.y + split.h), (sx, row), (jx, row), (jx, join.y + join.h)]


def framed(builder: Builder, body: Fragment, start: Fragment, end: Fragment) -> Fragment:
    """``start`` -> ``body`` -> ``end`` as one fragment (a process or an event sub-process)."""
    return builder.sequence([start, body, end])


def overlapping(shapes: list[Shape]) -> list[tuple[str, str]]:
    """Pairs of shapes whose rectangles intersect (a check for the layout's promise)."""
    found = []
    for i, a in enumerate(shapes):
        for b in shapes[i + 1 :]:
            if a.x < b.x + b.w and b.x < a.x + a.w and a.y < b.y + b.h and b.y < a.y + a.h:
                found.append((a.id, b.id))
    return found
