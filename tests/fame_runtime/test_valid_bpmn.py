"""Valid BPMN 2.0 as different modellers write it: ``fame check`` reads every file, reports
every problem of a file at once, names each correctly and never crashes."""

import json
from pathlib import Path

import pytest
from fame_suite import PERSON

from robotale.cli import main
from robotale.errors import ModelError
from robotale.fame_runtime.parser import parse

HEAD = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL"\n'
    '    xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"\n'
    '    xmlns:camunda="http://camunda.org/schema/1.0/bpmn" id="d"{attributes}>\n'
)

#: one process per modeller habit; each runs once its quirk is read
FILES = {
    # Signavio/Bizagi style: a data store and ioSpecification inputs and outputs in
    # associations, a property as the target of an input association.
    "data_store.bpmn": """
  <bpmn:process id="shop" isExecutable="true">
    <bpmn:ioSpecification id="io">
      <bpmn:dataInput id="order_in" /><bpmn:dataOutput id="receipt_out" />
      <bpmn:inputSet id="is"><bpmn:dataInputRefs>order_in</bpmn:dataInputRefs></bpmn:inputSet>
      <bpmn:outputSet id="os"><bpmn:dataOutputRefs>receipt_out</bpmn:dataOutputRefs>
      </bpmn:outputSet>
    </bpmn:ioSpecification>
    <bpmn:dataStore id="stock_store" name="Stock" />
    <bpmn:dataStoreReference id="stock" dataStoreRef="stock_store" />
    <bpmn:startEvent id="start" />
    <bpmn:task id="pick" name="Pick">
      <bpmn:property id="pick_in" name="__targetRef_placeholder" />
      <bpmn:dataInputAssociation id="a1"><bpmn:sourceRef>stock</bpmn:sourceRef>
        <bpmn:targetRef>pick_in</bpmn:targetRef></bpmn:dataInputAssociation>
      <bpmn:dataInputAssociation id="a2"><bpmn:sourceRef>order_in</bpmn:sourceRef>
        <bpmn:targetRef>pick_in</bpmn:targetRef></bpmn:dataInputAssociation>
      <bpmn:dataOutputAssociation id="a3"><bpmn:targetRef>receipt_out</bpmn:targetRef>
      </bpmn:dataOutputAssociation>
    </bpmn:task>
    <bpmn:endEvent id="end" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="pick" />
    <bpmn:sequenceFlow id="f2" sourceRef="pick" targetRef="end" />
  </bpmn:process>""",
    # Lanes, two pools, a message flow between them, and a process in no pool.
    "pools.bpmn": """
  <bpmn:collaboration id="c">
    <bpmn:participant id="p1" name="Rover" processRef="rover" />
    <bpmn:participant id="p2" name="Base" processRef="base" />
    <bpmn:messageFlow id="m1" sourceRef="send" targetRef="base_start" />
  </bpmn:collaboration>
  <bpmn:process id="rover" isExecutable="true">
    <bpmn:laneSet id="ls"><bpmn:lane id="l1" name="Arm">
      <bpmn:flowNodeRef>start</bpmn:flowNodeRef><bpmn:flowNodeRef>send</bpmn:flowNodeRef>
    </bpmn:lane></bpmn:laneSet>
    <bpmn:startEvent id="start" /><bpmn:task id="send" name="Send" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="send" />
  </bpmn:process>
  <bpmn:process id="base" isExecutable="true">
    <bpmn:startEvent id="base_start" /><bpmn:endEvent id="base_end" />
    <bpmn:sequenceFlow id="f2" sourceRef="base_start" targetRef="base_end" />
  </bpmn:process>
  <bpmn:process id="spare" isExecutable="false">
    <bpmn:startEvent id="s" />
  </bpmn:process>""",
    # Camunda: an execution listener and two unconditioned flows out of an exclusive gateway.
    "listener.bpmn": """
  <bpmn:process id="cam" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:task id="work" name="Work">
      <bpmn:extensionElements>
        <camunda:executionListener class="org.example.Audit" event="start" />
      </bpmn:extensionElements>
    </bpmn:task>
    <bpmn:exclusiveGateway id="choice" />
    <bpmn:endEvent id="e1" /><bpmn:endEvent id="e2" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="work" />
    <bpmn:sequenceFlow id="f2" sourceRef="work" targetRef="choice" />
    <bpmn:sequenceFlow id="f3" sourceRef="choice" targetRef="e1" />
    <bpmn:sequenceFlow id="f4" sourceRef="choice" targetRef="e2" />
  </bpmn:process>""",
}

#: files with gaps robotale must name, all of them at once
GAPS = {
    # An empty timeDate, a FEEL condition and an XPath condition (the file's language).
    "gaps.bpmn": (
        ' expressionLanguage="http://www.w3.org/1999/XPath"',
        """
  <bpmn:process id="gappy" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:intermediateCatchEvent id="wait" name="Wait">
      <bpmn:timerEventDefinition id="t"><bpmn:timeDate xsi:type="bpmn:tFormalExpression" />
      </bpmn:timerEventDefinition>
    </bpmn:intermediateCatchEvent>
    <bpmn:exclusiveGateway id="choice" default="f5" />
    <bpmn:endEvent id="e1" /><bpmn:endEvent id="e2" /><bpmn:endEvent id="e3" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="wait" />
    <bpmn:sequenceFlow id="f2" sourceRef="wait" targetRef="choice" />
    <bpmn:sequenceFlow id="f3" sourceRef="choice" targetRef="e1">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression"
        language="https://www.omg.org/spec/DMN/20191111/FEEL/"
        >amount &gt; 10</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="f4" sourceRef="choice" targetRef="e2">
      <bpmn:conditionExpression xsi:type="bpmn:tFormalExpression"
        >count(//item) &gt; 1</bpmn:conditionExpression>
    </bpmn:sequenceFlow>
    <bpmn:sequenceFlow id="f5" sourceRef="choice" targetRef="e3" />
  </bpmn:process>""",
    ),
}


def write(folder: Path, name: str, body: str, attributes: str = "") -> Path:
    path = folder / name
    path.write_text(HEAD.format(attributes=attributes) + body + "\n</bpmn:definitions>\n")
    return path


@pytest.mark.parametrize("name", sorted(FILES))
def test_valid_files_pass_the_check(tmp_path, capsys, name):
    path = write(tmp_path, name, FILES[name])
    code = main(["fame", "check", str(path)])
    out = capsys.readouterr().out
    assert code == 0, out
    assert "structure: ok" in out


def test_processes_outside_pools_are_named_as_not_run(tmp_path, capsys):
    path = write(tmp_path, "pools.bpmn", FILES["pools.bpmn"])
    main(["fame", "check", str(path)])
    out = capsys.readouterr().out
    assert "pools Rover, Base" in out
    assert f"warning: {path}:22: process spare is in no pool: it is not run" in out


def test_silent_choices_are_warnings(tmp_path, capsys):
    path = write(tmp_path, "listener.bpmn", FILES["listener.bpmn"])
    main(["fame", "check", str(path)])
    warnings = [line for line in capsys.readouterr().out.splitlines() if "warning" in line]
    assert warnings == [
        f"warning: {path}:8: task work (Work): camunda:executionListener is ignored (not run)",
        f"warning: {path}:13: exclusiveGateway choice has 2 outgoing flows without a "
        "condition (f3, f4): the engine takes the first, f3",
    ]


def test_every_gap_of_a_file_is_named_at_once(tmp_path, capsys):
    attributes, body = GAPS["gaps.bpmn"]
    path = write(tmp_path, "gaps.bpmn", body, attributes)
    assert main(["fame", "check", str(path)]) == 1
    out = capsys.readouterr().out
    problems = [line.strip() for line in out.splitlines() if line.startswith(f"  {path}")]
    not_evaluated = (
        "an expression language robotale does not evaluate (it evaluates python or javascript)"
    )
    # the language URIs are quoted as the file writes them
    assert problems == [
        f"{path}:8:5: gappy: intermediateCatchEvent wait (Wait) is a timer without a date, "
        "duration or cycle (give a timeDate, timeDuration or timeCycle with a value, e.g. PT10S)",
        f"{path}:16:5: gappy: sequence flow f3 has a condition the engine cannot run: it is in "
        f"'https://www.omg.org/spec/DMN/20191111/FEEL/', {not_evaluated}",
        f"{path}:21:5: gappy: sequence flow f4 has a condition the engine cannot run: it is in "
        f"'http://www.w3.org/1999/XPath', {not_evaluated}",
    ]
    assert "Python syntax error" not in out


def test_several_broken_references_are_reported_together_with_what_cannot_run(tmp_path, capsys):
    body = """
  <bpmn:collaboration id="c"><bpmn:participant id="p" processRef="ghost" /></bpmn:collaboration>
  <bpmn:process id="real">
    <bpmn:startEvent id="start" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="nowhere" />
    <bpmn:task id="t"><bpmn:dataInputAssociation id="a">
      <bpmn:sourceRef>missing</bpmn:sourceRef></bpmn:dataInputAssociation></bpmn:task>
    <bpmn:userTask id="ask" name="Ask" />
  </bpmn:process>"""
    path = write(tmp_path, "broken.bpmn", body)
    assert main(["fame", "check", str(path)]) == 1
    out = capsys.readouterr().out
    problems = [line.strip() for line in out.splitlines() if line.startswith(f"  {path}")]
    # reading and deploying at once: the reader's three and the deployer's user task
    assert problems == [
        f"{path}:9:5: sequence flow f1 is dangling: its target (nowhere) is not an element of "
        "the same process or sub-process",
        f"{path}:10:5: task t has a data association with missing, which is no data object, "
        "data object reference, data store reference, input, output or property of process real",
        f"{path}:6:30: pool p refers to process ghost, which is not in the file (processes: real)",
        f"{path}:12:5: real: userTask ask (Ask) needs a person" + PERSON,
    ]
    # parse (what fame run uses) refuses the file with the reader's three
    with pytest.raises(ModelError) as error:
        parse(path)
    assert str(error.value).splitlines()[0] == f"{path}: 3 problems:"


def test_run_prints_the_warnings_before_the_tags(tmp_path, capsys):
    # the same warnings fame check prints, on standard error before the run's first line
    path = write(tmp_path, "listener.bpmn", FILES["listener.bpmn"])
    main(["fame", "check", str(path)])
    checked = [line for line in capsys.readouterr().out.splitlines() if line.startswith("warn")]
    main(["fame", "run", str(path), "--until", "1"])
    err = capsys.readouterr().err.splitlines()
    assert len(checked) == 2
    assert err[: len(checked)] == [f"# {line}" for line in checked]


# -- the folder of valid files, as several modellers write them ---------------------------------

VALID = Path(__file__).resolve().parent / "valid"

#: what each file of ``valid/`` holds that robotale cannot run (file, line, column, element,
#: sentence): all of it, named right; nothing else
CANNOT_RUN = {
    "adonis_artifacts.bpmn": [],
    "adonis_vendor_ids.bpmn": [],
    "genmymodel_qnames.bpmn": [],
    "bizagi_data.bpmn": [],
    "camunda_compensation.bpmn": [],
    "signavio_gaps.bpmn": [
        (
            10,
            5,
            "check",
            "task check (Check each) has a multi-instance marker with neither a "
            "loopCardinality nor a collection (loopDataInputRef or camunda:collection), so "
            "robotale cannot tell how many instances to run: give one, e.g. "
            "<bpmn:loopCardinality>3</bpmn:loopCardinality>",
        ),
        (13, 5, "approve", "userTask approve (Approve) needs a person" + PERSON),
        (
            22,
            5,
            "f4",
            "sequence flow f4 has a condition the engine cannot run: it is no Python or "
            "JavaScript, so it is read in 'http://www.w3.org/1999/XPath', the standard's default "
            "expression language when neither the element nor the file names one, which "
            "robotale does not evaluate (it evaluates python or javascript: give "
            'language="python" or language="javascript")',
        ),
    ],
}


def test_the_folder_holds_the_files_the_expectations_name():
    assert sorted(p.name for p in VALID.glob("*.bpmn")) == sorted(CANNOT_RUN)


@pytest.mark.parametrize("name", sorted(CANNOT_RUN))
def test_each_valid_file_is_read_and_every_gap_named_right(name, capsys):
    path = VALID / name
    code = main(["fame", "check", "--json", str(path)])
    report = json.loads(capsys.readouterr().out)
    found = [(p["line"], p["column"], p["element"], p["sentence"]) for p in report["problems"]]
    assert found == CANNOT_RUN[name]
    assert all(p["file"] == str(path) for p in report["problems"])
    assert code == (1 if CANNOT_RUN[name] else 0) and report["ok"] is (not CANNOT_RUN[name])
    assert "syntax error" not in json.dumps(report)


def test_vendor_ids_are_no_duplicates_and_names_print_on_one_line(capsys):
    path = VALID / "adonis_vendor_ids.bpmn"
    assert main(["fame", "check", str(path)]) == 0
    out = capsys.readouterr().out
    assert "is given to" not in out
    # the name's line break is one space; the ignored vendor element is named once
    assert out.splitlines()[-1] == (
        f"warning: {path}:11: task pick (Pick up parts): adonis:target is ignored (not run)"
    )
    assert len([line for line in out.splitlines() if "adonis:target" in line]) == 1


def test_a_standard_id_given_twice_is_still_named(tmp_path, capsys):
    text = (VALID / "adonis_vendor_ids.bpmn").read_text()
    path = tmp_path / "twice.bpmn"
    path.write_text(
        text.replace('<endEvent id="end" />', '<endEvent id="end" /><task id="pick" />')
    )
    assert main(["fame", "check", "--json", str(path)]) == 1
    problems = json.loads(capsys.readouterr().out)["problems"]
    assert [p["sentence"] for p in problems if p["element"] == "pick"] == [
        "the id 'pick' is given to 2 elements (lines 11, 17); each element needs its own id"
    ]


def test_the_files_run_as_the_specification_says(capsys):
    # the compensation file: book, pay (charge), then the end event compensates both, the
    # last completed first: pay by its compensation event sub-process, then book by its handler
    path = VALID / "camunda_compensation.bpmn"
    assert main(["fame", "run", str(path), "--until", "1"]) == 0
    steps = [tuple(line.split("\t")[2:4]) for line in capsys.readouterr().out.splitlines()]
    assert steps == [
        ("book", "start"),
        ("book", "complete"),
        ("pay", "start"),
        ("charge", "start"),
        ("charge", "complete"),
        ("pay", "complete"),
        ("undo_all", "start"),
        ("undo_all", "complete"),
        ("refund_payment", "start"),
        ("refund_start", "start"),
        ("refund_start", "complete"),
        ("refund", "start"),
        ("refund", "complete"),
        ("refund_payment", "complete"),
        ("cancel_booking", "start"),
        ("cancel_booking", "complete"),
    ]


def test_a_dangling_message_ref_is_named_as_such(tmp_path, capsys):
    body = """
  <bpmn:message id="Msg_known" name="known" />
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:intermediateCatchEvent id="wait">
      <bpmn:messageEventDefinition messageRef="Msg_gone" />
    </bpmn:intermediateCatchEvent>
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="wait" />
  </bpmn:process>"""
    path = write(tmp_path, "dangling.bpmn", body)
    assert main(["fame", "check", "--json", str(path)]) == 1
    (problem,) = json.loads(capsys.readouterr().out)["problems"]
    assert (problem["element"], problem["line"]) == ("wait", 9)
    assert problem["sentence"] == (
        "intermediateCatchEvent wait refers to message Msg_gone, which the file does not "
        'declare (messages: Msg_known; declare <bpmn:message id="Msg_gone" name="..."/> or '
        "name the element)"
    )


def test_a_file_that_is_no_xml_is_one_problem_in_json(tmp_path, capsys):
    path = tmp_path / "broken.bpmn"
    path.write_text("<bpmn:definitions>\n<oops")
    assert main(["fame", "check", "--json", str(path)]) == 1
    (problem,) = json.loads(capsys.readouterr().out)["problems"]
    assert (problem["file"], problem["line"], problem["element"]) == (str(path), 1, "")
    assert problem["sentence"].startswith("malformed XML: ")


def test_run_names_the_reading_and_the_deploying_problems_together(tmp_path, capsys):
    body = """
  <bpmn:process id="p" isExecutable="true">
    <bpmn:startEvent id="start" />
    <bpmn:sequenceFlow id="f1" sourceRef="start" targetRef="nowhere" />
    <bpmn:userTask id="ask" name="Ask" />
  </bpmn:process>"""
    path = write(tmp_path, "both.bpmn", body)
    assert main(["fame", "run", str(path), "--until", "1"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"robotale: {path}: 2 problems:",
        f"{path}:8: sequence flow f1 is dangling: its target (nowhere) is not an element of "
        "the same process or sub-process",
        f"{path}:9: p: userTask ask (Ask) needs a person" + PERSON,
    ]
