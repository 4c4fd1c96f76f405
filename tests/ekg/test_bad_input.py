"""Every bad input of `robotale ingest` is one sentence, and Neo4j is left as it was."""

from __future__ import annotations

import csv
import signal
import subprocess
import sys
import time

import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.logs import list_logs, log_summary
from robotale.neo4j_server.server import free_port

GOOD = "time,activity,robot\n2023-05-16T10:00:00Z,takeoff,drone\n2023-05-16T10:00:05Z,land,drone\n"


def ingest(capsys, *args: str) -> tuple[int, str]:
    code = main(["ingest", *args])
    captured = capsys.readouterr()
    return code, captured.err.strip()


def one_sentence(message: str) -> bool:
    return message.startswith("robotale: ") and message.count("\n") == 0


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        (None, r"log\.csv does not exist\."),
        (b"", r"log\.csv is empty\."),
        (
            "time,activity\n2023-05-16T10:00Z,M\xe4hen\n".encode("latin-1"),
            r"log\.csv is not UTF-8 text \(byte 0xe4 on line 2\); save it as UTF-8\.",
        ),
        (
            b"time,robot\n2023-05-16T10:00Z,drone\n",
            r"log\.csv has no activity column \(looked for activity, concept:name",
        ),
        (
            b"time,activity\n2023-05-16T10:00Z,a\n2023-05-16 25:99,b\n",
            r"log\.csv line 3: cannot read the timestamp '2023-05-16 25:99'",
        ),
        (
            b'time,activity,"x`}) DETACH DELETE n //"\n2023-05-16T10:00Z,a,1\n',
            r"has a column named 'x`}\) DETACH DELETE n //', which cannot become a property name",
        ),
    ],
)
def test_bad_files(tmp_path, capsys, graph_counts, log_name, content, expected):
    path = tmp_path / "log.csv"
    if content is not None:
        path.write_bytes(content)
    before = graph_counts()
    code, message = ingest(capsys, str(path), "--log", log_name)
    assert code == 1
    assert one_sentence(message), message
    assert pd.Series([message]).str.contains(expected).all(), message
    assert graph_counts() == before


@pytest.mark.parametrize(
    ("entities", "expected"),
    [
        (
            "robot,battery",
            r"The event log has no column 'battery' to use as an entity type; its "
            r"columns are activity, case, id, lifecycle, robot\.",
        ),
        (
            "robot`}) MATCH (n) DETACH DELETE n //",
            r"no column 'robot`}\) MATCH \(n\) DETACH DELETE n //' to use as an entity type",
        ),
    ],
)
def test_bad_entity_types(tmp_path, capsys, graph_counts, log_name, entities, expected):
    path = tmp_path / "log.csv"
    path.write_text(GOOD)
    before = graph_counts()
    code, message = ingest(capsys, str(path), "--log", log_name, "--entities", entities)
    assert code == 1 and one_sentence(message), message
    assert pd.Series([message]).str.contains(expected).all(), message
    assert graph_counts() == before


def test_bad_aggregation_key(tmp_path, capsys, graph_counts, log_name):
    path = tmp_path / "log.csv"
    path.write_text(GOOD)
    before = graph_counts()
    code, message = ingest(capsys, str(path), "--log", log_name, "--aggregate", "activity,`x`")
    assert code == 1 and one_sentence(message), message
    assert "The aggregation key '`x`' cannot be used as a Neo4j name" in message
    assert graph_counts() == before


def test_existing_log_name(tmp_path, capsys, graph_counts, log_name):
    path = tmp_path / "log.csv"
    path.write_text(GOOD)
    assert ingest(capsys, str(path), "--log", log_name) == (0, "")
    before = graph_counts()
    code, message = ingest(capsys, str(path), "--log", log_name)
    assert code == 1 and one_sentence(message), message
    assert f"A log named '{log_name}' already exists in Neo4j; use --replace" in message
    assert graph_counts() == before
    # The name is refused before the file is read: a file that could not be read at all
    # gets the same answer, and nothing of a reading is reported.
    unreadable = tmp_path / "unreadable.csv"
    unreadable.write_text("time,activity,robot\nnot a time,takeoff,drone\n")
    code = main(["ingest", str(unreadable), "--log", log_name])
    captured = capsys.readouterr()
    assert code == 1 and captured.out == "", captured.out
    assert f"A log named '{log_name}' already exists in Neo4j" in captured.err
    assert graph_counts() == before


def test_digits_beyond_64_bits_are_stored_as_text(tmp_path, capsys, neo4j_driver, log_name):
    """A column of digits too long for Neo4j's integers (a serial number) is stored as the
    file writes it, as text; the column's short numbers become text too, one type a column."""
    path = tmp_path / "log.csv"
    path.write_text(
        "time,activity,robot,serial\n"
        "2023-05-16T10:00:00Z,takeoff,drone,123456789012345678901234567890\n"
        "2023-05-16T10:00:05Z,land,drone,-99999999999999999999\n"
        "2023-05-16T10:00:09Z,charge,drone,7\n"
    )
    assert ingest(capsys, str(path), "--log", log_name) == (0, "")
    with open(path, newline="") as file:
        in_file = sorted(row["serial"] for row in csv.DictReader(file))
    records = neo4j_driver.execute_query(
        "MATCH (e:Event {log: $log}) WHERE e.serial IS NOT NULL RETURN e.serial AS serial",
        log=log_name,
    ).records
    assert sorted(record["serial"] for record in records) == in_file


def test_neo4j_not_reachable(tmp_path, capsys, monkeypatch):
    path = tmp_path / "log.csv"
    path.write_text(GOOD)
    monkeypatch.delenv("NEO4J_URI")
    monkeypatch.setenv("ROBOTALE_HOME", str(tmp_path / "home"))
    monkeypatch.setenv("ROBOTALE_NEO4J_BOLT_PORT", str(free_port()))
    code, message = ingest(capsys, str(path))
    assert code == 1 and one_sentence(message), message
    assert "Neo4j is not running at bolt://127.0.0.1:" in message
    assert "start it with `robotale neo4j start`, or set NEO4J_URI" in message


# -- a failure in the middle of writing -------------------------------------------------------


def big_log(path, events: int) -> None:
    times = pd.date_range("2024-01-01", periods=events, freq="s", tz="UTC")
    pd.DataFrame(
        {
            "time": times.strftime("%Y-%m-%dT%H:%M:%SZ"),
            "activity": [f"a{i % 7}" for i in range(events)],
            "robot": [f"r{i % 5}" for i in range(events)],
            "case": [str(i // 50) for i in range(events)],
        }
    ).to_csv(path, index=False)


def interrupt_while_writing(path, name: str, driver, *extra: str) -> subprocess.CompletedProcess:
    """Run `robotale ingest` and press Ctrl-C once its first events are in Neo4j."""
    command = [
        sys.executable,
        "-m",
        "robotale",
        "ingest",
        str(path),
        "--log",
        name,
        "--entities",
        "robot,case",
        *extra,
    ]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while process.poll() is None and time.monotonic() < deadline:
        if _building(driver):
            process.send_signal(signal.SIGINT)
            break
        time.sleep(0.05)
    stdout, stderr = process.communicate(timeout=300)
    return subprocess.CompletedProcess(command, process.returncode, stdout, stderr)


def _building(driver) -> bool:
    return any(log["status"] == "building" for log in list_logs(driver))


@pytest.mark.slow
def test_interrupted_ingest_leaves_nothing(tmp_path, neo4j_driver, graph_counts, log_name):
    path = tmp_path / "big.csv"
    big_log(path, 40_000)
    before = graph_counts()
    result = interrupt_while_writing(path, log_name, neo4j_driver)
    assert result.returncode == 130, result.stderr
    assert "robotale: interrupted" in result.stderr
    assert graph_counts() == before
    assert log_name not in {log["name"] for log in list_logs(neo4j_driver)}


@pytest.mark.slow
def test_interrupted_replace_keeps_the_old_log(
    tmp_path, capsys, neo4j_driver, graph_counts, log_name
):
    small = tmp_path / "small.csv"
    small.write_text(GOOD)
    assert ingest(capsys, str(small), "--log", log_name, "--entities", "robot")[0] == 0
    old = log_summary(neo4j_driver, log_name)
    before = graph_counts()
    path = tmp_path / "big.csv"
    big_log(path, 40_000)
    result = interrupt_while_writing(path, log_name, neo4j_driver, "--replace")
    assert result.returncode == 130, result.stderr
    assert graph_counts() == before
    assert log_summary(neo4j_driver, log_name) == old
    assert [log["name"] for log in list_logs(neo4j_driver) if log_name in log["name"]] == [log_name]
