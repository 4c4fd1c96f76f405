"""CSV, XES and OCEL 2.0 written from a prepared log, read back by pm4py."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pm4py
import pytest
from bagbuilder import agri_like

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.prepare import prepare
from robotale.eventlog.writers import write_csv, write_ocel, write_xes

CASE, TIME, ACTIVITY = schema.CASE, schema.TIMESTAMP, schema.ACTIVITY
pytestmark = pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")


@pytest.fixture
def log(tmp_path, bag_builder) -> pd.DataFrame:
    """Two runs prepared from bags, plus columns of every XES type and XML's special characters."""
    agri_like(bag_builder).write(tmp_path / "runs" / "run_0001")
    agri_like(bag_builder, x0=50).write(tmp_path / "runs" / "run_0002")
    prepared = prepare(tmp_path / "runs")
    prepared["weeds"] = np.arange(len(prepared)) % 3
    prepared["seen"] = np.arange(len(prepared)) % 2 == 0
    messages = prepared[schema.MSG_ID].notna()
    prepared.loc[messages, schema.MSG_PAYLOAD] = '{"note": "<&> \\"é\\""}'
    return prepared


def same_values(left: pd.Series, right: pd.Series) -> bool:
    """Equal value by value, every kind of missing value equal to every other."""
    left, right = left.reset_index(drop=True), right.reset_index(drop=True)
    both_missing = left.isna() & right.isna()
    if pd.api.types.is_numeric_dtype(left) and pd.api.types.is_numeric_dtype(right):
        close = np.isclose(left.astype(float), right.astype(float), rtol=0, atol=0)
        return bool((close | both_missing).all())
    return bool(((left.astype(object) == right.astype(object)) | both_missing).all())


def read_csv(path) -> pd.DataFrame:
    """The CSV with canonical names and parsed timestamps.

    Not through ``pm4py.format_dataframe``: it parses every column that looks like a date, and
    takes message ids such as ``m1`` for one.
    """
    table = schema.from_csv_names(pd.read_csv(path))
    table[TIME] = pd.to_datetime(table[TIME], utc=True, format="ISO8601")
    return table.set_index(schema.EVENT_ID, drop=False)


def test_xes_read_back_by_pm4py_equals_the_csv_and_the_log(tmp_path, log):
    write_csv(log, tmp_path / "log.csv")
    write_xes(log, tmp_path / "log.xes")
    from_xes = pm4py.read_xes(str(tmp_path / "log.xes"))
    from_csv = read_csv(tmp_path / "log.csv").loc[from_xes[schema.EVENT_ID]]
    assert len(from_xes) == len(from_csv) == len(log)
    for column in log.columns:
        assert same_values(from_xes[column], from_csv[column]), column
        if column != "seen":  # pandas reads a CSV's booleans back as booleans, pm4py as objects
            assert same_values(from_xes[column], log[column]), column
    assert from_xes[TIME].tolist() == log[TIME].tolist()
    assert from_xes["seen"].tolist() == log["seen"].tolist()


def test_xes_declares_the_standard_and_types_its_attributes(tmp_path, log):
    from lxml import etree

    write_xes(log, tmp_path / "log.xes")
    root = etree.parse(str(tmp_path / "log.xes")).getroot()
    xes = "{http://www.xes-standard.org/}"
    assert root.tag == f"{xes}log" and root.get("xes.version") == "1849-2016"
    prefixes = {e.get("prefix") for e in root.iter(f"{xes}extension")}
    assert {"concept", "time", "lifecycle"} <= prefixes
    traces = root.findall(f"{xes}trace")
    assert [t.find(f"{xes}string").get("value") for t in traces] == ["run_0001", "run_0002"]
    first = traces[0].find(f"{xes}event")
    typed = {child.get("key"): etree.QName(child).localname for child in first}
    assert typed["time:timestamp"] == "date"
    assert typed["lifecycle:transition"] == typed["lifecycle:state"] == "string"
    assert typed["x"] == typed["y"] == typed["z"] == typed["battery"] == "float"
    assert (typed["weeds"], typed["seen"]) == ("int", "boolean")
    assert "msg_id" not in typed  # XES has no null: empty values are left out


def test_csv_has_the_short_column_names_and_utc_times(tmp_path, log):
    write_csv(log, tmp_path / "log.csv")
    lines = (tmp_path / "log.csv").read_text().splitlines()
    assert lines[0].split(",")[:7] == [
        "case", "time", "activity", "lifecycle", "state", "robot", "robot_type",
    ]  # fmt: skip
    assert lines[1].startswith("run_0001,2023-05-16T10:00:00.500000+00:00,take_off,start,none,")


def test_ocel_passes_pm4py_reader_with_robots_messages_and_runs(tmp_path, log):
    runs = {"run_0001": {"seed": 1, "outcome": {"status": "ended"}}}
    write_ocel(log, tmp_path / "log.json", runs=runs)
    ocel = pm4py.read_ocel2_json(str(tmp_path / "log.json"))
    assert len(ocel.events) == len(log)
    assert set(ocel.events["ocel:eid"]) == set(log[schema.EVENT_ID])
    objects = ocel.objects.set_index("ocel:oid")["ocel:type"].to_dict()
    assert objects == {
        "drone@run_0001": "robot",
        "tractor_1@run_0001": "robot",
        "drone@run_0002": "robot",
        "tractor_1@run_0002": "robot",
        "m1@run_0001": "message",
        "m1@run_0002": "message",
        "run_0001": "run",
        "run_0002": "run",
    }
    relations = ocel.relations
    per_event = relations.groupby("ocel:eid")["ocel:oid"].apply(set)
    for _, event in log.iterrows():
        expected = {event[CASE], f"{event[schema.ROBOT]}@{event[CASE]}"}
        if isinstance(event[schema.MSG_ID], str):
            expected.add(f"{event[schema.MSG_ID]}@{event[CASE]}")
        assert per_event[event[schema.EVENT_ID]] == expected
    sends = relations[relations["ocel:qualifier"] == "send"]
    assert set(sends["ocel:activity"]) == {"weed_position!"}
    o2o = set(map(tuple, ocel.o2o[["ocel:oid", "ocel:oid_2", "ocel:qualifier"]].to_numpy()))
    assert ("m1@run_0001", "drone@run_0001", "sent by") in o2o
    assert ("m1@run_0001", "tractor_1@run_0001", "received by") in o2o
    assert ("tractor_1@run_0002", "run_0002", "part of") in o2o
    run = ocel.objects.set_index("ocel:oid").loc["run_0001"]
    assert (run["seed"], run["outcome.status"]) == ("1", "ended")
    document = json.loads((tmp_path / "log.json").read_text())
    assert {t["name"] for t in document["objectTypes"]} == {"robot", "message", "run"}


def test_a_failed_write_leaves_no_partial_file_and_keeps_the_old_one(tmp_path, log):
    target = tmp_path / "log.xes"
    target.write_text("the previous log")
    broken = log.copy()
    broken.loc[len(broken) - 1, schema.MSG_PAYLOAD] = "bell \x07"  # not representable in XML
    with pytest.raises(InputError, match=r"msg_payload of event run_0002:15 .* cannot be written"):
        write_xes(broken, target)
    assert target.read_text() == "the previous log"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["log.xes", "runs"]


def test_a_file_cannot_be_written_where_a_folder_is_a_file(tmp_path, log):
    (tmp_path / "plain").write_text("")
    with pytest.raises(InputError, match=r"Cannot write .*plain/log.csv"):
        write_csv(log, tmp_path / "plain" / "log.csv")
