"""Inputs that used to get a traceback or a misleading sentence: each now gets one sentence
naming the file, line, column or option, exit status 1, and nothing is written."""

from __future__ import annotations

import json

import pytest

from robotale.cli import main

XES_BOOLEAN_ROLE = """<?xml version="1.0" encoding="UTF-8"?>
<log xes.version="1.0"><trace><string key="concept:name" value="1"/>
<event><string key="concept:name" value="send"/>
<date key="time:timestamp" value="2024-01-01T00:00:00Z"/>
<string key="msg_id" value="m1"/></event>
<event><string key="concept:name" value="receive"/>
<date key="time:timestamp" value="2024-01-01T00:00:01Z"/>
<boolean key="msg_role" value="true"/><string key="msg_id" value="m1"/></event>
</trace></log>
"""
OCEL = {
    "objectTypes": [{"name": "robot", "attributes": []}],
    "eventTypes": [{"name": "takeoff", "attributes": []}],
    "objects": [{"id": "r1", "type": "robot"}],
    "events": [{"id": "e1", "type": "takeoff", "time": "2024-01-01T00:00:00Z"}],
}


def run(capsys, *args: str) -> tuple[int, str]:
    code = main(list(args))
    return code, capsys.readouterr().err.strip()


def one_sentence(message: str) -> bool:
    return message.startswith("robotale: ") and "\n" not in message and "Traceback" not in message


@pytest.mark.parametrize(
    ("name", "content", "expected"),
    [
        ("bom.csv", b"\xef\xbb\xbf", "bom.csv holds nothing but a byte order mark"),
        (
            "quote.csv",
            b'time,"activity\n2024-01-01T00:00:00Z,a\n',
            "quote.csv line 1: the header is not readable CSV",
        ),
        (
            "twice.csv",
            b"time,activity,activity\n2024-01-01T00:00:00Z,a,b\n",
            "twice.csv line 1: the column 'activity' appears 2 times (columns 2, 3)",
        ),
        (
            "wide.csv",
            b"time,activity\n2024-01-01T00:00:00Z,2024-01-01T00:00:00Z,a\n",
            "wide.csv line 2: 3 cells, but the header names 2 columns.",
        ),
        (
            "roles.xes",
            XES_BOOLEAN_ROLE.encode(),
            "roles.xes line 6: the message role is the boolean true, not text",
        ),
        (
            "log.csv",
            json.dumps(OCEL).encode(),
            "log.csv is JSON, not CSV: an OCEL 2.0 log is read as one when its name ends in",
        ),
    ],
)
def test_bad_logs(tmp_path, capsys, graph_counts, log_name, name, content, expected):
    path = tmp_path / name
    path.write_bytes(content)
    before = graph_counts()
    code, message = run(capsys, "ingest", str(path), "--log", log_name)
    assert code == 1 and one_sentence(message), message
    assert expected in message
    assert graph_counts() == before


def test_a_value_too_long_for_an_index(tmp_path, capsys, graph_counts, log_name):
    path = tmp_path / "long.csv"
    huge = "x" * 10_000_000
    path.write_text(
        f"time,activity,robot\n2024-01-01T00:00:00Z,a,r\n2024-01-01T00:00:01Z,{huge},r\n"
    )
    before = graph_counts()
    code, message = run(capsys, "ingest", str(path), "--log", log_name)
    assert code == 1 and one_sentence(message), message
    assert "Event 2 of the log (id '1') has 10,000,000 bytes as its activity" in message
    assert len(message) < 400
    assert graph_counts() == before


@pytest.mark.parametrize("command", ["perspectives", "report"])
@pytest.mark.parametrize("threshold", ["nan", "-5", "120", "inf"])
def test_a_battery_threshold_that_is_no_percentage(
    tmp_path, capsys, thesis_csv, threshold, command
):
    report = tmp_path / "report.json"
    code, message = run(
        capsys, command, str(thesis_csv), "--json", str(report), "--threshold", threshold
    )
    assert code == 1 and one_sentence(message), message
    shown = f"{float(threshold):g}"
    assert f"--threshold {shown} is not usable: give a number from 0 to 100 percent" in message
    assert not report.exists()


def test_ocel_output_that_is_a_folder(tmp_path, capsys):
    folder = tmp_path / "out"
    folder.mkdir()
    csv = tmp_path / "log.csv"
    code, message = run(capsys, "prepare", str(tmp_path), "--out", str(csv), "--ocel", str(folder))
    assert code == 1 and one_sentence(message), message
    assert f"{folder} is a folder: give the name of the file to write" in message
    assert not csv.exists() and list(folder.iterdir()) == []
