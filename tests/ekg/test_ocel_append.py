"""`robotale ingest --append` of OCEL 2.0 files: a log pm4py splits by time into two files,
ingested then appended, gives the graph one ingest of the whole log gives (events, entities
and their attributes, CORR with qualifiers, DF, BEGINS, DF_C, object relations and attribute
changes, all read back by Cypher); a refused append leaves the stored log as it was."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pm4py
import pytest
from object_logs import logistics_csv, order_log, plain
from pandas.testing import assert_frame_equal

from robotale.cli import main
from robotale.ekg.columnar import stored_table
from robotale.ekg.logs import delete_log, log_info, log_summary

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::FutureWarning")

WRITERS = {
    "jsonocel": pm4py.write_ocel2_json,
    "xmlocel": pm4py.write_ocel2_xml,
    "sqlite": pm4py.write_ocel2_sqlite,
}

QUERIES = {
    "events": "MATCH (e:Event {log: $log}) RETURN e.id AS id, e.activity AS activity,"
    " e.timestamp AS time, e.order AS order, e.price AS price, e.clerk AS clerk,"
    " e.courier AS courier",
    "entities": "MATCH (n:Entity {log: $log}) RETURN n.type AS type, n.id AS id,"
    " properties(n) AS node",
    "corr": "MATCH (e:Event {log: $log})-[c:CORR]->(n:Entity) RETURN e.id AS e, n.type AS t,"
    " n.id AS o, c.qualifiers AS qs",
    "df": "MATCH (a:Event {log: $log})-[r:DF]->(b:Event) RETURN a.id AS a, b.id AS b,"
    " r.entityType AS t, r.entityId AS o",
    "rel": "MATCH (a:Entity {log: $log})-[r:REL]->(b:Entity) RETURN a.id AS a, b.id AS b,"
    " r.qualifier AS q",
    "changes": "MATCH (n:Entity {log: $log})-[:CHANGED]->(c:AttributeChange) RETURN n.id AS o,"
    " c.field AS f, c.value AS v, c.time AS time",
    "begins": "MATCH (n:Entity {log: $log})-[b:BEGINS]->(c:Class) RETURN n.type AS t, n.id AS o,"
    " c.type AS k, c.id AS c, b.cases AS cases",
    "df_c": "MATCH (a:Class {log: $log})-[r:DF_C]->(b:Class) RETURN a.type AS k, a.id AS a,"
    " b.id AS b, r.entityType AS t, r.count AS n, round(r.meanSeconds, 6) AS mean,"
    " round(r.medianSeconds, 6) AS median",
}


def graph(driver, log: str) -> dict[str, object]:
    """Every part of the log's graph as a multiset of plain rows (repeats counted)."""
    found: dict[str, object] = {"counts": log_summary(driver, log)["counts"]}
    for part, query in QUERIES.items():
        records, _, _ = driver.execute_query(query, log=log)
        rows = [tuple((k, _plain(v)) for k, v in r.data().items()) for r in records]
        found[part] = sorted(rows, key=repr)
    return found


def _plain(value: object) -> object:
    if isinstance(value, dict):
        return tuple(sorted((k, _plain(v)) for k, v in value.items() if k != "log"))
    if isinstance(value, list):
        return tuple(sorted(map(str, value)))
    return plain(value)


def _by_id(table: pd.DataFrame) -> pd.DataFrame:
    """An event table in one order of rows and columns, with missing values as None."""
    table = table.sort_values("ocel:eid" if "ocel:eid" in table else table.columns[0])
    table = table[sorted(table.columns)].reset_index(drop=True).astype(object)
    return table.where(table.notna(), None)


def ingest(capsys, path: Path, log: str, *options: str) -> tuple[int, str]:
    code = main(["ingest", str(path), "--log", log, *options])
    return code, capsys.readouterr().err


def halves(tmp_path: Path, suffix: str) -> tuple[Path, Path, Path]:
    """The order log as one file and as two, split by time, all written by pm4py. The later
    half's deliveries name a courier, an attribute the earlier half's events lack."""
    whole = order_log()
    events = whole.events.sort_values("ocel:timestamp")["ocel:eid"].tolist()
    middle = len(events) // 2
    later = whole.events["ocel:eid"].isin(events[middle:])
    deliveries = later & (whole.events["ocel:activity"] == "deliver")
    whole.events["courier"] = None
    whole.events.loc[deliveries, "courier"] = ["dhl", "ups"] * int(deliveries.sum() // 2) + (
        ["dhl"] if deliveries.sum() % 2 else []
    )
    first = pm4py.filter_ocel_events(whole, events[:middle])
    first.events = first.events.drop(columns=["courier"])
    paths = []
    for name, ocel in (
        ("whole", whole),
        ("first", first),
        ("next", pm4py.filter_ocel_events(whole, events[middle:])),
    ):
        path = tmp_path / f"{name}.{suffix}"
        WRITERS[suffix](ocel, str(path))
        paths.append(path)
    return paths[0], paths[1], paths[2]


@pytest.fixture
def other_name(neo4j_driver, log_name):
    name = f"{log_name}_whole"
    yield name
    delete_log(neo4j_driver, name)


@pytest.mark.parametrize("suffix", list(WRITERS))
def test_appending_the_later_half_gives_the_graph_of_the_whole_log(
    tmp_path, capsys, neo4j_driver, log_name, other_name, suffix
):
    whole, first, following = halves(tmp_path, suffix)
    assert ingest(capsys, whole, other_name) == (0, "")
    assert ingest(capsys, first, log_name) == (0, "")
    before = graph(neo4j_driver, log_name)
    assert ingest(capsys, following, log_name, "--append") == (0, "")
    appended, expected = graph(neo4j_driver, log_name), graph(neo4j_driver, other_name)
    for part in expected:
        assert appended[part] == expected[part], part
    # Not vacuous: objects of both halves had their DF chains joined across the split, and
    # the halves share objects and relations a naive append would write twice.
    first_ids = {dict(row)["id"] for row in before["events"]}
    crossing = [
        row
        for row in map(dict, expected["df"])
        if row["a"] in first_ids and row["b"] not in first_ids
    ]
    assert crossing, "some object's events lie on both sides of the split"
    assert len(expected["events"]) == 2 * len(before["events"])
    # The later half brought an attribute the stored log lacked: recorded as one ingest of the
    # whole records it, and in the columnar copy, empty for the events stored before.
    assert not any(dict(row)["courier"] for row in before["events"])
    assert {dict(row)["courier"] for row in expected["events"]} == {None, "dhl", "ups"}
    assert "courier" in log_info(neo4j_driver, log_name)["properties"]
    assert_frame_equal(
        _by_id(stored_table(neo4j_driver, log_name)),
        _by_id(stored_table(neo4j_driver, other_name)),
        check_dtype=False,
    )
    shared = pm4py.read_ocel2(str(first)).objects.merge(
        pm4py.read_ocel2(str(following)).objects, on="ocel:oid"
    )
    assert len(shared) > 0


def test_appending_the_earlier_half_to_the_later_one(
    tmp_path, capsys, neo4j_driver, log_name, other_name
):
    # New events before the stored ones: each object's chain is built again from its start.
    whole, first, following = halves(tmp_path, "jsonocel")
    assert ingest(capsys, whole, other_name) == (0, "")
    assert ingest(capsys, following, log_name) == (0, "")
    assert ingest(capsys, first, log_name, "--append") == (0, "")
    appended, expected = graph(neo4j_driver, log_name), graph(neo4j_driver, other_name)
    for part in expected:
        if part != "events":  # an event's order is its position in the files as ingested
            assert appended[part] == expected[part], part
    without_order = [tuple(c for c in row if c[0] != "order") for row in expected["events"]]
    assert sorted(
        (tuple(c for c in row if c[0] != "order") for row in appended["events"]), key=repr
    ) == sorted(without_order, key=repr)


def test_appending_an_oced_csv_with_object_tables(
    tmp_path, capsys, neo4j_driver, log_name, other_name
):
    # The OCED-style logistics CSV split by time; each part ingested with the object tables
    # of the whole log, the second appended: the graph of one ingest of the whole file.
    whole, objects = logistics_csv(tmp_path)
    events = pd.read_csv(whole)
    middle = len(events) // 2
    first, following = tmp_path / "first.csv", tmp_path / "next.csv"
    events.iloc[:middle].to_csv(first, index=False)
    events.iloc[middle:].to_csv(following, index=False)
    tables = ("--objects", str(objects))
    assert ingest(capsys, whole, other_name, *tables) == (0, "")
    assert ingest(capsys, first, log_name, *tables) == (0, "")
    before = graph(neo4j_driver, log_name)
    assert ingest(capsys, following, log_name, *tables, "--append") == (0, "")
    appended, expected = graph(neo4j_driver, log_name), graph(neo4j_driver, other_name)
    for part in expected:
        assert appended[part] == expected[part], part
    # Not vacuous: the forklifts' and trucks' chains cross the split, and the entities
    # carry the tables' attributes.
    first_ids = {dict(row)["id"] for row in before["events"]}
    assert any(
        row["a"] in first_ids and row["b"] not in first_ids for row in map(dict, expected["df"])
    )
    assert any(dict(dict(row)["node"]).get("axles") for row in expected["entities"])


def test_refused_appends_leave_the_log_as_it_was(tmp_path, capsys, neo4j_driver, log_name):
    _, first, following = halves(tmp_path, "jsonocel")
    assert ingest(capsys, first, log_name) == (0, "")
    stored = graph(neo4j_driver, log_name)
    # An event id the log already has: the first half once more.
    code, err = ingest(capsys, first, log_name, "--append")
    assert code != 0 and "The event id " in err and f"is already in the log {log_name!r}" in err
    assert err.count("\n") == 1
    assert graph(neo4j_driver, log_name) == stored
    # An object type the stored log lacks: the later half with its packages renamed.
    renamed = pm4py.read_ocel2(str(following))
    for table in (renamed.objects, renamed.relations):
        table["ocel:type"] = table["ocel:type"].replace("package", "parcel")
    other = tmp_path / "parcels.jsonocel"
    pm4py.write_ocel2_json(renamed, str(other))
    code, err = ingest(capsys, other, log_name, "--append")
    assert code != 0 and "The object type 'parcel' is not an entity type" in err
    assert graph(neo4j_driver, log_name) == stored
    # An object the log holds as an order, now said to be an item.
    retyped = pm4py.read_ocel2(str(following))
    moved = retyped.objects["ocel:type"] == "order"
    oid = retyped.objects.loc[moved, "ocel:oid"].iloc[0]
    for table in (retyped.objects, retyped.relations):
        table.loc[table["ocel:oid"] == oid, "ocel:type"] = "item"
    stored_ids = {dict(row)["id"] for row in stored["entities"]}
    assert oid in stored_ids
    other = tmp_path / "retyped.jsonocel"
    pm4py.write_ocel2_json(retyped, str(other))
    code, err = ingest(capsys, other, log_name, "--append")
    assert code != 0 and f"The object {oid!r} is of type 'item'" in err
    assert graph(neo4j_driver, log_name) == stored
