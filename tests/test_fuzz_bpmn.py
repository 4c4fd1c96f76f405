"""Fuzzed BPMN files: the parser and `fame check` answer each with a model, a report or
robotale's own error, never another exception. Files are real models of the test suite cut,
spliced and given random attribute values, and models built from random BPMN elements.

A few hundred examples per run; `make fuzz` runs many more (ROBOTALE_FUZZ_EXAMPLES)."""

from __future__ import annotations

import os
from contextlib import suppress
from pathlib import Path
from xml.sax.saxutils import quoteattr

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from robotale.errors import RobotaleError
from robotale.fame_runtime.check import check
from robotale.fame_runtime.parser import parse_bytes

FUZZ = settings(
    max_examples=int(os.environ.get("ROBOTALE_FUZZ_EXAMPLES", "200")),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
MODELS = sorted((Path(__file__).parent / "fame_runtime" / "models").glob("*.bpmn"))
SEEDS = [path.read_bytes() for path in MODELS]

TAGS = st.sampled_from(
    ["startEvent", "endEvent", "task", "scriptTask", "serviceTask", "callActivity",
     "subProcess", "exclusiveGateway", "parallelGateway", "inclusiveGateway",
     "eventBasedGateway", "intermediateCatchEvent", "intermediateThrowEvent", "boundaryEvent",
     "sequenceFlow", "signalEventDefinition", "timerEventDefinition", "errorEventDefinition",
     "conditionExpression", "timeDuration", "script", "participant", "collaboration"]
)  # fmt: skip
ATTRIBUTES = st.sampled_from(
    ["id", "name", "sourceRef", "targetRef", "attachedToRef", "calledElement", "signalRef",
     "default", "scriptFormat", "processRef", "isExecutable", "cancelActivity", "xsi:type"]
)  # fmt: skip
IDS = st.sampled_from(["s", "e", "t", "g", "f1", "f2", "p", "", "s e", "1", "${x}", "-"])
VALUES = IDS | st.text(max_size=8)


@st.composite
def element(draw, depth: int = 0) -> str:
    tag = draw(TAGS)
    attributes = "".join(
        f" {draw(ATTRIBUTES)}={quoteattr(draw(VALUES))}" for _ in range(draw(st.integers(0, 4)))
    )
    if depth < 2 and draw(st.booleans()):
        children = "".join(draw(element(depth + 1)) for _ in range(draw(st.integers(0, 3))))
    else:
        children = draw(st.sampled_from(["", "PT5S", "x > 1", "${a}", "R3/PT1S"]))
    return f"<bpmn:{tag}{attributes}>{children}</bpmn:{tag}>"


@st.composite
def built_models(draw) -> bytes:
    body = "".join(draw(element()) for _ in range(draw(st.integers(0, 8))))
    process = f'<bpmn:process id="p" isExecutable="true">{body}</bpmn:process>'
    return (
        '<?xml version="1.0" encoding="UTF-8"?><bpmn:definitions '
        'xmlns:bpmn="http://www.omg.org/spec/BPMN/20100524/MODEL" '
        'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="d">'
        f"{process}</bpmn:definitions>"
    ).encode("utf-8", "surrogatepass")


@st.composite
def mutated_models(draw) -> bytes:
    data = bytearray(draw(st.sampled_from(SEEDS)))
    for _ in range(draw(st.integers(1, 4))):
        start = draw(st.integers(0, len(data)))
        end = draw(st.integers(start, min(len(data), start + 80)))
        data[start:end] = draw(
            st.sampled_from([b"", b'"', b"<", b"/>", b"id", b"x"]) | st.binary(max_size=8)
        )
    return bytes(data)


def parse_and_check(data: bytes) -> None:
    with suppress(RobotaleError):
        check(parse_bytes(data, "fuzzed.bpmn"))


def test_the_seeds_are_models():
    assert len(SEEDS) >= 5
    for seed, path in zip(SEEDS, MODELS, strict=True):
        assert parse_bytes(seed, path).processes, path


@FUZZ
@given(data=mutated_models())
def test_mutated_models(data):
    parse_and_check(data)


@FUZZ
@given(data=built_models())
def test_models_of_random_elements(data):
    parse_and_check(data)
