"""CSV and XES logs into the canonical DataFrame, checked against pandas, pm4py and hand counts."""

from __future__ import annotations

import datetime as dt

import pandas as pd
import pm4py
import pytest

from robotale.errors import InputError
from robotale.eventlog import schema
from robotale.eventlog.readers import read_csv, read_log, read_xes

XES = """<?xml version="1.0" encoding="UTF-8"?>
<log xes.version="1.0" xmlns="http://www.xes-standard.org/">
  <extension name="Concept" prefix="concept" uri="http://www.xes-standard.org/concept.xesext"/>
  <trace>
    <string key="concept:name" value="run-1"/>
    <int key="field" value="4"/>
    <event>
      <string key="concept:name" value="takeoff"/>
      <string key="lifecycle:transition" value="start"/>
      <string key="org:resource" value="drone"/>
      <string key="execution_id" value="x1"/>
      <date key="time:timestamp" value="2023-05-16T10:27:08.918+01:00"/>
    </event>
    <event>
      <string key="concept:name" value="takeoff"/>
      <string key="lifecycle:transition" value="complete"/>
      <string key="org:resource" value="drone"/>
      <string key="execution_id" value="x1"/>
      <float key="battery" value="97.5"/>
      <date key="time:timestamp" value="2023-05-16T10:27:09.972+01:00"/>
    </event>
  </trace>
  <trace>
    <string key="concept:name" value="run-2"/>
    <event>
      <string key="concept:name" value="weed_position!"/>
      <string key="org:resource" value="drone"/>
      <boolean key="urgent" value="true"/>
      <list key="ignored"><string key="a" value="b"/></list>
      <date key="time:timestamp" value="2023-05-16T10:30:00.000+01:00"/>
    </event>
  </trace>
</log>
"""


def write(tmp_path, name: str, content: str | bytes):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return path


# -- the thesis log ----------------------------------------------------------------------------


def test_thesis_csv_reads_as_one_case_with_resource_as_robot(thesis_csv):
    log = read_csv(thesis_csv)
    raw = pd.read_csv(thesis_csv)
    assert len(log) == len(raw) == 3648
    assert log[schema.ROBOT].tolist() == raw["resource"].tolist()
    assert set(log[schema.CASE]) == {"1"}
    assert log[schema.ACTIVITY].tolist() == raw["activity"].tolist()
    assert log[schema.EVENT_ID].tolist() == raw["event_id"].tolist()
    first = log[schema.TIMESTAMP].iloc[0]
    assert first == pd.Timestamp("2023-05-16T09:27:08.918Z")
    assert first.utcoffset() == dt.timedelta(hours=1), "the file's offset is kept"
    assert set(log[schema.LIFECYCLE]) == {"start", "complete"}
    assert log["field"].iloc[0] == "f4" and log[schema.X].dtype == float


def test_thesis_csv_with_an_explicit_case_column(thesis_csv):
    log = read_csv(thesis_csv, case="field")
    assert log.groupby(schema.CASE).size().to_dict() == {"1": 12, "f1": 988, "f2": 1668, "f4": 980}


# -- column mapping ----------------------------------------------------------------------------


def test_usual_column_names_are_recognised(tmp_path):
    path = write(
        tmp_path,
        "disco.csv",
        "Case ID,Activity,Timestamp,Resource,Lifecycle:Transition,concept:instance\n"
        "38,explore,2023-05-16 10:00:00,drone,START,a1\n"
        "38,explore,2023-05-16 10:00:05,drone,complete,a1\n",
    )
    log = read_csv(path)
    assert log[schema.CASE].tolist() == ["38", "38"], "case ids stay text"
    assert log[schema.ROBOT].tolist() == ["drone", "drone"]
    assert log[schema.LIFECYCLE].tolist() == ["start", "complete"]
    assert log[schema.EXECUTION_ID].tolist() == ["a1", "a1"]
    assert log[schema.TIMESTAMP].dt.tz is not None, "times without an offset are UTC"
    assert log[schema.TIMESTAMP].iloc[1] == pd.Timestamp("2023-05-16T10:00:05Z")
    assert log[schema.EVENT_ID].tolist() == ["0", "1"]


def test_explicit_mapping_wins_over_the_usual_names(tmp_path):
    path = write(
        tmp_path,
        "de.csv",
        "Zeit,Tätigkeit,wer,activity\n2023-05-16T10:00:00Z,start,tractor_1,ignored\n",
    )
    log = read_csv(path, mapping={"Zeit": "time", "Tätigkeit": "activity", "wer": "robot"})
    assert log[schema.ACTIVITY].tolist() == ["start"]
    assert log[schema.ROBOT].tolist() == ["tractor_1"]
    assert "activity" in log.columns, "the unmapped column keeps its own name"


def test_without_lifecycle_events_are_complete(tmp_path):
    path = write(tmp_path, "l.csv", "time,activity\n2023-05-16T10:00:00Z,a\n")
    assert read_csv(path)[schema.LIFECYCLE].tolist() == ["complete"]


def test_mixed_offsets_become_utc(tmp_path):
    path = write(
        tmp_path,
        "tz.csv",
        "time,activity\n2023-05-16T10:00:00+01:00,a\n2023-05-16T10:00:00+02:00,b\n",
    )
    times = read_csv(path)[schema.TIMESTAMP]
    assert times.tolist() == [pd.Timestamp("2023-05-16T09:00Z"), pd.Timestamp("2023-05-16T08:00Z")]


# -- XES ---------------------------------------------------------------------------------------


@pytest.mark.filterwarnings("ignore:Install the optional requirement")
def test_xes_matches_pm4py(tmp_path):
    path = write(tmp_path, "log.xes", XES)
    log = read_xes(path)
    reference = pm4py.read_xes(str(path))
    assert log[schema.CASE].tolist() == reference[schema.CASE].tolist() == ["run-1"] * 2 + ["run-2"]
    assert log[schema.ACTIVITY].tolist() == reference[schema.ACTIVITY].tolist()
    assert log[schema.ROBOT].tolist() == reference["org:resource"].tolist()
    assert log[schema.TIMESTAMP].tolist() == reference[schema.TIMESTAMP].tolist()
    assert log[schema.TIMESTAMP].iloc[0].utcoffset() == dt.timedelta(hours=1)
    assert log[schema.EXECUTION_ID].tolist()[:2] == ["x1", "x1"]
    assert log["case:field"].tolist()[:2] == [4, 4]
    assert log["battery"].iloc[1] == 97.5
    assert bool(log["urgent"].iloc[2]) is True
    assert "ignored" not in log.columns
    assert log[schema.LIFECYCLE].tolist() == ["start", "complete", "complete"]


def test_read_log_chooses_by_extension(tmp_path, thesis_csv):
    assert len(read_log(write(tmp_path, "log.xes", XES))) == 3
    assert len(read_log(thesis_csv)) == 3648


# -- bad input: one sentence naming the file and line ------------------------------------------


@pytest.mark.parametrize(
    ("name", "content", "message"),
    [
        ("empty.csv", "", r"empty\.csv is empty\."),
        ("blank.csv", "\n  \n", r"blank\.csv is empty\."),
        ("header.csv", "time,activity\n", r"header\.csv has no events, only a header\."),
        (
            "latin1.csv",
            "time,activity\n2023-05-16T10:00Z,M\xe4hen\n".encode("latin-1"),
            r"latin1\.csv is not UTF-8 text \(byte 0xe4 on line 2\)",
        ),
        (
            "noact.csv",
            "time,robot\n2023-05-16T10:00Z,drone\n",
            r"noact\.csv has no activity column \(looked for activity, concept:name"
            r".*--map COLUMN=activity",
        ),
        ("notime.csv", "activity\nexplore\n", r"notime\.csv has no time column"),
        (
            "badtime.csv",
            "time,activity\n2023-05-16T10:00Z,a\nyesterday,b\n",
            r"badtime\.csv line 3: cannot read the timestamp 'yesterday'",
        ),
        (  # the fuzz test's find: pandas reads "/1" as the year 0, which no date can hold
            "yearzero.csv",
            "activity,time\n2024-01-01T00:00:00Z,/1\n",
            r"yearzero\.csv line 2: cannot read the timestamp '/1'",
        ),
        (
            "notime2.csv",
            "time,activity\n2023-05-16T10:00Z,a\n,b\n",
            r"notime2\.csv line 3: cannot read the timestamp ''",
        ),
        (
            "noname.csv",
            "time,activity\n2023-05-16T10:00Z,a\n2023-05-16T10:00Z,\n",
            r"noname\.csv line 3: the activity is empty",
        ),
        (
            "dup.csv",
            "time,activity,event_id\n2023-05-16T10:00Z,a,e1\n2023-05-16T10:01Z,b,e1\n",
            r"dup\.csv: the event_id 'e1' appears more than once \(lines 2 and 3\)",
        ),
        (
            "inject.csv",
            'time,activity,"x`}) DETACH DELETE n //"\n2023-05-16T10:00Z,a,1\n',
            r"inject\.csv has a column named 'x`}\) DETACH DELETE n //', which cannot become"
            r" a property",
        ),
        (
            "broken.xes",
            "<log><trace><event></trace></log>",
            r"broken\.xes is not valid XES: .*line 1",
        ),
        (
            "none.xes",
            "<log xmlns='http://www.xes-standard.org/'></log>",
            r"none\.xes has no events",
        ),
        (
            "badint.xes",
            "<log><trace><event><int key='n' value='x'/></event></trace></log>",
            r"badint\.xes line 1: the int attribute 'n' has the value 'x'",
        ),
    ],
)
def test_bad_files_are_one_sentence(tmp_path, name, content, message):
    path = write(tmp_path, name, content)
    with pytest.raises(InputError, match=message):
        read_log(path)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match=r"nope\.csv does not exist\."):
        read_log(tmp_path / "nope.csv")


def test_case_column_must_exist(thesis_csv):
    with pytest.raises(InputError, match=r"has no column 'run' for --case; its columns are 'time'"):
        read_csv(thesis_csv, case="run")


def test_mapped_column_must_exist(thesis_csv):
    with pytest.raises(InputError, match=r"has no column 'Zeit' to map"):
        read_csv(thesis_csv, mapping={"Zeit": "time"})


def test_two_columns_mapped_to_one_field_are_refused(tmp_path):
    path = write(tmp_path, "two.csv", "when,at,activity\n2023-05-16T10:00Z,2023-05-16T10:00Z,a\n")
    with pytest.raises(InputError, match=r"more than one column would be 'time:timestamp'"):
        read_csv(path, mapping={"when": "time", "at": "time"})
