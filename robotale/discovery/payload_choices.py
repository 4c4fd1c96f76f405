"""Why a robot chose a branch after catching a message: a field of the message's payload.

FAME's models decide what a robot does with a message by reading its payload: the thesis'
tractor goes to the weed only when ``closest_tractor`` names it (``tractor ===
node.namespace()``). The log keeps every caught payload, so such a rule can be found: for a
choice the model makes after a catch, each catch of the log is followed, until the robot
caught the same message again, by the work of one branch; when a test of one payload field
(equal to the catching robot's own name, else equal to one value) is true exactly where one
branch was taken and false exactly where the others were, the choice is written as that
test. Nothing is written where no such test separates the branches in every catch of the log.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from dataclasses import dataclass

#: ``{ name: tractor_2 }``: the thesis' payloads, fields written without JSON's quotes
_LOOSE_FIELD = re.compile(r"([A-Za-z_]\w*)\s*:\s*([^,{}]*)")


@dataclass(frozen=True, slots=True)
class Caught:
    """One catch of a message in a robot's process: its payload's fields, the robot, and the
    activities the robot began after it until it caught the same message again."""

    fields: tuple[tuple[str, str], ...]
    robot: str
    after: frozenset[str]


@dataclass(frozen=True, slots=True)
class Test:
    """A test of a caught payload's field: equal to the robot's own name (``value`` None) or
    to ``value``."""

    field: str
    value: str | None

    def holds(self, caught: Caught) -> bool:
        fields = dict(caught.fields)
        if self.field not in fields:
            return False
        return fields[self.field] == (caught.robot if self.value is None else self.value)

    def expression(self, variable: str, *, holds: bool = True) -> str:
        """The test (or, ``holds`` False, its opposite) as a Python condition on the variable
        the engine stores the message in (a mapping of its fields) and ``robot``, the robot's
        handle."""
        wanted = "robot.name" if self.value is None else repr(self.value)
        return f"{variable}.get({self.field!r}) {'==' if holds else '!='} {wanted}"


def payload_fields(text: object) -> tuple[tuple[str, str], ...]:
    """A logged payload's fields as text, in name order: a JSON object's, a JSON value as
    ``data`` (a ROS ``String``'s one field), or the thesis' ``{ name: value }``; none when
    the text is no payload."""
    if not isinstance(text, str) or not text.strip():
        return ()
    try:
        value = json.loads(text)
    except ValueError:
        pairs = {name: found.strip().strip("'\"") for name, found in _LOOSE_FIELD.findall(text)}
        return tuple(sorted(pairs.items()))
    if not isinstance(value, dict):
        value = {"data": value}
    return tuple(sorted((str(k), _text(v)) for k, v in value.items() if _text(v) is not None))


def _text(value: object) -> str | None:
    """A field's value as the robot's name would compare with it: text and numbers only."""
    if isinstance(value, bool) or value is None or isinstance(value, dict | list):
        return None
    return str(value)


def windows(
    labels: Sequence[str], fields: Sequence[tuple[tuple[str, str], ...]], catches: set[str]
) -> dict[str, list[tuple[int, frozenset[str]]]]:
    """For each catch in one trace (``labels``, with each instance's payload ``fields``): its
    position and the activities after it up to the next catch of the same message. A catch
    the same message follows at once decided nothing: the robot read the later one (the
    engine keeps the last message caught)."""
    found: dict[str, list[tuple[int, frozenset[str]]]] = {}
    for position, label in enumerate(labels):
        if label not in catches or not fields[position]:
            continue
        end = position + 1
        while end < len(labels) and labels[end] != label:
            end += 1
        if end == position + 1 and end < len(labels):
            continue
        found.setdefault(label, []).append((position, frozenset(labels[position + 1 : end])))
    return found


def separating(
    caught: Sequence[Caught], branches: Sequence[frozenset[str]]
) -> tuple[Test, int] | None:
    """The test and the branch it picks, when the test is true on exactly the catches after
    which that branch was taken (and false on those after which another was).

    ``branches``: the activities inside each branch of the choice (empty for a branch that
    does nothing). The branch taken after a catch is the one whose activities the robot
    began before it caught the message again; the empty branch when it began none. A catch
    after which several branches' work came, or none without an empty branch, leaves the
    choice unexplained (None)."""
    taken = [_taken(one.after, branches) for one in caught]
    if not caught or None in taken or len(set(taken)) < 2:
        return None
    for test in _tests(caught):
        chosen = {branch for one, branch in zip(caught, taken, strict=True) if test.holds(one)}
        others = {branch for one, branch in zip(caught, taken, strict=True) if not test.holds(one)}
        if len(chosen) == 1 and others and not chosen & others:
            return test, chosen.pop()
    return None


def _taken(after: frozenset[str], branches: Sequence[frozenset[str]]) -> int | None:
    hit = [number for number, inside in enumerate(branches) if inside & after]
    if len(hit) == 1:
        return hit[0]
    empty = [number for number, inside in enumerate(branches) if not inside]
    return empty[0] if not hit and len(empty) == 1 else None


def _tests(caught: Sequence[Caught]) -> list[Test]:
    """The tests worth trying, the robot's own name first (it needs no value the log chose),
    then each value a field had, in name order."""
    names = sorted({name for one in caught for name, _ in one.fields})
    own = [Test(name, None) for name in names]
    values = sorted({(name, value) for one in caught for name, value in one.fields})
    return own + [Test(name, value) for name, value in values]
