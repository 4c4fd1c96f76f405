"""OCEL 2.0 logs written by pm4py in all three encodings, read by robotale: the events,
objects, relations and attributes equal pm4py's own reading of the same file; written back
by robotale, pm4py reads the same log again; broken files are refused in one sentence."""

from __future__ import annotations

import json
import re
import sqlite3

import pandas as pd
import pm4py
import pytest
from object_logs import logistics_csv, missing, order_log, plain, pm4py_view

from robotale.ekg.tables import RESERVED
from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.objects import EVENT_OWN, SEPARATOR, Objects
from robotale.eventlog.readers import read_log, read_with_objects
from robotale.eventlog.writers import write_ocel

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::FutureWarning")

ENCODINGS = {
    "json": ("log.jsonocel", pm4py.write_ocel2_json, pm4py.read_ocel2_json),
    "xml": ("log.xmlocel", pm4py.write_ocel2_xml, pm4py.read_ocel2_xml),
    "sqlite": ("log.sqlite", pm4py.write_ocel2_sqlite, pm4py.read_ocel2_sqlite),
}


def robotale_view(log: pd.DataFrame, objects: Objects) -> dict[str, object]:
    """robotale's reading in the shape of :func:`object_logs.pm4py_view`."""
    own = {schema.EVENT_ID, schema.ACTIVITY, schema.TIMESTAMP, schema.CASE, schema.LIFECYCLE}
    attributes = [c for c in log.columns if c not in own | set(objects.entity_types)]
    events = {
        row[schema.EVENT_ID]: (
            row[schema.ACTIVITY],
            row[schema.TIMESTAMP].tz_convert("UTC"),
            {c: plain(row[c]) for c in attributes if not missing(row[c])},
        )
        for row in log.to_dict("records")
    }
    listed = {
        row["id"]: (
            row["type"],
            {c: plain(row[c]) for c in objects.attributes if not missing(row[c])},
        )
        for row in objects.objects.to_dict("records")
    }
    return {
        "events": events,
        "objects": listed,
        "e2o": set(objects.e2o.itertuples(index=False, name=None)),
        "o2o": set(objects.o2o.itertuples(index=False, name=None)),
        "changes": {
            (o, pd.Timestamp(t).tz_convert("UTC"), f, plain(v))
            for o, t, f, v in objects.changes.itertuples(index=False, name=None)
        },
    }


@pytest.fixture(scope="module")
def ocel():
    return order_log()


@pytest.mark.parametrize("encoding", sorted(ENCODINGS))
def test_reading_equals_pm4py(tmp_path, ocel, encoding):
    name, write, read = ENCODINGS[encoding]
    path = tmp_path / name
    write(ocel, str(path))
    expected = pm4py_view(read(str(path)))
    log, reading, objects = read_with_objects(path)
    found = robotale_view(log, objects)
    for part in ("events", "objects", "e2o", "o2o", "changes"):
        assert found[part] == expected[part], part
    # the sizes, so equal empty readings could not pass
    assert len(found["events"]) == len(ocel.events) > 40
    assert len(found["e2o"]) == len(ocel.relations)
    assert len(found["o2o"]) == len(ocel.o2o) > 10
    assert len(found["changes"]) == len(ocel.object_changes) > 0
    # each event's objects of a type, as the entity column lists them
    for kind in ("order", "item", "package"):
        column = objects.column(kind)
        listed = {
            (row[schema.EVENT_ID], oid)
            for row in log.to_dict("records")
            if isinstance(row[column], str)
            for oid in row[column].split(SEPARATOR)
        }
        related = ocel.relations[ocel.relations["ocel:type"] == kind]
        assert listed == set(zip(related["ocel:eid"], related["ocel:oid"], strict=True))
    assert reading.columns["item"] == "objects (entity type)"
    assert reading.cases == 1 and not reading.warnings


def test_written_back_pm4py_reads_the_same_log(tmp_path, ocel):
    source = tmp_path / "log.xmlocel"
    pm4py.write_ocel2_xml(ocel, str(source))
    log, _, objects = read_with_objects(source)
    target = tmp_path / "back.jsonocel"
    write_ocel(log, target, objects=objects)
    assert pm4py_view(pm4py.read_ocel2_json(str(target))) == pm4py_view(
        pm4py.read_ocel2_xml(str(source))
    )
    # and robotale reads its own file as it read the original
    again, _, again_objects = read_with_objects(target)
    assert robotale_view(again, again_objects) == robotale_view(log, objects)


def test_read_log_gives_the_events_with_object_columns(tmp_path, ocel):
    path = tmp_path / "log.json"
    pm4py.write_ocel2_json(ocel, str(path))
    log = read_log(path)
    assert len(log) == len(ocel.events)
    # "order" is a property every Event has (its position in the log)
    assert {"object:order", "item", "package"} <= set(log.columns)


def test_event_properties_the_graph_sets_are_no_entity_columns():
    assert set(RESERVED) == set(EVENT_OWN)


def _json_log(tmp_path, document) -> object:
    path = tmp_path / "bad.jsonocel"
    path.write_text(json.dumps(document))
    return path


GOOD_EVENT = {"id": "e1", "type": "a", "time": "2024-01-01T00:00:00Z", "relationships": []}


@pytest.mark.parametrize(
    ("document", "says"),
    [
        ({"objects": []}, 'no list of "events"'),
        (
            {"objects": [], "events": [{**GOOD_EVENT, "relationships": [{"objectId": "x9"}]}]},
            "event 'e1' relates to the object 'x9', which the log's objects do not list",
        ),
        (
            {"objects": [], "events": [{**GOOD_EVENT, "time": "soon"}]},
            "event 1 ('e1') has the time 'soon'",
        ),
        ({"objects": [], "events": [{**GOOD_EVENT, "type": ""}]}, "event 1 ('e1') has no type"),
        (
            {"objects": [{"id": "a,b", "type": "t"}], "events": [GOOD_EVENT]},
            "the object id 'a,b' holds a comma",
        ),
        (
            {
                "objects": [{"id": "o", "type": "t", "attributes": [{"name": "type", "value": 1}]}],
                "events": [GOOD_EVENT],
            },
            "the object attribute 'type' has the name of the Entity node's own 'type'",
        ),
        ({"objects": [], "events": [GOOD_EVENT, GOOD_EVENT]}, "the event id 'e1' appears more"),
    ],
)
def test_bad_json_is_refused_naming_the_element(tmp_path, document, says):
    path = _json_log(tmp_path, document)
    with pytest.raises(InputError) as refused:
        read_with_objects(path)
    assert str(refused.value).startswith(str(path))
    assert says in str(refused.value)


def test_bad_xml_value_names_its_line(tmp_path, ocel):
    path = tmp_path / "log.xmlocel"
    pm4py.write_ocel2_xml(ocel, str(path))
    text = path.read_text().splitlines()
    line = next(i for i, t in enumerate(text) if 'name="weight"' in t and "time=" in t)
    text[line] = re.sub(r">[^<]*</attribute>", ">heavy</attribute>", text[line])
    path.write_text("\n".join(text))
    with pytest.raises(
        InputError, match=rf"line {line + 1}: the float attribute 'weight' has the value 'heavy'"
    ):
        read_with_objects(path)


def test_sqlite_without_a_table_is_refused(tmp_path, ocel):
    path = tmp_path / "log.sqlite"
    pm4py.write_ocel2_sqlite(ocel, str(path))
    with sqlite3.connect(path) as connection:
        connection.execute("DROP TABLE object_object")
    connection.close()
    with pytest.raises(InputError, match="has no table 'object_object'"):
        read_with_objects(path)


def test_objects_folder_with_ocel_is_refused(tmp_path, ocel):
    path = tmp_path / "log.jsonocel"
    pm4py.write_ocel2_json(ocel, str(path))
    with pytest.raises(InputError, match="lists its objects itself"):
        read_with_objects(path, objects=tmp_path)


def test_oced_csv_reads_objects_from_the_type_tables(tmp_path):
    events_file, folder = logistics_csv(tmp_path)
    log, _, objects = read_with_objects(events_file, objects=folder)
    events = pd.read_csv(events_file)
    assert sorted(objects.types) == ["Container", "Forklift", "Truck", "Vehicle"]
    trucks = objects.objects[objects.objects["type"] == "Truck"].set_index("id")
    table = pd.read_csv(folder / "Truck.csv").set_index("id")
    assert trucks["plate"].to_dict() == table["plate"].to_dict()
    assert trucks["axles"].astype(int).to_dict() == table["axles"].to_dict()
    named = events["Container"].str.split(",").explode()
    containers = objects.e2o[objects.e2o["object"].str.startswith("cr")]
    assert len(containers) == len(named) and containers["qualifier"].isna().all()
    assert log["Container"].tolist() == events["Container"].tolist()


@pytest.mark.parametrize(
    ("damage", "says"),
    [
        (lambda folder: (folder / "Truck.csv").write_text("plate\nK-1\n"), "has no 'id' column"),
        (lambda folder: (folder / "Crane.csv").write_text("id\nc1\n"), "no column 'Crane'"),
        (lambda folder: (folder / "Vehicle.csv").write_text("id,type\nve1,tug\n"), "'type'"),
        (lambda folder: (folder / "Vehicle.csv").write_text("id\nve1\nve1\n"), "'ve1' appears"),
    ],
)
def test_bad_object_tables_are_refused_naming_the_file(tmp_path, damage, says):
    events_file, folder = logistics_csv(tmp_path)
    damage(folder)
    with pytest.raises(InputError, match=says) as refused:
        read_with_objects(events_file, objects=folder)
    assert str(folder) in str(refused.value)
