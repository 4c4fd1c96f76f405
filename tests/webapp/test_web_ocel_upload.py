"""OCEL 2.0 logs uploaded on the Logs page, in each of the three encodings, written by pm4py:
the graph the dashboard stores holds the objects, attributes, event-to-object relations with
their qualifiers and object-to-object relations pm4py reads from the same file."""

from __future__ import annotations

import re

import pm4py
import pytest
from object_logs import order_log, plain, pm4py_view
from test_web_logs import ingest, read_step, stored, text, upload

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::FutureWarning")

ENCODINGS = {
    "json": ("orders.jsonocel", pm4py.write_ocel2_json, pm4py.read_ocel2_json),
    "xml": ("orders.xmlocel", pm4py.write_ocel2_xml, pm4py.read_ocel2_xml),
    "sqlite": ("orders.sqlite", pm4py.write_ocel2_sqlite, pm4py.read_ocel2_sqlite),
}
#: "order" is a property of every Event (its position): that type's entities are "object:order"
COLUMN = {"order": "object:order"}


def _rows(driver, query: str, log: str) -> list[dict]:
    records, _, _ = driver.execute_query(query, log=log)
    return [record.data() for record in records]


def _graph(driver, log: str) -> dict[str, object]:
    """The stored log in the shape of pm4py_view (objects under their entity types)."""
    own = {"log", "type", "id"}
    nodes = _rows(driver, "MATCH (n:Entity {log: $log}) RETURN n.type AS t, n.id AS id, n", log)
    rel = _rows(
        driver,
        "MATCH (a:Entity {log: $log})-[r:REL]->(b) RETURN a.id AS a, b.id AS b, r.qualifier AS q",
        log,
    )
    corr = _rows(
        driver,
        "MATCH (e:Event {log: $log})-[c:CORR]->(n:Entity) RETURN e.id AS e, n.id AS o,"
        " c.qualifiers AS qs",
        log,
    )
    events = _rows(driver, "MATCH (e:Event {log: $log}) RETURN e.id AS id, e.activity AS a", log)
    return {
        "objects": {
            (r["t"], r["id"]): {k: plain(v) for k, v in r["n"].items() if k not in own}
            for r in nodes
        },
        "o2o": {(r["a"], r["b"], r["q"]) for r in rel},
        "e2o": {(r["e"], r["o"], q) for r in corr for q in r["qs"]},
        "activities": {r["id"]: r["a"] for r in events},
    }


@pytest.mark.parametrize("encoding", sorted(ENCODINGS))
def test_an_ocel_upload_is_stored_as_pm4py_reads_it(
    encoding, client, tmp_path, log_name, neo4j_driver, web_settings
):
    filename, write, read = ENCODINGS[encoding]
    path = tmp_path / filename
    write(order_log(), str(path))
    expected = pm4py_view(read(str(path)))

    token, page = read_step(client, filename, path.read_bytes())
    assert f"{len(expected['events'])} events" in page
    types = sorted({COLUMN.get(kind, kind) for kind, _ in expected["objects"].values()})
    for kind in types:  # the object types are the entities the page proposes
        assert re.search(rf'value="{re.escape(kind)}" checked\s+aria-label="', page), kind

    job, _ = ingest(client, token, {"name": log_name, "entity": types})
    assert job["error"] is None and job["stage"] == "done"
    assert stored(client)[log_name]["events"] == len(expected["events"])
    assert list(web_settings.upload_dir.iterdir()) == []

    graph = _graph(neo4j_driver, log_name)
    assert graph["objects"] == {
        (COLUMN.get(kind, kind), oid): attributes
        for oid, (kind, attributes) in expected["objects"].items()
    }
    assert graph["o2o"] == expected["o2o"]
    assert graph["e2o"] == expected["e2o"]
    assert graph["activities"] == {eid: a for eid, (a, _, _) in expected["events"].items()}


def test_a_file_named_as_ocel_that_is_none_is_refused(client, web_settings):
    response = upload(client, "orders.sqlite", b"type,id\norder,o1\n")
    assert response.status_code == 400
    assert "'orders.sqlite' is not an SQLite database, so it is no OCEL 2.0 log." in text(response)
    response = upload(client, "orders.jsonocel", b"<log/>")
    assert response.status_code == 400
    assert "is not an OCEL 2.0 JSON log" in text(response)
    assert list(web_settings.upload_dir.iterdir()) == []
