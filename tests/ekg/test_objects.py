"""Object-centric logs in the graph: an OCED-style CSV with object tables and an OCEL 2.0 file
written by pm4py, ingested by `robotale ingest`; nodes, edges and attributes against pandas
and pm4py."""

from __future__ import annotations

import pandas as pd
import pm4py
import pytest
from object_logs import logistics_csv, order_log, plain, pm4py_view

from robotale.cli import main

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
