"""One writer per log name, against the session's Neo4j: concurrent ingests, stale locks."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import threading
import uuid

import pandas as pd
import pytest

from robotale.ekg import build_ekg
from robotale.ekg.build import _undo
from robotale.ekg.connection import connect, database
from robotale.ekg.logs import delete_log, delete_log_locked, list_logs, log_run, log_summary
from robotale.ekg.writelock import LogBusy, log_write_lock
from robotale.errors import InputError
from robotale.eventlog.readers import read_csv


@pytest.fixture(scope="module")
def two_logs(thesis_csv) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Two different logs (parts of the thesis' log), told apart by their sizes."""
    log = read_csv(thesis_csv)
    first = log.iloc[:600].reset_index(drop=True)
    second = log.iloc[600:1500].reset_index(drop=True)
    assert len(first) != len(second)
    return first, second


def _race(settings, logs, name: str) -> list[object]:
    """Build each log under ``name`` in its own thread and driver, all started together."""
    barrier = threading.Barrier(len(logs))
    outcomes: list[object] = [None] * len(logs)

    def ingest(index: int) -> None:
        with connect(settings) as driver:
            barrier.wait()
            try:
                outcomes[index] = build_ekg(driver, logs[index], name, progress=False)
            except InputError as refused:
                outcomes[index] = refused

    threads = [threading.Thread(target=ingest, args=(i,)) for i in range(len(logs))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    return outcomes


def test_two_ingests_of_one_name_started_together(
    neo4j_server, neo4j_driver, two_logs, graph_counts
):
    before = graph_counts()
    for attempt in range(20):
        name = f"test_race_{attempt}_{uuid.uuid4().hex[:8]}"
        outcomes = _race(neo4j_server, two_logs, name)
        won = [i for i, outcome in enumerate(outcomes) if not isinstance(outcome, Exception)]
        assert len(won) == 1, outcomes
        refused = outcomes[1 - won[0]]
        assert isinstance(refused, InputError)
        assert f"'{name}'" in str(refused) and str(refused).count(".") <= 3
        winner = two_logs[won[0]]
        summary = log_summary(neo4j_driver, name)
        assert summary["status"] == "complete"
        assert summary["counts"]["events"] == len(winner)
        assert summary["counts"]["entities:robot"] == winner["robot"].nunique()
        assert [log["name"] for log in list_logs(neo4j_driver)].count(name) == 1
        delete_log(neo4j_driver, name)
        # Nothing of the loser stayed behind, hidden from `logs list`, and no lock either.
        assert graph_counts() == before, f"attempt {attempt}"


def test_a_live_writer_is_named_and_its_log_not_touched(neo4j_driver, two_logs, log_name):
    build_ekg(neo4j_driver, two_logs[0], log_name, progress=False)
    stored = log_summary(neo4j_driver, log_name)["counts"]
    with log_write_lock(neo4j_driver, log_name):
        with pytest.raises(LogBusy, match=rf"'{log_name}' is being written .*pid {os.getpid()}"):
            build_ekg(neo4j_driver, two_logs[1], log_name, replace=True, progress=False)
        with pytest.raises(LogBusy, match="deleting it now is refused"):
            delete_log_locked(neo4j_driver, log_name)
    assert log_summary(neo4j_driver, log_name)["counts"] == stored


def test_an_undo_removes_only_its_own_run(neo4j_driver, two_logs, log_name, graph_counts):
    build_ekg(neo4j_driver, two_logs[0], log_name, progress=False)
    before = graph_counts()
    assert log_run(neo4j_driver, log_name) is not None
    _undo(neo4j_driver, log_name, uuid.uuid4().hex)  # some other run's undo
    assert graph_counts() == before


def test_a_lock_left_by_a_dead_writer_is_taken_over(neo4j_driver, two_logs, log_name):
    dead = subprocess.run(
        [sys.executable, "-c", "import os; print(os.getpid())"],
        text=True,
        capture_output=True,
        check=True,
    )
    neo4j_driver.execute_query(
        "CREATE (:LogLock {name: $name, run: 'gone', host: $host, pid: $pid, pidStart: '1', "
        "started: datetime()})",
        name=log_name,
        host=socket.gethostname(),
        pid=int(dead.stdout),
        database_=database(),
    )
    summary = build_ekg(neo4j_driver, two_logs[0], log_name, progress=False)
    assert summary.events == len(two_logs[0])
    records, _, _ = neo4j_driver.execute_query(
        "MATCH (k:LogLock {name: $name}) RETURN count(k) AS locks",
        name=log_name,
        database_=database(),
    )
    assert records[0]["locks"] == 0
