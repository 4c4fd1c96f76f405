"""``robotale fame verify`` on small models with a known flaw each, its counterexample
checked; on correct models no finding; and its answers against the engine itself, run over
every combination of the values the verifier does not know."""

import itertools
import json
from pathlib import Path

import pytest

from robotale.cli import main
from robotale.errors import ModelError
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.labels import element_label
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.parser import parse, parse_bytes
from robotale.fame_runtime.verify import verify

HEAD = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
    'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d">\n'
)


def model(*pools: tuple[str, str]) -> bytes:
    """A collaboration of ``(pool name, process body)`` pools."""
    parts = [HEAD, '<bpmn:collaboration id="c">']
    for name, _ in pools:
        parts.append(f'<bpmn:participant id="P_{name}" name="{name}" processRef="{name}_p"/>')
    parts.append("</bpmn:collaboration>")
    for name, body in pools:
        for own in ("s", "e", "e2"):  # start and end ids, each pool its own
            body = body.replace(f'"{own}"', f'"{name.lower()}_{own}"')
        parts.append(f'<bpmn:process id="{name}_p" isExecutable="true">{body}</bpmn:process>')
    parts.append('<bpmn:signal id="S_go" name="go"/><bpmn:signal id="S_done" name="done"/>')
    parts.append("</bpmn:definitions>")
    return "\n".join(parts).encode()


def flow(source, target, condition=None, fid=None):
    fid = fid or f"f_{source}_{target}"
    if condition is None:
        return f'<bpmn:sequenceFlow id="{fid}" sourceRef="{source}" targetRef="{target}"/>'
    return (
        f'<bpmn:sequenceFlow id="{fid}" sourceRef="{source}" targetRef="{target}">'
        f"<bpmn:conditionExpression>{condition}</bpmn:conditionExpression></bpmn:sequenceFlow>"
    )


def catch(eid, signal):
    return (
        f'<bpmn:intermediateCatchEvent id="{eid}" name="{signal}">'
        f'<bpmn:signalEventDefinition signalRef="S_{signal}"/></bpmn:intermediateCatchEvent>'
    )


def throw(eid, signal):
    return (
        f'<bpmn:intermediateThrowEvent id="{eid}" name="{signal}">'
        f'<bpmn:signalEventDefinition signalRef="S_{signal}"/></bpmn:intermediateThrowEvent>'
    )


def timer(eid, seconds=1):
    return (
        f'<bpmn:intermediateCatchEvent id="{eid}" name="wait"><bpmn:timerEventDefinition>'
        f"<bpmn:timeDuration>PT{seconds}S</bpmn:timeDuration></bpmn:timerEventDefinition>"
        "</bpmn:intermediateCatchEvent>"
    )


def script(eid, name, text):
    return (
        f'<bpmn:scriptTask id="{eid}" name="{name}" scriptFormat="python">'
        f"<bpmn:script>{text}</bpmn:script></bpmn:scriptTask>"
    )


def task(eid, name):
    return f'<bpmn:task id="{eid}" name="{name}"/>'


START, END = '<bpmn:startEvent id="s"/>', '<bpmn:endEvent id="e"/>'


def gateway(eid, default=None):
    extra = f' default="{default}"' if default else ""
    return f'<bpmn:exclusiveGateway id="{eid}"{extra}/>'


def check(data: bytes, **kw):
    return verify(parse_bytes(data, "m.bpmn"), **kw)


def kinds(verdict):
    return [f.kind for f in verdict.findings]


def lines(trace):
    return [(t.robot, t.activity, t.lifecycle) for t in trace]


# -- a known flaw each ----------------------------------------------------------------------------

DEADLOCK = model(
    (
        "A",
        START
        + catch("a_wait", "go")
        + throw("a_done", "done")
        + END
        + flow("s", "a_wait")
        + flow("a_wait", "a_done")
        + flow("a_done", "e"),
    ),
    (
        "B",
        START
        + catch("b_wait", "done")
        + throw("b_go", "go")
        + END
        + flow("s", "b_wait")
        + flow("b_wait", "b_go")
        + flow("b_go", "e"),
    ),
)


def test_two_robots_waiting_for_each_other_is_a_deadlock_naming_who_waits_for_what():
    verdict = check(DEADLOCK)
    assert kinds(verdict) == [
        "deadlock",
        "never_fires",
        "never_fires",
        "unreachable",
        "unreachable",
        "unreachable",
        "unreachable",
    ]
    deadlock = verdict.findings[0]
    assert "a waits at intermediateCatchEvent a_wait (go) for signal /go" in deadlock.sentence
    assert "b waits at intermediateCatchEvent b_wait (done) for signal /done" in deadlock.sentence
    assert deadlock.trace == []  # both wait right after the start: the shortest trace is empty
    assert sorted(deadlock.elements) == ["a_wait", "b_wait"]


LOST = model(
    (
        "A",
        START
        + task("a_work", "Work")
        + throw("a_go", "go")
        + END
        + flow("s", "a_work")
        + flow("a_work", "a_go")
        + flow("a_go", "e"),
    ),
    (
        "B",
        START
        + timer("b_timer")
        + catch("b_wait", "go")
        + END
        + flow("s", "b_timer")
        + flow("b_timer", "b_wait")
        + flow("b_wait", "e"),
    ),
)


def test_a_signal_thrown_before_its_catcher_waits_is_lost_and_the_catcher_waits_for_ever():
    verdict = check(LOST)
    lost = next(f for f in verdict.findings if f.kind == "lost_signal")
    assert lost.robot == "a" and lost.elements == ["a_go"]
    # the mission begins: A works and throws while B still waits for its timer
    assert lines(lost.trace) == [
        ("a", "work", "start"),
        ("a", "work", "complete"),
        ("a", "go!", "start"),
        ("a", "go!", "complete"),
    ]
    deadlock = next(f for f in verdict.findings if f.kind == "deadlock")
    assert "b waits at intermediateCatchEvent b_wait (go) for signal /go" in deadlock.sentence
    assert lines(deadlock.trace)[-2:] == [("b", "wait", "start"), ("b", "wait", "complete")]


UNREACHABLE = model(
    (
        "A",
        START
        + script("a_set", "Set", "x = 1")
        + gateway("g")
        + task("a_one", "One")
        + task("a_two", "Two")
        + END
        + '<bpmn:endEvent id="e2"/>'
        + flow("s", "a_set")
        + flow("a_set", "g")
        + flow("g", "a_one", "x == 1")
        + flow("g", "a_two", "x == 2")
        + flow("a_one", "e")
        + flow("a_two", "e2"),
    ),
)


def test_a_branch_whose_condition_the_tracked_values_rule_out_is_never_reached():
    verdict = check(UNREACHABLE)
    assert [(f.kind, f.elements) for f in verdict.findings] == [
        ("unreachable", ["a_two"]),
        ("unreachable", ["a_e2"]),
    ]
    assert "task a_two (Two) of A_p is never reached" in verdict.findings[0].sentence
    assert {"a_s", "a_set", "g", "a_one", "a_e"} <= set(verdict.reached)


NO_EXIT = model(
    (
        "A",
        START
        + task("a_go", "Go")
        + timer("a_timer", 2)
        + script("a_check", "Check", "done = False")
        + gateway("g")
        + task("a_stop", "Stop")
        + END
        + flow("s", "a_go")
        + flow("a_go", "a_timer")
        + flow("a_timer", "a_check")
        + flow("a_check", "g")
        + flow("g", "a_stop", "done", "yes")
        + flow("g", "a_timer", "not done", "no")
        + flow("a_stop", "e"),
    ),
)


def test_a_loop_whose_exit_is_closed_by_a_plain_assignment_cannot_terminate():
    verdict = check(NO_EXIT)
    assert kinds(verdict) == ["no_exit", "unreachable", "unreachable"]
    loop = verdict.findings[0]
    assert loop.robot == "a"
    assert "exclusiveGateway g never takes yes" in loop.sentence
    assert "done = false, set by a_check (Check) in the same step" in loop.sentence
    assert lines(loop.trace) == [
        ("a", "go", "start"),
        ("a", "go", "complete"),
        ("a", "wait", "start"),
        ("a", "wait", "complete"),
        ("a", "check", "start"),
        ("a", "check", "complete"),
        ("a", "wait", "start"),
        ("a", "wait", "complete"),
        ("a", "check", "start"),
        ("a", "check", "complete"),
    ]
    assert loop.elements[0] == "g"


CORRECT = model(
    (
        "A",
        START
        + timer("a_timer")
        + throw("a_go", "go")
        + END
        + flow("s", "a_timer")
        + flow("a_timer", "a_go")
        + flow("a_go", "e"),
    ),
    (
        "B",
        START
        + catch("b_wait", "go")
        + task("b_work", "Work")
        + END
        + flow("s", "b_wait")
        + flow("b_wait", "b_work")
        + flow("b_work", "e"),
    ),
)


def test_parallel_and_inclusive_splits_joined_again_give_no_finding():
    verdict = check(GATEWAYS)
    assert verdict.findings == [] and verdict.complete
    assert {"t_1", "t_2", "t_x", "t_y", "t_z", "join", "merge", "a_e"} <= set(verdict.reached)


def test_a_correct_handshake_gives_no_finding():
    verdict = check(CORRECT)
    assert verdict.findings == [] and verdict.complete
    # by hand: not begun; begun (A at its timer, B waiting for go); the timer fired (A threw
    # go, B caught it, both ended)
    assert verdict.states == 3


# -- the authors' models ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "robots"),
    [("agri", ["drone"]), ("simple_scenario", ["dingo", "rex"]), ("GoTo", ["goto"])],
)
def test_the_authors_models_are_named_with_gotos_loop_and_why(fame_models, name, robots):
    model = fame_models / "fame-ros" / f"{name}.bpmn"
    verdict = verify(parse(model), library=_library(model.parent))
    loops = [f for f in verdict.findings if f.kind == "no_exit"]
    assert [f.robot for f in loops] == robots
    for loop in loops:
        assert "exclusiveGateway Gateway_0mn0474 (destination reached?) never takes" in (
            loop.sentence
        )
        assert "reached = false, set by Activity_1gbttx6 (Check Position) in the same step" in (
            loop.sentence
        )
        assert lines(loop.trace)[-2:] == [
            (loop.robot, "check_position", "start"),
            (loop.robot, "check_position", "complete"),
        ]
    assert verdict.complete


def _library(folder):
    return Library(folder)


# -- the command --------------------------------------------------------------------------------


def test_the_command_exits_1_on_a_finding_0_on_none_2_on_bad_input(tmp_path, capsys):
    (tmp_path / "loop.bpmn").write_bytes(NO_EXIT)
    (tmp_path / "ok.bpmn").write_bytes(CORRECT)
    (tmp_path / "bad.bpmn").write_bytes(b"<nothing/>")
    assert main(["fame", "verify", str(tmp_path / "loop.bpmn")]) == 1
    text = capsys.readouterr().out
    assert "no_exit: robot a can never finish" in text
    assert "\ta\tcheck\tcomplete" in text  # the trace as tag lines
    assert main(["fame", "verify", str(tmp_path / "ok.bpmn"), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["findings"] == [] and data["complete"] is True
    assert main(["fame", "verify", str(tmp_path / "bad.bpmn")]) == 2
    assert "bad.bpmn:1: not a BPMN 2.0 file" in capsys.readouterr().err
    assert main(["fame", "verify", str(tmp_path / "ok.bpmn"), "--max-states", "0"]) == 2


def test_a_bound_hit_is_reported(tmp_path, capsys):
    (tmp_path / "loop.bpmn").write_bytes(NO_EXIT)
    assert (
        main(["fame", "verify", str(tmp_path / "loop.bpmn"), "--max-states", "2", "--json"]) == 0
    )  # nothing found in the explored states
    data = json.loads(capsys.readouterr().out)
    assert data["complete"] is False and data["bound"] == "--max-states 2 reached"
    assert "unreachable" not in [f["kind"] for f in data["findings"]]


# -- against the engine itself ------------------------------------------------------------------

BRANCHES = model(
    (
        "A",
        START
        + gateway("g1")
        + task("t_a", "TA")
        + task("t_b", "TB")
        + gateway("g2")
        + task("t_c", "TC")
        + task("t_d", "TD")
        + timer("w")
        + '<bpmn:endEvent id="e2"/>'
        + END
        + flow("s", "g1")
        + flow("g1", "t_a", "a")
        + flow("g1", "t_b", "not a")
        + flow("t_a", "e")
        + flow("t_b", "g2")
        + flow("g2", "t_c", "b")
        + flow("g2", "t_d", "not b")
        + flow("t_c", "e2")
        + flow("t_d", "w")
        + flow("w", "g2"),
    ),
)


GATEWAYS = model(
    (
        "A",
        START
        + '<bpmn:parallelGateway id="fork"/><bpmn:parallelGateway id="join"/>'
        + '<bpmn:inclusiveGateway id="or"/><bpmn:inclusiveGateway id="merge"/>'
        + task("t_1", "One")
        + task("t_2", "Two")
        + task("t_x", "X")
        + task("t_y", "Y")
        + task("t_z", "Z")
        + END
        + flow("s", "fork")
        + flow("fork", "t_1")
        + flow("fork", "t_2")
        + flow("t_1", "join")
        + flow("t_2", "join")
        + flow("join", "or")
        + flow("or", "t_x", "a")
        + flow("or", "t_y", "b")
        + flow("or", "t_z", "not a and not b")
        + flow("t_x", "merge")
        + flow("t_y", "merge")
        + flow("t_z", "merge")
        + flow("merge", "e"),
    ),
)


@pytest.mark.parametrize(
    "data",
    [BRANCHES, UNREACHABLE, NO_EXIT, CORRECT, DEADLOCK, LOST, GATEWAYS],
    ids=["branches", "unreachable", "no_exit", "correct", "deadlock", "lost", "gateways"],
)
def test_the_verifier_agrees_with_the_engine_run_over_every_combination_of_unknowns(data):
    definitions = parse_bytes(data, "m.bpmn")
    verdict = verify(definitions)
    labels = _labels(definitions)
    reached, ends, stuck_at = set(), [], set()
    for a, b in itertools.product([True, False], repeat=2):
        tags = []
        clock = SimClock(start=0.0)
        mission = Mission(
            definitions,
            clock=clock,
            tag_sink=tags.append,
            variables={r: {"a": a, "b": b} for r in ("a", "b")},
        )
        mission.run(until=60.0)
        reached |= {labels[t.activity] for t in tags if t.activity in labels}
        ends.append(mission.done)
        if clock.next_time() is None and not mission.done:  # nothing can happen any more
            stuck_at |= {w.split()[1] for e in mission.engines.values() for w in e.where()}
    # a catch event is tagged when it fires: one that waits but never fires is not in a log
    never = {e for f in verdict.findings if f.kind == "never_fires" for e in f.elements}
    verified = (set(verdict.reached) - never) & set(labels.values())
    assert verified == reached
    # some run cannot finish exactly when the verifier finds a loop without exit or a deadlock
    assert bool({"no_exit", "deadlock"} & set(kinds(verdict))) == (not all(ends))
    deadlocked = {e for f in verdict.findings if f.kind == "deadlock" for e in f.elements}
    assert deadlocked == stuck_at


def _labels(definitions):
    """Tagged label -> element id of every element the engine tags (what both sides see)."""
    return {
        element_label(node): node.id
        for process in definitions.processes.values()
        for node in process.walk()
        if not node.kind.endswith("Gateway") and node.kind not in ("startEvent", "endEvent")
    }


BUSY = model(
    (
        "A",
        START
        + script("a_count", "Count", "n = 1")
        + gateway("g")
        + END
        + flow("s", "a_count")
        + flow("a_count", "g")
        + flow("g", "a_count", "n == 1")
        + flow("g", "e", "n == 2"),
    ),
)


def test_a_loop_that_never_waits_cannot_finish_and_the_engine_stops_it():
    verdict = check(BUSY)
    loop = next(f for f in verdict.findings if f.kind == "no_exit")
    assert loop.robot == "a" and "for ever without ever waiting" in loop.sentence
    assert "exclusiveGateway g never takes f_g_e: it reads n = 1, set by a_count (Count)" in (
        loop.sentence
    )
    assert lines(loop.trace) == [("a", "count", "start"), ("a", "count", "complete")] * 2
    mission = Mission(parse_bytes(BUSY, "m.bpmn"), clock=SimClock(start=0.0))
    with pytest.raises(ModelError, match="without waiting for anything"):
        mission.run(until=10.0)


def test_every_model_of_the_engine_tests_is_verified_completely(models):
    """Each construct the engine runs (boundaries, errors, escalations, event sub-processes,
    loops, messages, terminate, timers ...) is explored to the end, or refused as the
    deployer refuses it."""
    verified = 0
    for path in sorted(models.glob("*.bpmn")):
        library = Library(models / "library")
        try:
            verdict = verify(parse(path), library=library, skills=["drive", "take_off", "land"])
        except ModelError as error:
            assert path.name in str(error) or "robot" in str(error)
            continue
        assert verdict.complete, path.name
        verified += 1
    assert verified >= 20


def test_compensation_is_stated_as_not_explored_and_its_handlers_are_not_called_unreachable(
    tmp_path, capsys
):
    semantics = Path(__file__).resolve().parent / "semantics"
    source = (semantics / "compensation_boundary.bpmn").read_text()
    # an element no flow reaches, outside compensation: still reported
    lost = source.replace(
        '<bpmn:task id="notice" name="notice" />',
        '<bpmn:task id="notice" name="notice" /><bpmn:task id="orphan" name="orphan" />'
        '<bpmn:endEvent id="orphan_end" />'
        '<bpmn:sequenceFlow id="f_orphan" sourceRef="orphan" targetRef="orphan_end" />',
    )
    path = tmp_path / "compensation.bpmn"
    path.write_text(lost)
    assert main(["fame", "verify", str(path), "--json"]) == 1
    verdict = json.loads(capsys.readouterr().out)
    # the handlers (joined by associations, never by flows) are read from the file itself
    assert verdict["abstractions"] == [
        "compensation is not explored: compensation throw events (undo) pass on at once and "
        "compensation handlers (release, refund) never run, so nothing inside them is "
        "checked or reported"
    ]
    assert sorted(e for f in verdict["findings"] for e in f["elements"]) == [
        "orphan",
        "orphan_end",
    ]
    assert main(["fame", "verify", str(path)]) == 1
    assert "note: compensation is not explored:" in capsys.readouterr().out
    # a model without compensation states no abstraction
    path.write_text(source.split("<bpmn:process")[0] + PLAIN)
    assert main(["fame", "verify", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["abstractions"] == []


PLAIN = """<bpmn:process id="rover" isExecutable="true">
    <bpmn:startEvent id="start" /><bpmn:task id="work" /><bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="work" />
    <bpmn:sequenceFlow id="f2" sourceRef="work" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>
"""
