"""Object-centric logs in the graph: an OCED-style CSV with object tables and an OCEL 2.0 file
written by pm4py, ingested by `robotale ingest`; nodes, edges and attributes against pandas
and pm4py."""

from __future__ import annotations

import json

import pandas as pd
import pm4py
import pytest
from object_logs import logistics_csv, order_log, plain, pm4py_view

from robotale.cli import main
from robotale.ekg.logs import delete_log

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::FutureWarning")


def _rows(driver, query: str, **parameters) -> list[dict]:
    records, _, _ = driver.execute_query(query, parameters)
    return [record.data() for record in records]


def _entities(driver, log: str) -> dict[tuple[str, str], dict]:
    rows = _rows(
        driver, "MATCH (n:Entity {log: $log}) RETURN n.type AS type, n.id AS id, n AS node", log=log
    )
    own = {"log", "type", "id"}
    return {
        (r["type"], r["id"]): {k: plain(v) for k, v in r["node"].items() if k not in own}
        for r in rows
    }


def test_oced_csv_with_object_tables(tmp_path, capsys, neo4j_driver, log_name):
    events_file, folder = logistics_csv(tmp_path)
    code = main(["ingest", str(events_file), "--objects", str(folder), "--log", log_name])
    out, err = capsys.readouterr()
    assert code == 0, err
    events = pd.read_csv(events_file)
    types = ["Forklift", "Truck", "Vehicle", "Container"]
    # pandas: each event's objects, one row per (event, object)
    links = (
        events.melt(id_vars=["event_id"], value_vars=types, var_name="type", value_name="id")
        .dropna()
        .assign(id=lambda t: t["id"].str.split(","))
        .explode("id")
    )
    tables = {kind: pd.read_csv(folder / f"{kind}.csv") for kind in types}
    expected = {}
    for kind, table in tables.items():
        for row in table.to_dict("records"):
            oid = row.pop("id")
            expected[(kind, oid)] = {k: plain(v) for k, v in row.items()}
    for kind, oid in links[["type", "id"]].drop_duplicates().itertuples(index=False):
        expected.setdefault((kind, oid), {})
    assert _entities(neo4j_driver, log_name) == expected
    assert len(expected) == 3 + 5 + 3 + 40

    corr = _rows(
        neo4j_driver,
        "MATCH (e:Event {log: $log})-[:CORR]->(n:Entity) RETURN e.id AS event, n.type AS type,"
        " n.id AS id",
        log=log_name,
    )
    assert sorted(map(tuple, (r.values() for r in corr))) == sorted(
        links[["event_id", "type", "id"]].itertuples(index=False, name=None)
    )
    # one case: every object's events in one chain, so DF edges = links - objects with events
    df = _rows(
        neo4j_driver,
        "MATCH (:Event {log: $log})-[r:DF]->() RETURN r.entityType AS type, count(*) AS n",
        log=log_name,
    )
    per_type = links.groupby("type").size() - links.groupby("type")["id"].nunique()
    assert {r["type"]: r["n"] for r in df} == per_type[per_type > 0].to_dict()
    assert f"{len(events):,} events" in out


def test_ocel_file_with_relations_and_qualifiers(tmp_path, capsys, neo4j_driver, log_name):
    ocel = order_log()
    path = tmp_path / "orders.jsonocel"
    pm4py.write_ocel2_json(ocel, str(path))
    expected = pm4py_view(pm4py.read_ocel2_json(str(path)))
    code = main(["ingest", str(path), "--log", log_name])
    _, err = capsys.readouterr()
    assert code == 0, err

    entities = _entities(neo4j_driver, log_name)
    # "order" is a property of every Event (its position): the type's entities are "object:order"
    column = {"order": "object:order"}
    assert entities == {
        (column.get(kind, kind), oid): attributes
        for oid, (kind, attributes) in expected["objects"].items()
    }
    rel = _rows(
        neo4j_driver,
        "MATCH (a:Entity {log: $log})-[r:REL]->(b:Entity) RETURN a.id AS a, b.id AS b,"
        " r.qualifier AS q",
        log=log_name,
    )
    assert {(r["a"], r["b"], r["q"]) for r in rel} == expected["o2o"]
    corr = _rows(
        neo4j_driver,
        "MATCH (e:Event {log: $log})-[c:CORR]->(n:Entity) RETURN e.id AS e, n.id AS o,"
        " c.qualifiers AS qs",
        log=log_name,
    )
    assert {(r["e"], r["o"], q) for r in corr for q in r["qs"]} == expected["e2o"]
    events = _rows(
        neo4j_driver,
        "MATCH (e:Event {log: $log}) RETURN e.id AS id, e.activity AS activity, e.price AS price",
        log=log_name,
    )
    assert {r["id"]: r["activity"] for r in events} == {
        eid: activity for eid, (activity, _, _) in expected["events"].items()
    }
    prices = {eid: a.get("price") for eid, (_, _, a) in expected["events"].items()}
    assert {r["id"]: r["price"] for r in events} == prices


# Two objects; o1's status changes twice after its first value, i1's weight once, and one
# value at the beginning of time is no change. By hand: three AttributeChange nodes.
CHANGES = {
    "objectTypes": [
        {"name": "order", "attributes": [{"name": "status", "type": "string"}]},
        {"name": "item", "attributes": [{"name": "weight", "type": "float"}]},
    ],
    "eventTypes": [{"name": "pay", "attributes": []}, {"name": "ship", "attributes": []}],
    "objects": [
        {
            "id": "o1",
            "type": "order",
            "attributes": [
                {"name": "status", "time": "1970-01-01T00:00:00Z", "value": "new"},
                {"name": "status", "time": "2024-05-01T10:00:00Z", "value": "paid"},
                {"name": "status", "time": "2024-05-02T09:30:00Z", "value": "shipped"},
            ],
        },
        {
            "id": "i1",
            "type": "item",
            "attributes": [
                {"name": "weight", "time": "1970-01-01T00:00:00Z", "value": 1.5},
                {"name": "weight", "time": "2024-05-01T12:00:00Z", "value": 2.25},
            ],
        },
    ],
    "events": [
        {"id": "e1", "type": "pay", "time": "2024-05-01T10:00:00Z", "attributes": [],
         "relationships": [{"objectId": "o1", "qualifier": "paid"}]},
        {"id": "e2", "type": "ship", "time": "2024-05-02T09:30:00Z", "attributes": [],
         "relationships": [{"objectId": "o1", "qualifier": "shipped"},
                           {"objectId": "i1", "qualifier": "content"}]},
    ],
}  # fmt: skip


def test_attribute_changes_are_nodes_of_their_entities(tmp_path, capsys, neo4j_driver, log_name):
    path = tmp_path / "changes.jsonocel"
    path.write_text(json.dumps(CHANGES))
    code = main(["ingest", str(path), "--log", log_name])
    _, err = capsys.readouterr()
    assert code == 0, err
    rows = _rows(
        neo4j_driver,
        "MATCH (n:Entity {log: $log})-[:CHANGED]->(c:AttributeChange {log: $log}) "
        "RETURN n.id AS id, n.type AS type, c.field AS field, c.value AS value, "
        "toString(c.time) AS time",
        log=log_name,
    )
    found = sorted((r["id"], r["field"], r["value"], r["time"]) for r in rows)
    assert found == [
        ("i1", "weight", 2.25, "2024-05-01T12:00:00Z"),
        ("o1", "status", "paid", "2024-05-01T10:00:00Z"),
        ("o1", "status", "shipped", "2024-05-02T09:30:00Z"),
    ]
    # the Entity keeps the value from the beginning
    assert _entities(neo4j_driver, log_name) == {
        ("object:order", "o1"): {"status": "new"},
        ("item", "i1"): {"weight": 1.5},
    }
    delete_log(neo4j_driver, log_name)
    left = _rows(
        neo4j_driver,
        "MATCH (c:AttributeChange {log: $log}) RETURN count(c) AS n",
        log=log_name,
    )
    assert left == [{"n": 0}]
