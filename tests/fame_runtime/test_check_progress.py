"""`fame check` finds flows that can never complete: loops of gateways only, parallel joins
that wait for themselves, element ids used twice; and `fame run` refuses a negative --until.
Each model is small enough that the expected answer is read off it by hand."""

from __future__ import annotations

import pytest

from robotale.cli import main

HEAD = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<bpmn:definitions xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" id="d">\n'
    '<bpmn:process id="p" isExecutable="true">\n'
)
TAIL = "</bpmn:process></bpmn:definitions>\n"


def flows(*pairs: str) -> str:
    return "".join(
        f'<bpmn:sequenceFlow id="f{i}" sourceRef="{pair.split(">")[0]}" '
        f'targetRef="{pair.split(">")[1]}"/>\n'
        for i, pair in enumerate(pairs)
    )


MODELS = {
    # g1 -> g2 -> g1: no task in the loop, the token circles without doing anything.
    "gateway_loop": (
        '<bpmn:startEvent id="start"/><bpmn:exclusiveGateway id="g1"/>'
        '<bpmn:exclusiveGateway id="g2"/><bpmn:task id="t"/><bpmn:endEvent id="end"/>'
        + flows("start>g1", "g1>g2", "g2>g1", "g2>t", "t>end"),
        "g1, g2 form a loop of gateways only",
    ),
    # The join needs a token from `again`, which only runs after the join has fired.
    "deadlock": (
        '<bpmn:startEvent id="start"/><bpmn:parallelGateway id="join"/><bpmn:task id="work"/>'
        '<bpmn:exclusiveGateway id="again"/><bpmn:endEvent id="end"/>'
        + flows("start>join", "join>work", "work>again", "again>join", "again>end"),
        "join joins in parallel but its flow from again can only carry a token after the "
        "join itself has fired",
    ),
    # Two elements called `start`: the parser keeps one, the check names both lines.
    "duplicate_ids": (
        '<bpmn:startEvent id="start"/>\n<bpmn:task id="start"/>\n<bpmn:endEvent id="end"/>\n'
        + flows("start>end"),
        "the id 'start' is given to 2 elements (lines 4, 5)",
    ),
}


@pytest.mark.parametrize("model", sorted(MODELS))
def test_a_flow_that_cannot_complete_is_a_problem(tmp_path, capsys, model):
    body, expected = MODELS[model]
    path = tmp_path / f"{model}.bpmn"
    path.write_text(HEAD + body + TAIL)
    assert main(["fame", "check", str(path)]) == 1
    out = capsys.readouterr().out
    assert "structure: the engine cannot run" in out
    assert expected in out


def test_a_parallel_loop_closed_by_an_exclusive_merge_is_fine(tmp_path, capsys):
    # The same loop as `deadlock`, but entered through an exclusive merge and with a proper
    # split before the join: every join gets its tokens from the split.
    body = (
        '<bpmn:startEvent id="start"/><bpmn:exclusiveGateway id="merge"/>'
        '<bpmn:parallelGateway id="split"/><bpmn:task id="a"/><bpmn:task id="b"/>'
        '<bpmn:parallelGateway id="join"/><bpmn:exclusiveGateway id="again"/>'
        '<bpmn:endEvent id="end"/>'
        + flows(
            "start>merge",
            "merge>split",
            "split>a",
            "split>b",
            "a>join",
            "b>join",
            "join>again",
            "again>merge",
            "again>end",
        )
    )
    path = tmp_path / "fine.bpmn"
    path.write_text(HEAD + body + TAIL)
    assert main(["fame", "check", str(path)]) == 0, capsys.readouterr().out
    assert "structure: ok" in capsys.readouterr().out


@pytest.mark.parametrize("until", ["-5", "nan"])
def test_fame_run_refuses_an_until_below_zero(tmp_path, capsys, until):
    path = tmp_path / "fine.bpmn"
    path.write_text(HEAD + '<bpmn:startEvent id="s"/>' + TAIL)
    assert main(["fame", "run", str(path), "--until", until]) == 1
    err = capsys.readouterr().err.strip()
    assert err == (
        f"robotale: --until {float(until):g} is not usable: give a number of at least 0 seconds."
    )


def test_run_names_a_shared_id_instead_of_a_missing_start(tmp_path, capsys):
    body, expected = MODELS["duplicate_ids"]
    path = tmp_path / "shared.bpmn"
    path.write_text(HEAD + body + TAIL)
    assert main(["fame", "run", str(path)]) == 1
    err = capsys.readouterr().err
    assert err == f"robotale: {path}: {expected}; each element needs its own id\n"
