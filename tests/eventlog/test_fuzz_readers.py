"""Fuzzed event logs (CSV, XES, and the JSON of OCEL 2.0 given where a log is expected): the
readers answer every input with a log or with robotale's own error, never with another
exception. A log that is read is also written as OCEL 2.0 and must load as JSON again.

A few hundred examples per run; `make fuzz` runs many more (ROBOTALE_FUZZ_EXAMPLES)."""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from xml.sax.saxutils import quoteattr

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from robotale.errors import RobotaleError
from robotale.eventlog.readers import read_log_with_reading
from robotale.eventlog.reading import format_reading
from robotale.eventlog.writers import write_ocel

FUZZ = settings(
    max_examples=int(os.environ.get("ROBOTALE_FUZZ_EXAMPLES", "200")),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

NAMES = st.sampled_from(
    ["time", "timestamp", "time:timestamp", "activity", "concept:name", "case", "robot",
     "org:resource", "lifecycle", "lifecycle:transition", "msg_id", "msg_role", "x", "y",
     "battery", "state", "id", "", " ", "a,b", '"', "\ufeff"]
)  # fmt: skip
CELLS = st.one_of(
    st.sampled_from(
        ["2024-01-01T00:00:00Z", "2024-01-01 00:00:01+01:00", "2024-13-45", "1704067200",
         "NaN", "nan", "-", "", " NA ", "null", "start", "complete", "START", "send", "receive",
         "1e400", "-0", "inf", "true", '"', '""', "\n", "\r", "a\u0000b", "\ud7ff"]
    ),
    st.text(max_size=10),
    st.integers().map(str),
    st.floats().map(repr),
)  # fmt: skip


@st.composite
def csv_files(draw) -> bytes:
    header = draw(st.lists(NAMES, max_size=7))
    rows = draw(st.lists(st.lists(CELLS, max_size=len(header) + 1), max_size=8))
    if draw(st.booleans()):
        out = io.StringIO()
        csv.writer(out).writerows([header, *rows])
        text = out.getvalue()
    else:  # no quoting at all: commas and quotes in cells break the rows
        text = "\n".join(",".join(row) for row in [header, *rows])
    prefix = draw(st.sampled_from(["", "\ufeff", " ", "\n"]))
    return (prefix + text).encode("utf-8", "surrogatepass")


XES_KINDS = st.sampled_from(["string", "date", "int", "float", "boolean", "id", "list", "foo"])


@st.composite
def xes_files(draw) -> bytes:
    def attribute() -> str:
        kind, key, value = draw(XES_KINDS), draw(NAMES), draw(CELLS)
        return f"<{kind} key={quoteattr(key)} value={quoteattr(value)}/>"

    traces = []
    for _ in range(draw(st.integers(0, 3))):
        events = "".join(
            "<event>" + "".join(attribute() for _ in range(draw(st.integers(0, 5)))) + "</event>"
            for _ in range(draw(st.integers(0, 4)))
        )
        own = "".join(attribute() for _ in range(draw(st.integers(0, 2))))
        traces.append(f"<trace>{own}{events}</trace>")
    text = f'<?xml version="1.0" encoding="UTF-8"?><log xes.version="1.0">{"".join(traces)}</log>'
    cut = draw(st.integers(0, len(text)))  # sometimes a file that ends too early
    return text.encode("utf-8", "surrogatepass")[: cut if draw(st.booleans()) else None]


JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text(max_size=8),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    ),
    max_leaves=20,
)
OCEL_KEYS = st.sampled_from(["objectTypes", "eventTypes", "objects", "events"])


@pytest.fixture(scope="module")
def folder() -> Iterator[Path]:
    with tempfile.TemporaryDirectory() as work:
        yield Path(work)


def read_or_refuse(folder: Path, name: str, content: bytes) -> None:
    """Read the log; if it is read, describe it and write it as OCEL 2.0 JSON that loads."""
    path = folder / name
    path.write_bytes(content)
    try:
        log, reading = read_log_with_reading(path)
        format_reading(reading)
        write_ocel(log, folder / "out.json")
    except RobotaleError:
        return
    json.loads((folder / "out.json").read_text(encoding="utf-8"))


@FUZZ
@given(content=csv_files())
# Inputs fuzzing found once: more cells than the header in the first row (pandas took the
# first column for the index), and then a lone CR among them; a log naming no robot.
@example(content=b"time,activity\n2024-01-01T00:00:00Z,2024-01-01T00:00:00Z,x\n")
@example(content=b"time\n2024-01-01T00:00:00Z,0\r0")
@example(content=b"time,activity\n2024-01-01T00:00:00Z,a\n")
def test_csv_text(folder, content):
    read_or_refuse(folder, "log.csv", content)


@FUZZ
@given(content=st.binary(max_size=300))
def test_csv_bytes(folder, content):
    read_or_refuse(folder, "log.csv", content)


@FUZZ
@given(content=xes_files())
def test_xes(folder, content):
    read_or_refuse(folder, "log.xes", content)


@FUZZ
@given(document=st.dictionaries(OCEL_KEYS, JSON, max_size=4) | JSON)
# Found by fuzzing once: a list of objects given as a plain value.
@example(document={"objects": True})
def test_ocel_json_where_a_log_is_expected(folder, document):
    for name in ("log.jsonocel", "log.csv"):
        read_or_refuse(folder, name, json.dumps(document).encode())
