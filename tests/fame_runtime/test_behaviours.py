"""The engine's table of behaviours against the parser's vocabulary and the models' plans, and
the JavaScript runtime the engine loads against the package's files."""

from __future__ import annotations

import fnmatch
import tomllib
from collections.abc import Iterator
from pathlib import Path

import pytest
from fame_suite import build

import robotale.fame_runtime
from robotale.errors import ModelError
from robotale.fame_runtime import javascript
from robotale.fame_runtime.behaviours import BEHAVIOURS
from robotale.fame_runtime.bus import InProcessBus
from robotale.fame_runtime.clock import SimClock
from robotale.fame_runtime.kinds import FLOW_NODES, Kind
from robotale.fame_runtime.library import Library
from robotale.fame_runtime.mission import Mission
from robotale.fame_runtime.parser import parse, parse_all
from robotale.fame_runtime.plan import OUTSIDE, NodePlan, ScopePlan, deploy
from robotale.fame_runtime.splitter import split

HERE = Path(__file__).resolve().parent
PACKAGE = Path(robotale.fame_runtime.__file__).parent
PYPROJECT = PACKAGE.parent.parent / "pyproject.toml"


def _node_plans(scope: ScopePlan, seen: set[int]) -> Iterator[NodePlan]:
    """Every node plan of ``scope``: its nodes and event sub-processes, with the content of
    sub-processes and called processes and the bodies of loops (each scope once)."""
    if id(scope) in seen:
        return
    seen.add(id(scope))
    for node in [*scope.nodes.values(), *scope.event_subprocesses]:
        while node is not None:
            yield node
            if node.child is not None:
                yield from _node_plans(node.child, seen)
            node = node.loop.body if node.loop is not None else None


def _deployed_behaviours() -> dict[str, set[str]]:
    """Element kind -> the behaviours the deployer gave its elements in every test model
    that deploys (the semantics suite, the modelers' files, the differential models)."""
    library = Library(HERE / "models" / "library")
    found: dict[str, set[str]] = {}
    for path in sorted(HERE.rglob("*.bpmn")):
        if "node_modules" in path.parts:
            continue
        for _, process in parse_all(path).pools():
            try:
                plan = deploy(process, skills=["drive", "take_off", "land"], library=library)
            except ModelError:  # skills these tests do not name, or elements refused
                continue
            for node in _node_plans(plan, set()):
                found.setdefault(str(node.node.kind), set()).add(str(node.behaviour))
    return found


def test_every_kind_the_parser_reads_has_a_behaviour_or_is_refused_with_a_reason():
    deployed = _deployed_behaviours()
    # the parser reads exactly the flow nodes BPMN 2.0 defines (by their XML names)
    assert {str(k) for k in FLOW_NODES} == {
        *("startEvent", "endEvent", "intermediateCatchEvent", "intermediateThrowEvent"),
        *("boundaryEvent", "implicitThrowEvent", "task", "scriptTask", "callActivity"),
        *("subProcess", "transaction", "adHocSubProcess", "userTask", "serviceTask"),
        *("sendTask", "receiveTask", "manualTask", "businessRuleTask", "exclusiveGateway"),
        *("parallelGateway", "inclusiveGateway", "eventBasedGateway", "complexGateway"),
    }
    for kind in FLOW_NODES:
        if kind in OUTSIDE:  # refused by the deployer, with what robotale runs instead
            assert "robotale runs" in OUTSIDE[kind] or "use a" in OUTSIDE[kind], kind
            assert kind not in deployed, f"{kind} is refused, yet a model deployed one"
        else:
            assert deployed.get(kind), f"no test model deploys a {kind}"
            assert deployed[kind] <= set(BEHAVIOURS), (kind, deployed[kind] - set(BEHAVIOURS))
    # and the table has no entry the deployer never gives
    assert set().union(*deployed.values()) == {str(b) for b in BEHAVIOURS}
    assert deployed[Kind.CALL_ACTIVITY] >= {"call", "skill", "loop"}


def _function_text(source: str, name: str) -> str:
    """The text of the top-level JavaScript function ``name`` in ``source``: from its
    ``function`` keyword to the closing brace at the start of a line."""
    start = source.index(f"function {name}(")
    return source[start : source.index("\n}", start) + 2]


def test_the_engine_runs_the_javascript_files_of_the_package(tmp_path):
    files = {
        name: (PACKAGE / name).read_text(encoding="utf-8")
        for name in ("rclnodejs.js", "javascript.js")
    }
    assert files["rclnodejs.js"] + files["javascript.js"] == javascript._PRELUDE
    assert "var __fame = " not in (PACKAGE / "javascript.py").read_text(encoding="utf-8")
    # what a script of a running engine sees is the file's function, as written there
    path = tmp_path / "shim.bpmn"
    path.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>'
        '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">'
        '<bpmn:process id="rover" isExecutable="true"><bpmn:startEvent id="start" />'
        '<bpmn:scriptTask id="s" scriptFormat="javascript"><bpmn:script>'
        "this.environment.variables.shim = String(fame_rclnodejs); next();"
        '</bpmn:script></bpmn:scriptTask><bpmn:endEvent id="end" />'
        '<bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="s" />'
        '<bpmn:sequenceFlow id="f2" sourceRef="s" targetRef="end" />'
        "</bpmn:process></bpmn:definitions>"
    )
    mission, _ = build(path)
    mission.run(until=1.0)
    (engine,) = mission.engines.values()
    assert engine.completed == 1
    assert engine.variables["shim"] == _function_text(files["rclnodejs.js"], "fame_rclnodejs")


def test_an_installed_package_carries_the_javascript_files():
    package_data = tomllib.loads(PYPROJECT.read_text(encoding="utf-8"))["tool"]["setuptools"][
        "package-data"
    ]
    patterns = [*package_data.get("*", []), *package_data.get("robotale.fame_runtime", [])]
    for name in javascript.PRELUDE_FILES:
        assert (PACKAGE / name).is_file()
        assert any(fnmatch.fnmatch(name, pattern) for pattern in patterns), name
    # and says it is typed (PEP 561)
    assert (PACKAGE.parent / "py.typed").is_file()
    assert "py.typed" in package_data["robotale"]


MODEL_WITH_PROBLEMS = """<?xml version="1.0" encoding="UTF-8"?>
<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">
  <bpmn:process id="rover" isExecutable="true">
    <bpmn:startEvent id="start" />
      <bpmn:userTask id="ask" name="Ask" />
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="ask" />
    <bpmn:sequenceFlow id="f2" sourceRef="ask" targetRef="end" />
  </bpmn:process>
</bpmn:definitions>
"""


def _where(text: str, element: str) -> tuple[int, int]:
    """Line and column (both from 1) of the start tag of ``element``, counted by hand."""
    for number, line in enumerate(text.splitlines(), 1):
        if f'id="{element}"' in line:
            return number, line.index("<") + 1
    raise AssertionError(element)


def test_errors_of_the_reader_and_the_deployer_carry_file_line_column_and_element(tmp_path):
    path = tmp_path / "ask.bpmn"
    path.write_text(MODEL_WITH_PROBLEMS, encoding="utf-8")
    (_, process), *_ = parse(path).pools()
    with pytest.raises(ModelError) as refused:
        deploy(process)
    (problem,) = refused.value.problems
    assert (problem.file, problem.element) == (str(path), "ask")
    assert (problem.line, problem.column) == _where(MODEL_WITH_PROBLEMS, "ask")
    assert problem.sentence in str(refused.value) and "needs a person" in problem.sentence
    # a file the reader refuses: the boundary event's problem, placed the same way
    boundary = '<bpmn:boundaryEvent id="late" attachedToRef="nowhere" />'
    end = '<bpmn:endEvent id="end" />'
    broken = MODEL_WITH_PROBLEMS.replace(end, f"{end}\n      {boundary}")
    path.write_text(broken, encoding="utf-8")
    with pytest.raises(ModelError) as unread:
        parse(path)
    (problem,) = unread.value.problems
    assert (problem.file, problem.element) == (str(path), "late")
    assert (problem.line, problem.column) == _where(broken, "late")
    assert str(unread.value) == f"{path}:{problem.line}: {problem.sentence}"


def test_a_pool_and_a_mission_refused_carry_their_places(tmp_path):
    collaboration = MODEL_WITH_PROBLEMS.replace(
        '  <bpmn:process id="rover"',
        '  <bpmn:collaboration id="c">\n'
        '    <bpmn:participant id="rovers" name="Rover" processRef="rover">\n'
        '      <bpmn:participantMultiplicity minimum="2" />\n'
        "    </bpmn:participant>\n"
        "  </bpmn:collaboration>\n"
        '  <bpmn:process id="rover"',
    )
    path = tmp_path / "pool.bpmn"
    path.write_text(collaboration, encoding="utf-8")
    with pytest.raises(ModelError, match="needs at least 2 robots, 1 given") as few:
        split(parse(path), ["rover_1"])
    (problem,) = few.value.problems
    assert (problem.file, problem.element) == (str(path), "rovers")
    assert (problem.line, problem.column) == _where(collaboration, "rovers")
    with pytest.raises(ModelError, match="elements of the mission") as refused:
        Mission(path, clock=SimClock(0.0), bus=InProcessBus(SimClock(0.0)))
    places = {(p.file, p.element, p.line, p.column) for p in refused.value.problems}
    assert places == {(str(path), "ask", *_where(collaboration, "ask"))}
