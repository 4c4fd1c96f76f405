"""The bulk build (Neo4j's offline importer into robotale's own local server) against the online
build of the same log: the two graphs are read back with Cypher and compared property by
property, with their Neo4j types; then a second log is ingested online into the bulk-built
database, a log is deleted, and a broken import is shown to leave the database empty and
usable."""

from __future__ import annotations

import datetime
import re
import uuid
from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from neo4j import Driver

from robotale.ekg import import_files
from robotale.ekg.build import build_ekg
from robotale.ekg.bulk import BULK, ONLINE, build_log
from robotale.ekg.columnar import EVENTS, build_folder, log_build
from robotale.ekg.connection import connect
from robotale.ekg.load import timezone_name
from robotale.ekg.logs import delete_log_locked, list_logs, log_summary
from robotale.errors import InputError, ServerError
from robotale.neo4j_server.server import LocalServer, ServerOptions, free_ports

AGGREGATE = ["activity", "activity,robot"]
SCHEMA = Path(__file__).parents[2] / "cypher" / "ekg_schema.cypher"
#: events of the logs written after the two builds are compared
SMALL = 200
# what differs between any two builds of one log: when and by which run it was made
VARYING = {"created", "finished", "run"}

NODES = """
MATCH (n) WHERE n.log = $log OR (n:Log AND n.name = $log)
RETURN labels(n) AS labels,
       [k IN keys(n) | [k, valueType(n[k]),
        CASE WHEN valueType(n[k]) STARTS WITH 'ZONED' THEN toString(n[k]) ELSE n[k] END]]
       AS properties
"""
RELATIONSHIPS = """
MATCH (a)-[r]->(b) WHERE a.log = $log
RETURN type(r) AS type, [labels(a)[0], a.type, a.id] AS start, [labels(b)[0], b.type, b.id] AS end,
       [k IN keys(r) | [k, valueType(r[k]), r[k]]] AS properties
"""


def typed_log(log: pd.DataFrame) -> pd.DataFrame:
    """The thesis' log with an integer, a boolean and a text column (quotes, commas, the
    importer's array separator, gaps) and its times in a named zone with daylight saving."""
    size = len(log)
    note = np.where(np.arange(size) % 5 == 0, 'said "hi", then; left', None)
    typed = log.assign(level=np.arange(size) % 7, ok=np.arange(size) % 3 == 0, note=note)
    typed["time:timestamp"] = typed["time:timestamp"].dt.tz_convert("Europe/Berlin")
    return typed


def graph(driver: Driver, log: str) -> tuple[Counter, Counter]:
    """The log's nodes and relationships as comparable rows (values with their types)."""

    def row(properties: list) -> tuple:
        return tuple(
            sorted((k, kind, repr(value)) for k, kind, value in properties if k not in VARYING)
        )

    nodes, _, _ = driver.execute_query(NODES, log=log)
    edges, _, _ = driver.execute_query(RELATIONSHIPS, log=log)
    return (
        Counter((tuple(r["labels"]), row(r["properties"])) for r in nodes),
        Counter(
            (r["type"], tuple(r["start"]), tuple(r["end"]), row(r["properties"])) for r in edges
        ),
    )


def schema(driver: Driver) -> set[tuple]:
    rows, _, _ = driver.execute_query(
        "SHOW INDEXES YIELD name, type, entityType, labelsOrTypes, properties, state "
        "WHERE type <> 'LOOKUP' RETURN *"
    )
    return {
        (r["name"], r["type"], tuple(r["labelsOrTypes"]), tuple(r["properties"]), r["state"])
        for r in rows
    }


def answers(driver: Driver, log: str) -> tuple:
    """What `logs list` and `logs show` read of the log."""
    listed = [
        {k: v for k, v in entry.items() if k != "created"}
        for entry in list_logs(driver)
        if entry["name"] == log
    ]
    return listed, log_summary(driver, log)["counts"]


@pytest.fixture(scope="module")
def managed(tmp_path_factory, neo4j_server) -> Iterator[LocalServer]:
    """robotale's own local server in a home of its own, as `robotale neo4j start` runs it,
    with the environment pointing at it (no NEO4J_URI) while this module runs."""
    from robotale.neo4j_server import jars

    root = tmp_path_factory.mktemp("bulk-home")
    with pytest.MonkeyPatch.context() as env:
        for name in ("NEO4J_URI", "NEO4J_USER", "NEO4J_PASSWORD", "NEO4J_DATABASE"):
            env.delenv(name, raising=False)
        env.setenv("ROBOTALE_HOME", str(root))
        env.setenv("ROBOTALE_CACHE", str(jars.server_dir().parent))
        server = LocalServer(root)
        bolt, http = free_ports(2)
        server.start(ServerOptions(bolt, http, heap="512m", pagecache="64m"), timeout=600)
        try:
            yield server
        finally:
            server.stop()


def test_bulk_is_refused_where_the_server_is_not_robotales(neo4j_driver, thesis_log, log_name):
    # the session's server is named by NEO4J_URI: robotale cannot stop it
    with pytest.raises(InputError, match="NEO4J_URI names a server robotale does not manage"):
        build_log(neo4j_driver, thesis_log, log_name, build=BULK, aggregate=AGGREGATE)
    with pytest.raises(InputError, match="--build 'fast' is not one of auto, online, bulk"):
        build_log(neo4j_driver, thesis_log, log_name, build="fast")


@pytest.mark.slow
@pytest.mark.timeout(2400)  # two imports, each stopping and starting a server
def test_the_bulk_build_equals_the_online_build(managed, neo4j_driver, thesis_log, monkeypatch):
    log = typed_log(thesis_log)
    # what follows the comparison needs no size (bulk is never chosen by size below BULK_FROM
    # events): a part of the typed log, written faster
    small = log.head(SMALL)
    name = f"bulk-{uuid.uuid4().hex[:6]}"
    build_ekg(neo4j_driver, log, name, aggregate=AGGREGATE, progress=False)
    agent = f"robotale-test/{uuid.uuid4().hex}"
    with connect(user_agent=agent) as driver:
        summary = build_log(driver, log, name, build=BULK, user_agent=agent, aggregate=AGGREGATE)
    assert summary.events == len(log)
    before = managed.running()
    with connect() as bulk:
        online_nodes, online_edges = graph(neo4j_driver, name)
        bulk_nodes, bulk_edges = graph(bulk, name)
        labels = Counter(labels for labels, _ in online_nodes.elements())
        assert labels[("Event",)] == len(log) and labels[("Log",)] == 1
        assert bulk_nodes == online_nodes
        assert bulk_edges == online_edges
        assert answers(bulk, name) == answers(neo4j_driver, name)
        # the constraints and indexes the online build creates, online
        declared = set(re.findall(r"CREATE \w+ (\w+) IF NOT EXISTS", SCHEMA.read_text()))
        built = schema(bulk)
        assert {row[0] for row in built} == declared
        assert {row[-1] for row in built} == {"ONLINE"}
        assert built == {row for row in schema(neo4j_driver) if row[0] in declared}
        assert bulk.execute_query("MATCH (k:LogLock) RETURN count(k) AS n").records[0]["n"] == 0
        # the columnar copy, kept while the indexes filled, belongs to the imported build
        copy = pd.read_parquet(build_folder(log_build(bulk, name)) / EVENTS)
        pd.testing.assert_frame_equal(copy, log.reset_index(drop=True))

        # a second log goes online into the database that now holds a graph: no restart
        second = f"{name}-second"
        build_log(bulk, small, second, aggregate=["activity"], progress=False)
        assert managed.running() == before
        assert answers(bulk, second)[1]["events"] == len(small)
        delete_log_locked(bulk, name)
        assert graph(bulk, name) == (Counter(), Counter())
        assert answers(bulk, second)[1]["events"] == len(small)
        delete_log_locked(bulk, second)
        empty = bulk.execute_query("MATCH (n) RETURN count(n) AS n").records[0]["n"]
        assert empty == 0
    delete_log_locked(neo4j_driver, name)

    # a broken import (an edge to a node that is not there) leaves the database empty, usable
    write = import_files.write_import_files

    def broken(folder, *args):
        files = write(folder, *args)
        with Path(files.relationships[0][1]).open("a") as edges:
            edges.write("0,999999999\n")
        return files

    monkeypatch.setattr("robotale.ekg.bulk.write_import_files", broken)
    with connect(user_agent=agent) as driver:
        with pytest.raises(ServerError, match="failed: neo4j-admin could not import") as failed:
            build_log(driver, small, name, build=BULK, user_agent=agent, aggregate=AGGREGATE)
        assert "the database is as it was before" in str(failed.value)
    with connect() as after:
        assert after.execute_query("MATCH (n) RETURN count(n) AS n").records[0]["n"] == 0
        # --build online into the empty database of robotale's server: written online, no restart
        running = managed.running()
        build_log(after, small, name, build=ONLINE, aggregate=["activity"], progress=False)
        assert managed.running() == running
        assert answers(after, name)[1]["events"] == len(small)


@pytest.mark.parametrize("zone", ["Europe/Berlin", "UTC", None])
def test_times_are_written_as_the_online_build_stores_them(neo4j_driver, zone):
    # across both daylight-saving changes of 2024, with nanoseconds; None: a fixed offset
    moments = ["2024-03-31T00:59:59.123456789Z", "2024-03-31T01:00:00Z", "2024-10-27T00:30:00Z"]
    moments += ["2024-10-27T01:30:00.5Z", "2024-12-31T23:00:00Z"]
    utc = pd.Series(pd.to_datetime(moments, utc=True, format="ISO8601"))
    times = utc.dt.tz_convert(zone or datetime.timezone(datetime.timedelta(hours=-3, minutes=-30)))
    texts = import_files._times(times, "timestamp").fields.tolist()
    nanos = utc.dt.as_unit("ns").astype("int64")
    rows, _, _ = neo4j_driver.execute_query(
        "UNWIND range(0, size($texts) - 1) AS i "
        "WITH datetime($texts[i]) AS bulk, datetime({epochSeconds: $seconds[i], "
        "nanosecond: $nanos[i], timezone: $zone}) AS online "
        "RETURN toString(bulk) AS bulk, toString(online) AS online",
        texts=texts,
        seconds=(nanos // 10**9).tolist(),
        nanos=(nanos % 10**9).tolist(),
        zone=timezone_name(times),
    )
    assert [r["bulk"] for r in rows] == [r["online"] for r in rows]
    assert len(rows) == 5
