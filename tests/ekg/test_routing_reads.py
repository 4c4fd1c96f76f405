"""What only reads runs in read transactions, so that a cluster sends it to a follower.

Seen on the session's single server through ``neo4j://``: each read path is given a query that
writes in place of its own, and Neo4j itself refuses the write, as it refuses every write in a
read transaction (the same statement in a write transaction writes: the control). Without a
write swapped in, the paths answer as through ``bolt://``."""

from __future__ import annotations

import pandas as pd
import pytest
from neo4j.exceptions import ClientError

from robotale.discovery import ekg as discovery
from robotale.ekg import logs, writelock
from robotale.ekg.build import build_ekg
from robotale.ekg.connection import Settings, connect, server_version
from robotale.ekg.readonly import WriteRefused, run_read_only

PROBE = "CREATE (probe:RoutingProbe) RETURN probe"
ACCESS_MODE = "Neo.ClientError.Statement.AccessMode"


@pytest.fixture
def routed(neo4j_server):
    """A driver on the session's server through the routing scheme."""
    uri = "neo4j://" + neo4j_server.uri.split("://", 1)[1]
    driver = connect(Settings(uri, neo4j_server.user, neo4j_server.password, True))
    yield driver
    driver.close()


@pytest.fixture
def stored(neo4j_driver, log_name) -> str:
    """A small log of two robots, stored under a fresh name."""
    times = pd.date_range("2024-05-01 10:00", periods=6, freq="1min", tz="UTC")
    log = pd.DataFrame(
        {
            "case:concept:name": ["1"] * 6,
            "time:timestamp": times,
            "concept:name": ["go", "go", "lift", "lift", "go", "go"],
            "lifecycle:transition": ["start", "complete"] * 3,
            "robot": ["r1", "r1", "r2", "r2", "r1", "r1"],
        }
    )
    build_ekg(neo4j_driver, log, log_name, entities=["robot"], aggregate=[["activity"]])
    return log_name


def probes(driver) -> int:
    records, _, _ = driver.execute_query("MATCH (p:RoutingProbe) RETURN count(p) AS n")
    return records[0]["n"]


def writing(monkeypatch, *modules) -> None:
    """Every query those modules load from cypher/ becomes one that writes."""
    for module in modules:
        monkeypatch.setattr(module, "cypher", lambda name: PROBE)


def test_the_probe_writes_in_a_write_transaction(routed):
    routed.execute_query(PROBE)
    assert probes(routed) == 1
    routed.execute_query("MATCH (p:RoutingProbe) DELETE p")


@pytest.mark.parametrize(
    "read",
    [
        lambda driver, name: logs.list_logs(driver),
        lambda driver, name: logs.log_info(driver, name),
        lambda driver, name: logs.log_summary(driver, name),
        lambda driver, name: logs.log_values(driver, name),
        lambda driver, name: logs.stored_events(driver, name),
        lambda driver, name: logs.graph_counts(driver),
    ],
    ids=["list", "info", "summary", "values", "events", "graph counts"],
)
def test_the_reads_of_stored_logs_run_in_read_transactions(routed, stored, monkeypatch, read):
    writing(monkeypatch, logs)
    with pytest.raises(ClientError) as refused:
        read(routed, stored)
    assert refused.value.code == ACCESS_MODE
    assert probes(routed) == 0


def test_the_lock_list_and_the_discovery_reads_run_in_read_transactions(
    routed, stored, monkeypatch
):
    writing(monkeypatch, writelock)
    with pytest.raises(ClientError) as refused:
        logs.list_logs(routed)
    assert refused.value.code == ACCESS_MODE
    monkeypatch.undo()
    writing(monkeypatch, discovery)
    with pytest.raises(ClientError) as refused:
        discovery.discover_ekg(stored, "activity", driver=routed)
    assert refused.value.code == ACCESS_MODE
    assert probes(routed) == 0


def test_routed_reads_answer_as_direct_ones(routed, neo4j_driver, stored):
    assert logs.log_summary(routed, stored) == logs.log_summary(neo4j_driver, stored)
    assert logs.log_values(routed, stored)["events"] == 6
    names = [log["name"] for log in logs.list_logs(routed)]
    assert stored in names and names == [log["name"] for log in logs.list_logs(neo4j_driver)]
    routed_graph = discovery.discover_ekg(stored, "activity", driver=routed).to_dict()
    direct_graph = discovery.discover_ekg(stored, "activity", driver=neo4j_driver).to_dict()
    assert routed_graph == direct_graph
    classes = {
        n["label"]: n["count"] for n in routed_graph["nodes"] if n["label"] in ("go", "lift")
    }
    assert classes == {"go": 2, "lift": 1}  # the log's activity instances (start, complete)
    assert server_version(routed)["name"] == server_version(neo4j_driver)["name"]


def test_the_console_still_refuses_writes_through_a_routing_uri(routed):
    with pytest.raises(WriteRefused):
        run_read_only(routed, "MATCH (n) WITH n LIMIT 1 SET n.touched = true RETURN n")
    assert run_read_only(routed, "RETURN 1 AS one")[0].rows == [[1]]
