"""The differential semantics suite: each case of ``semantics/`` runs on robotale, on
SpiffWorkflow and on bpmn-engine (FAME's own engine, driven as FAME's controller.js drives it,
by ``bpmn_engine/harness.js``), and what each did is held against what the BPMN 2.0
specification says must happen, written here case by case.

robotale must do what the specification says, in Python and in FAME's JavaScript dialect.
Where the other engines depart from it is kept in ``docs/semantics.md``; the last test fails
when that table no longer says what the engines do.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest
from fame_suite import run

from robotale.fame_runtime.labels import activity_label

HERE = Path(__file__).resolve().parent
CASES_DIR = HERE / "semantics"
HARNESS = HERE / "bpmn_engine"
TABLE = HERE.parents[1] / "docs" / "semantics.md"
AS_SPECIFIED = "as specified"

#: FAME's dialect of a Python case: what to replace, with what
CAMUNDA = (
    'xmlns:camunda="http://camunda.org/schema/1.0/bpmn" '
    'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id='
)
#: a condition with a language is a tFormalExpression (the schema's tExpression has none)
FORMAL = '<bpmn:conditionExpression xsi:type="bpmn:tFormalExpression" language="javascript">'
MI_CAMUNDA = (
    "<bpmn:multiInstanceLoopCharacteristics>",
    '<bpmn:multiInstanceLoopCharacteristics camunda:collection="${environment.variables.items}"'
    ' camunda:elementVariable="item">',
)


@dataclass(frozen=True)
class Outcome:
    """What an engine did: the activities it completed, in order (their names as robotale
    labels them), its variables at the end, whether the process ended, and why not."""

    completed: list[str]
    variables: dict
    ended: bool
    error: str | None = None


@dataclass(frozen=True)
class Case:
    name: str
    variables: dict
    activities: frozenset[str]  # the names of the case's activities (events are left out)
    #: the specification's verdict on an outcome: the ways it departs ([]: as specified)
    judge: Callable[[Outcome], list[str]]
    javascript: tuple[tuple[str, str], ...] = ()  # Python dialect -> FAME's dialect
    spiff: tuple[tuple[str, str], ...] = ()  # Python dialect -> SpiffWorkflow's
    described: str = ""
    exact: list[str] = field(default_factory=list)

    def text(self, dialect: str) -> str:
        text = (CASES_DIR / f"{self.name}.bpmn").read_text()
        if dialect == "javascript":
            text = text.replace(' id="', f' {CAMUNDA}"', 1)
        for old, new in {"javascript": self.javascript, "spiff": self.spiff}.get(dialect, ()):
            assert old in text, (self.name, old)
            text = text.replace(old, new)
        return text


def js_condition(python: str) -> tuple[str, str]:
    """A Python condition ``name op value`` as FAME's dialect writes it."""
    return (
        f"<bpmn:conditionExpression>{python}</bpmn:conditionExpression>",
        f"{FORMAL}next(null, this.environment.variables.{python});</bpmn:conditionExpression>",
    )


def in_order(expected: list[str]) -> Callable[[Outcome], list[str]]:
    """The specification gives one trace: exactly these activities complete, in this order,
    and the process ends."""

    def judge(outcome: Outcome) -> list[str]:
        found = []
        if outcome.completed != expected:
            found.append(
                f"completes {', '.join(outcome.completed) or 'nothing'} instead of "
                f"{', '.join(expected)}"
            )
        if not outcome.ended:
            found.append("does not end")
        return found

    return judge


def items_judge(outcome: Outcome) -> list[str]:
    # 10.3.8: each instance has its own loopCounter and input item; the output items are
    # collected, in instance order, into the loopDataOutputRef collection
    # (bpmn-engine's listener hears one end of a multi-instance activity, not one per
    # instance: the collected outputs, not the tags, tell what each instance saw)
    found = [] if outcome.ended else ["does not end"]
    lines = outcome.variables.get("lines")
    want = [f"item {item} loopCounter {n}" for n, item in enumerate((10, 20, 30))]
    if lines != want:
        found.append(f"collects {lines!r} into loopDataOutputRef lines, not {want!r}")
    return found


def error_judge(outcome: Outcome) -> list[str]:
    # the instance whose loopCounter is 1 throws "second" and the boundary around the whole
    # activity catches it: handle runs, the activity never completes (after never runs); the
    # other instances run in parallel, so fine completes at most twice before the error
    found = []
    raised_by = outcome.variables.get("raised_by")
    if "handle" not in outcome.completed:
        found.append("never runs the error's handler (the error at loopCounter 1 is not raised)")
    elif raised_by != 20:
        found.append(f"raises the error in the instance of item {raised_by!r}, not 20")
    if "after" in outcome.completed:
        found.append("leaves the activity normally although an instance threw an error")
    if outcome.completed.count("fine") > 2:
        found.append("runs fine for every instance")
    if not outcome.ended:
        found.append("does not end")
    return found


def inclusive_judge(outcome: Outcome) -> list[str]:
    # 13.3.3: a and b run in parallel (either first), c does not; the join waits for both
    found = []
    if sorted(outcome.completed[:2]) != ["a", "b"] or outcome.completed[2:] != ["after"]:
        found.append(
            f"completes {', '.join(outcome.completed) or 'nothing'}, not a and b then after"
        )
    if not outcome.ended:
        found.append("does not end")
    return found


def items_case(name: str, marker: str) -> Case:
    """A multi-instance script task over [10, 20, 30] writing its item and loopCounter."""
    return Case(
        name,
        {"items": [10, 20, 30]},
        frozenset({"visit"}),
        items_judge,
        javascript=(
            ('scriptFormat="python"', 'scriptFormat="javascript"'),
            (marker, MI_CAMUNDA[1].replace(">", marker.removeprefix(MI_CAMUNDA[0][:-1]))),
            (
                '<bpmn:script>line = f"item {item} loopCounter {loopCounter}"</bpmn:script>',
                "<bpmn:script>var v = this.environment.variables;\n"
                'v.line = "item " + v.item + " loopCounter " + v.loopCounter; next();'
                "</bpmn:script>",
            ),
        ),
    )


def implicit_judge(outcome: Outcome) -> list[str]:
    # 10.5.2: left and right start together (either first), then the sub-processes complete
    found = []
    if sorted(outcome.completed[:2]) != ["left", "right"] or outcome.completed[2:] != [
        "group",
        "empty",
        "after",
    ]:
        done = ", ".join(outcome.completed) or "nothing"
        found.append(f"completes {done}, not left and right, then group, empty, after")
    if not outcome.ended:
        found.append("does not end")
    return found


CASES = [
    items_case("mi_parallel_items", MI_CAMUNDA[0]),
    Case(
        "mi_parallel_error",
        {"items": [10, 20, 30]},
        frozenset({"fine", "mark", "handle", "after"}),
        error_judge,
        javascript=(
            MI_CAMUNDA,
            ('scriptFormat="python"', 'scriptFormat="javascript"'),
            (
                "<bpmn:script>raised_by = item</bpmn:script>",
                "<bpmn:script>var v = this.environment.variables;\n"
                "v.raised_by = v.item; next();</bpmn:script>",
            ),
            (
                "<bpmn:conditionExpression>loopCounter == 1</bpmn:conditionExpression>",
                f"{FORMAL}next(null, this.environment.variables.loopCounter === 1);"
                "</bpmn:conditionExpression>",
            ),
        ),
    ),
    Case(
        "compensation_boundary",
        {},
        frozenset({"reserve", "charge", "notice", "refund", "release"}),
        # 13.5.5: completed activities are compensated in reverse order of completion
        in_order(["reserve", "charge", "notice", "refund", "release"]),
    ),
    Case(
        "compensation_event_subprocess",
        {},
        frozenset({"work", "pick", "place", "undo_work", "tidy", "unpick", "after"}),
        # 10.6.5: compensating a sub-process runs its compensation event sub-process, whose
        # throw compensates the sub-process's own activities; the throw waits for it
        in_order(["pick", "place", "work", "tidy", "unpick", "undo_work", "after"]),
    ),
]
CASES += [
    items_case(
        "mi_sequential_items", '<bpmn:multiInstanceLoopCharacteristics isSequential="true">'
    ),
    Case(
        "inclusive_join",
        {"amount": 50},
        frozenset({"a", "b", "c", "after"}),
        inclusive_judge,
        javascript=tuple(js_condition(f"amount &gt; {n}") for n in (5, 10, 100)),
    ),
    # 13.5.6: a terminate end event ends every token of the instance at once
    Case(
        "terminate_branch",
        {},
        frozenset({"quick", "late"}),
        in_order(["quick"]),
        # SpiffWorkflow reads a timer's text as a Python expression
        spiff=(("<bpmn:timeDuration>PT1S<", '<bpmn:timeDuration>"PT1S"<'),),
    ),
    # 10.5.4: the error leaves the sub-process through its boundary event, nothing else
    Case(
        "error_subprocess",
        {},
        frozenset({"work", "job", "repair", "after"}),
        in_order(["work", "repair"]),
    ),
    Case(
        "exclusive_default",
        {"amount": 1, "bigger": 50},
        frozenset({"big", "small", "over_ten", "over_five", "none"}),
        # 13.3.2: no condition holds: the default flow; several hold: the first in order only
        in_order(["small", "over_ten"]),
        javascript=(
            js_condition("amount &gt; 100"),
            js_condition("bigger &gt; 10"),
            js_condition("bigger &gt; 5"),
        ),
    ),
]
CASES.append(
    Case(
        "implicit_start",
        {},
        frozenset({"left", "right", "group", "empty", "after"}),
        implicit_judge,
    )
)
BY_NAME = {case.name: case for case in CASES}


# -- the engines --------------------------------------------------------------------------------


def robotale(case: Case, dialect: str, tmp_path: Path) -> Outcome:
    path = tmp_path / f"{case.name}.{dialect}.bpmn"
    path.write_text(case.text(dialect))
    mission, tags = run(path, variables={"rover": dict(case.variables)}, until=60)
    engine = mission.engines["rover"]
    completed = [
        t.activity for t in tags if t.lifecycle == "complete" and t.activity in case.activities
    ]
    error = "; ".join(engine.failures) or None
    return Outcome(completed, dict(engine.variables), mission.done and not error, error)


def spiffworkflow(case: Case, tmp_path: Path) -> Outcome:
    from SpiffWorkflow.bpmn import BpmnWorkflow
    from SpiffWorkflow.bpmn.parser import BpmnParser
    from SpiffWorkflow.util.task import TaskState

    path = tmp_path / f"{case.name}.spiff.bpmn"
    path.write_text(case.text("spiff"))
    parser = BpmnParser()
    try:
        parser.add_bpmn_file(str(path))
        workflow = BpmnWorkflow(parser.get_spec("rover"), parser.get_subprocess_specs("rover"))
        workflow.get_tasks()[0].data.update(case.variables)
        workflow.do_engine_steps()
        # SpiffWorkflow leaves a task without a type to a person: complete those as its
        # users do, until nothing is ready
        while ready := [t for t in workflow.get_tasks(state=TaskState.READY) if t.task_spec.manual]:
            for task in ready:
                task.run()
            workflow.do_engine_steps()
    except Exception as error:  # what the engine says is the finding: any error it raises
        return Outcome([], {}, False, f"{type(error).__name__}: {error}")
    done = sorted(workflow.get_tasks(state=TaskState.COMPLETED), key=lambda t: t.last_state_change)
    names = [activity_label(t.task_spec.bpmn_name) for t in done if t.task_spec.bpmn_name]
    completed = [name for name in names if name in case.activities]
    return Outcome(completed, dict(workflow.data), workflow.is_completed())


def node_missing() -> str | None:
    """Why bpmn-engine cannot run here (None: it can)."""
    if shutil.which("node") is None:
        return "node is not installed, so bpmn-engine (FAME's engine) cannot run here"
    if not (HARNESS / "node_modules" / "bpmn-engine").is_dir():
        where = HARNESS.relative_to(HERE.parents[1])
        pytest.fail(f"bpmn-engine is not installed: run `npm ci --prefix {where}` (make test does)")
    return None


def bpmn_engine(case: Case, tmp_path: Path) -> Outcome:
    path = tmp_path / f"{case.name}.fame.bpmn"
    path.write_text(case.text("javascript"))
    command = ["node", str(HARNESS / "harness.js"), str(path), json.dumps(case.variables), "20"]
    result = subprocess.run(command, capture_output=True, text=True, timeout=120, check=True)
    report = json.loads(result.stdout.strip().splitlines()[-1])
    ended = [name or ident for kind, ident, name, _ in report["trace"] if kind == "end"]
    completed = [activity_label(n) for n in ended if activity_label(n) in case.activities]
    return Outcome(completed, report["variables"], report["ended"], report["error"])


# -- the tests ----------------------------------------------------------------------------------


@pytest.mark.parametrize("dialect", ["python", "javascript"])
@pytest.mark.parametrize("name", sorted(BY_NAME))
def test_robotale_does_what_the_specification_says(name, dialect, tmp_path):
    case = BY_NAME[name]
    outcome = robotale(case, dialect, tmp_path)
    assert case.judge(outcome) == [], outcome


def departures_table() -> dict[str, dict[str, str]]:
    """docs/semantics.md's departures table: case -> engine -> "as specified" or how it
    departs."""
    lines = TABLE.read_text().splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("| Case | robotale"))
    header = _cells(lines[first])
    table = {}
    for line in lines[first + 2 :]:
        if not line.startswith("|"):
            break
        row = _cells(line)
        table[row[0].strip("`")] = dict(zip(header[1:], row[1:], strict=True))
    return table


def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in line.strip().strip("|").split("|")]


def verdict(found: list[str]) -> str:
    return "; ".join(found) if found else AS_SPECIFIED


@pytest.mark.slow
def test_the_departures_table_says_what_each_engine_does(tmp_path):
    table = departures_table()
    assert sorted(table) == sorted(BY_NAME)
    missing = node_missing()
    for name, case in BY_NAME.items():
        row = table[name]
        assert row["robotale"] == AS_SPECIFIED
        spiff = spiffworkflow(case, tmp_path)
        assert _cell(row["SpiffWorkflow 3.2.0"]) == verdict(case.judge(spiff)), (name, spiff)
        if missing is None:
            fame = bpmn_engine(case, tmp_path)
            assert _cell(row["bpmn-engine 22.0.3"]) == verdict(case.judge(fame)), (name, fame)
    if missing is not None:
        pytest.skip(f"the bpmn-engine column was not checked: {missing}")


def _cell(text: str) -> str:
    """A table cell as a verdict: Markdown code marks and escaped bars taken off."""
    return re.sub(r"`", "", text).replace("\\|", "|")
