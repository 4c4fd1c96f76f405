"""`robotale ingest --append`: runs added to a stored log give the graph of one ingest of all
of them (also when they bring a column the log lacks), and a refused or interrupted append
leaves the log as it was.

The runs are the thesis authors' five recorded runs, each repeated twice as a run of
its own (new case and event ids, a day later each time): ten real multi-robot runs that
number their messages from ``m_1`` again, as simulated runs do.
"""

from __future__ import annotations

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.append import append_ekg
from robotale.ekg.columnar import stored_table
from robotale.ekg.connection import database
from robotale.ekg.logs import delete_log, log_info, log_summary, log_values
from robotale.eventlog.readers import read_csv
from robotale.eventlog.schema import EVENT_ID
from robotale.queries import cypher

ENTITIES = "robot,msg_id"
KEYS = ("activity", "activity,robot")


@pytest.fixture(scope="module")
def runs(thesis_csv) -> pd.DataFrame:
    """Ten runs in the thesis log's own CSV columns, numbered run_01 ... run_10."""
    raw = pd.read_csv(thesis_csv, dtype=str)
    times = pd.to_datetime(raw["time"], format="ISO8601")
    # The recorded runs lie a day or so apart; within a run no pause lasts an hour.
    raw["case"] = (times.diff() > pd.Timedelta(hours=1)).cumsum().astype(str)
    cases = sorted(raw["case"].unique(), key=int)
    assert len(cases) == 5
    parts = []
    for run in range(1, 11):
        part = raw[raw["case"] == cases[(run - 1) % 5]].copy()
        part["case"] = f"run_{run:02d}"
        part["event_id"] = f"r{run}_" + part["event_id"]
        shifted = times[part.index] + pd.Timedelta(days=run)
        part["time"] = shifted.map(lambda t: t.isoformat())
        parts.append(part)
    return pd.concat(parts, ignore_index=True)


def ingest(capsys, path: Path, name: str, *options: str) -> str:
    keys = [option for key in KEYS for option in ("--aggregate", key)]
    code = main(["ingest", str(path), "--log", name, "--entities", ENTITIES, *keys, *options])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    return captured.out


def rows(driver, query: str, **parameters) -> list[dict]:
    records, _, _ = driver.execute_query(cypher(query), parameters, database_=database())
    return [record.data() for record in records]


def content(driver, name: str) -> dict:
    """Everything the comparison covers: counts by kind and type, every DF_C edge with its
    count and durations, where every entity begins, and what the Log node records."""
    info = log_info(driver, name)
    df_c, begins = {}, {}
    for kind in info["classTypes"]:
        for entity_type in info["entityTypes"]:
            for edge in rows(
                driver, "ekg_class_graph", log=name, type=kind, entityType=entity_type
            ):
                pair = (kind, entity_type, edge["source"]["id"], edge["target"]["id"])
                df_c[pair] = (edge["count"], edge["meanSeconds"], edge["medianSeconds"])
            for entry in rows(
                driver, "discover_entry_nodes", log=name, type=kind, entityType=entity_type
            ):
                begins[(kind, entity_type, entry["entity"], entry["class"])] = entry["cases"]
    values = log_values(driver, name)
    return {
        "counts": log_summary(driver, name)["counts"],
        "df_c": df_c,
        "begins": begins,
        "values": {k: sorted(map(str, v)) if isinstance(v, list) else v for k, v in values.items()},
        "types": (sorted(info["entityTypes"]), sorted(info["classTypes"])),
        "properties": sorted(info["properties"]),
    }


def assert_same(ours: dict, expected: dict) -> None:
    assert ours["counts"] == expected["counts"]
    assert ours["begins"] == expected["begins"]
    assert ours["values"] == expected["values"]
    assert ours["types"] == expected["types"] and ours["properties"] == expected["properties"]
    assert ours["df_c"].keys() == expected["df_c"].keys()
    for pair, (count, mean, median) in expected["df_c"].items():
        assert ours["df_c"][pair][0] == count, pair
        assert ours["df_c"][pair][1:] == pytest.approx((mean, median), abs=1e-6), pair


@pytest.fixture
def other_name(neo4j_driver, log_name):
    name = f"{log_name}_whole"
    yield name
    delete_log(neo4j_driver, name)


def test_appending_runs_gives_the_graph_of_one_ingest(
    tmp_path, capsys, neo4j_driver, runs, log_name, other_name
):
    first = runs["case"] <= "run_05"
    # The later runs bring an attribute the first ones lack: the append adds the property.
    runs = runs.assign(charge=np.where(first, np.nan, np.linspace(99.5, 20.25, len(runs))))
    runs.to_csv(tmp_path / "all.csv", index=False)
    runs[first].drop(columns="charge").to_csv(tmp_path / "first.csv", index=False)
    runs[~first].to_csv(tmp_path / "next.csv", index=False)
    ingest(capsys, tmp_path / "all.csv", other_name)
    ingest(capsys, tmp_path / "first.csv", log_name)
    before = content(neo4j_driver, log_name)
    out = ingest(capsys, tmp_path / "next.csv", log_name, "--append")
    assert f"Log '{log_name}': {int((~first).sum()):,} appended" in out
    whole = content(neo4j_driver, other_name)
    appended = content(neo4j_driver, log_name)
    assert_same(appended, whole)
    # The append did change what the first five runs had: the comparison is not vacuous.
    assert appended["counts"]["events"] == len(runs) == 2 * before["counts"]["events"]
    assert appended["counts"]["cases"] == 10 and appended["values"]["case"][-1] == "run_10"
    changed = [p for p, v in before["df_c"].items() if appended["df_c"][p] != v]
    assert changed, "the DF_C edges of the first runs were updated"
    assert all(appended["begins"][k] == 2 * v for k, v in before["begins"].items())
    # Each entity is one node for the whole log: three robots, however many runs.
    assert appended["counts"]["entities:robot"] == 3
    assert log_info(neo4j_driver, log_name)["events"] == len(runs)

    # The columnar copy kept at the first ingest holds five runs: analyses read all ten.
    def table(name: str) -> pd.DataFrame:
        events = stored_table(neo4j_driver, name)
        return events.sort_values(EVENT_ID, kind="stable").reset_index(drop=True)

    pd.testing.assert_frame_equal(table(log_name), table(other_name))
    assert len(table(log_name)) == len(runs)
    assert "charge" not in before["properties"] and "charge" in appended["properties"]
    assert table(log_name)["charge"].notna().sum() == (~first).sum()


def test_refused_appends_change_nothing(
    tmp_path, capsys, neo4j_driver, runs, log_name, graph_counts
):
    first = runs["case"] <= "run_02"
    runs[first].to_csv(tmp_path / "first.csv", index=False)
    ingest(capsys, tmp_path / "first.csv", log_name)
    before, counted = content(neo4j_driver, log_name), graph_counts()

    def refused(frame: pd.DataFrame, message: str, *options: str, name: str = log_name):
        path = tmp_path / "append.csv"
        frame.to_csv(path, index=False)
        code = main(["ingest", str(path), "--log", name, "--append", *options])
        err = capsys.readouterr().err
        assert code == 1 and message in err, err
        assert len(err.strip().splitlines()) == 1, err
        assert content(neo4j_driver, log_name) == before and graph_counts() == counted

    third = runs[runs["case"] == "run_03"]
    refused(runs[runs["case"] == "run_02"], f"The case 'run_02' is already in the log '{log_name}'")
    refused(third, "There is no log named 'no such log'", name="no such log")
    refused(third.drop(columns="field"), "no column 'field', which the log")
    refused(third, "has the entity types robot, msg_id, not robot", "--entities", "robot")
    refused(third, "has the class types", "--aggregate", "activity")
    refused(
        third.assign(event_id=runs[first]["event_id"].iloc[: len(third)].to_numpy()),
        "is already in the log",
    )
    code = main(["ingest", str(tmp_path / "append.csv"), "--append", "--replace"])
    assert code == 1 and "give one" in capsys.readouterr().err


def test_an_interrupted_append_leaves_the_log_as_it_was(
    tmp_path, capsys, neo4j_driver, runs, log_name, graph_counts
):
    """Ctrl-C while the append waits for a class node another transaction holds: once that
    transaction lets go, the append stops at its next batch and Neo4j rolls it all back."""
    runs[runs["case"] <= "run_02"].to_csv(tmp_path / "first.csv", index=False)
    ingest(capsys, tmp_path / "first.csv", log_name)
    before, counted = content(neo4j_driver, log_name), graph_counts()
    third = read_csv_runs(tmp_path, runs[runs["case"] == "run_03"])
    with neo4j_driver.session(database=database()) as session:
        holder = session.begin_transaction()
        holder.run(
            "MATCH (c:Class {log: $log, type: 'activity'}) SET c.held = true", log=log_name
        ).consume()
        release = threading.Thread(target=_interrupt_when_blocked, args=(neo4j_driver, holder))
        release.start()
        try:
            with pytest.raises(KeyboardInterrupt):
                append_ekg(neo4j_driver, third, log_name)
        finally:
            release.join()
    assert content(neo4j_driver, log_name) == before
    assert graph_counts() == counted


def read_csv_runs(tmp_path: Path, frame: pd.DataFrame) -> pd.DataFrame:
    path = tmp_path / "runs.csv"
    frame.to_csv(path, index=False)
    return read_csv(path)


def _interrupt_when_blocked(driver, holder) -> None:
    """Wait until a transaction waits for the holder's locks, press Ctrl-C, let go."""
    deadline = time.monotonic() + 120
    try:
        while time.monotonic() < deadline:
            records, _, _ = driver.execute_query(
                "SHOW TRANSACTIONS YIELD status WHERE status STARTS WITH 'Blocked' RETURN count(*)",
                database_=database(),
            )
            if records[0][0]:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)  # the signal handler runs in the main thread
                break
            time.sleep(0.05)
    finally:
        holder.rollback()
