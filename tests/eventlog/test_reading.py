"""Event logs written in other tools' conventions, read the way their authors meant them.

Each generated log renders one known execution (``tests/conventions.py``); the answers come
from that ground truth, from pm4py, or from pandas counts on the raw file, never from the
reader itself.
"""

from __future__ import annotations

import io

import pandas as pd
import pm4py
import pytest
from conventions import (
    BATTERY_MARKERS,
    ground_truth,
    robot_id_battery,
    write_inprogress_xes,
    write_robot_id_csv,
    write_robotale_csv,
)
from pm4py.objects.log.util import interval_lifecycle

from robotale.discovery.instances import activity_instances, control_flow_events
from robotale.errors import InputError
from robotale.eventlog import reading, schema
from robotale.eventlog.readers import _csv_table, read_log, read_log_with_reading

WRITERS = {
    "robotale.csv": write_robotale_csv,
    "inprogress.xes": write_inprogress_xes,
    "robot_id.csv": write_robot_id_csv,
}
TRUTH = ground_truth()


@pytest.fixture(params=list(WRITERS))
def convention(request, tmp_path):
    """(file, its log, its reading) for each generated convention."""
    path = WRITERS[request.param](TRUTH, tmp_path / request.param)
    log, reading = read_log_with_reading(path)
    return path, log, reading


def write(tmp_path, name: str, content: str):
    path = tmp_path / name
    path.write_text(content, encoding="utf-8")
    return path


# -- every convention against the ground truth ---------------------------------------------------


def test_every_instance_lasts_what_it_lasted(convention):
    _, log, _ = convention
    found = activity_instances(log)
    table = pd.DataFrame(
        {
            "case": found[schema.CASE].astype(str),
            "robot": found[schema.ROBOT].astype(str),
            "activity": found[schema.ACTIVITY].astype(str),
            "start": found["start_timestamp"].dt.tz_convert("UTC"),
            "end": found[schema.TIMESTAMP].dt.tz_convert("UTC"),
            "seconds": found["duration"],
        }
    )
    columns = list(table.columns)
    table = table.sort_values(columns).reset_index(drop=True)
    expected = TRUTH.instance_table()
    expected["start"] = expected["start"].dt.tz_convert("UTC").astype(table["start"].dtype)
    expected["end"] = expected["end"].dt.tz_convert("UTC").astype(table["end"].dtype)
    pd.testing.assert_frame_equal(table, expected)
    assert (table["seconds"] > 0).sum() == sum(not i.instant for i in TRUTH.instances)


def test_robots_and_their_types(convention):
    _, log, reading = convention
    assert reading.robots == TRUTH.robots
    pairs = log[[schema.ROBOT, schema.ROBOT_TYPE]].astype(str).drop_duplicates()
    assert dict(pairs.itertuples(index=False)) == TRUTH.robots
    assert reading.cases == len(TRUTH.cases)
    assert set(log[schema.CASE]) == set(TRUTH.cases)


def test_message_ids_senders_and_receivers(convention):
    _, log, _ = convention
    ids = log[schema.MSG_ID].dropna()
    assert set(ids) == TRUTH.message_ids()
    assert not ids.isin(["null", "None", "-", ""]).any(), "no marker became a message id"
    roles = schema.message_roles(log)
    for message in TRUTH.messages:
        events = log[(log[schema.MSG_ID] == message.msg_id).fillna(False).to_numpy(bool)]
        role = roles[events.index]
        assert set(events.loc[role == "send", schema.ROBOT]) == {message.sender}
        received = set(events.loc[role == "receive", schema.ROBOT])
        assert received == (set() if message.received is None else {message.receiver})
    lost = [m for m in TRUTH.messages if m.received is None]
    resent = [m for m in TRUTH.messages if m.resend_of]
    assert len(lost) == len(resent) == len(TRUTH.cases), "every run loses one and resends it"
    assert all(m.msg_id != m.resend_of and m.received is not None for m in resent)


def test_nothing_is_dropped_silently(convention):
    path, log, reading = convention
    if path.suffix == ".xes":
        rows = path.read_text().count("<event>")
    else:
        rows = len(pd.read_csv(path, dtype=str, keep_default_na=False))
    assert reading.rows == rows
    assert reading.kept == len(log) == rows and reading.dropped == {}
    assert sum(reading.events.values()) == len(log)
    assert reading.warnings == [], "a log written as its author meant raises no warning"


def test_samples_and_control_flow(convention):
    path, log, reading = convention
    starts = sum(not i.instant for i in TRUTH.instances)
    events = control_flow_events(log)
    assert (events[schema.LIFECYCLE] == "start").sum() == starts
    samples = 0 if path.name == "robot_id.csv" else len(TRUTH.samples)
    assert reading.events["sample"] == samples
    assert len(log) - len(events) == samples


# -- one convention each ---------------------------------------------------------------------


def test_inprogress_starts_match_pm4py_intervals(tmp_path):
    path = write_inprogress_xes(TRUTH, tmp_path / "log.xes")
    log, reading = read_log_with_reading(path)
    starts = sum(not i.instant for i in TRUTH.instances)
    assert reading.notes == [
        f"{starts} start rows say the state is in progress: read as control-flow events "
        "(the lifecycle wins over the state)."
    ]
    # pm4py's own interval conversion, paired by execution_id within each trace
    columns = [schema.CASE, schema.ACTIVITY, schema.TIMESTAMP, schema.LIFECYCLE, "execution_id"]
    events = log.loc[log[schema.LIFECYCLE] != "none", columns].astype({"execution_id": object})
    events = events.sort_values([schema.CASE, schema.TIMESTAMP], kind="stable")
    lifecycle = pm4py.convert_to_event_log(events)
    key = interval_lifecycle.Parameters.LIFECYCLE_INSTANCE_KEY
    intervals = interval_lifecycle.to_interval(lifecycle, parameters={key: "execution_id"})
    found = sorted(
        (trace.attributes["concept:name"], event["concept:name"], event["@@duration"])
        for trace in intervals
        for event in trace
    )
    expected = sorted((i.case, i.activity, i.seconds) for i in TRUTH.instances)
    assert found == expected


def test_inprogress_samples_keep_their_battery(tmp_path):
    path = write_inprogress_xes(TRUTH, tmp_path / "log.xes")
    log, reading = read_log_with_reading(path)
    samples = log[log[schema.STATE] == "inprogress"]
    found = sorted(
        zip(samples[schema.ROBOT], samples[schema.TIMESTAMP], samples["battery"], strict=True)
    )
    assert found == sorted((s.robot, s.time, s.battery) for s in TRUTH.samples)
    flow = len(log) - len(TRUTH.samples)
    assert reading.missing == {
        "execution_id": len(TRUTH.samples),
        "msg_id": len(log)
        - sum(i.msg_id is not None for i in TRUTH.instances)
        - sum(i.msg_id is not None and not i.instant for i in TRUTH.instances),
        "battery": flow,
    }


def test_robot_id_csv_markers_and_roles(tmp_path):
    path = write_robot_id_csv(TRUTH, tmp_path / "log.csv")
    log, reading = read_log_with_reading(path)
    assert reading.columns["robot_id"] == "robot"
    assert reading.columns["org:resource"] == "robot type"
    assert reading.columns["msg_sender"] == "message sender"
    expected = robot_id_battery(TRUTH)
    assert log["battery"].isna().tolist() == [value is None for value in expected]
    assert log["battery"].dropna().tolist() == [v for v in expected if v is not None]
    message_events = sum(2 - i.instant for i in TRUTH.instances if i.msg_id)
    raw = pd.read_csv(path, dtype=str, keep_default_na=False)
    assert set(raw["battery"]) >= set(BATTERY_MARKERS)
    assert reading.missing == {
        "lifecycle:transition": sum(i.instant for i in TRUTH.instances),
        "msg_id": len(raw) - message_events,
        "msg_sender": len(raw) - message_events,
        "msg_receiver": len(raw) - message_events,
        "battery": expected.count(None),
    }
    assert reading.notes == [
        f"{message_events} message events take their role from msg_sender / msg_receiver."
    ]
    sends = sum(1 for i in TRUTH.instances if i.msg_id and i.activity.endswith("!")) * 2
    assert (log[schema.MSG_ROLE] == "send").sum() == sends


# -- the thesis' own log -----------------------------------------------------------------------


def test_thesis_log_warns_of_its_days_and_splits_them_by_gap(thesis_csv):
    raw = pd.read_csv(thesis_csv)
    days = pd.to_datetime(raw["time"], format="ISO8601").dt.date
    assert days.nunique() == 5
    _, whole = read_log_with_reading(thesis_csv)
    assert whole.cases == 1
    assert any("spans 5 days" in w and "--case-gap 1h" in w for w in whole.warnings)
    log, split = read_log_with_reading(thesis_csv, case_gap="1h")
    assert split.cases == 5 and not any("days" in w for w in split.warnings)
    per_case = log.groupby(schema.CASE).size().sort_index().tolist()
    assert per_case == days.value_counts().sort_index().tolist()
    assert split.kept == len(raw) and split.dropped == {}
    assert split.events["start"] == (raw["lifecycle"] == "start").sum()
    assert split.robots == dict.fromkeys(sorted(raw["resource"].unique()))


# -- rules on small logs ---------------------------------------------------------------------


def test_lifecycle_wins_over_state_and_only_untransitioned_rows_are_samples(tmp_path):
    path = write(
        tmp_path,
        "states.csv",
        "time,activity,lifecycle,state\n"
        "2024-01-01T10:00:00Z,a,start,inprogress\n"
        "2024-01-01T10:00:01Z,a,none,In Progress\n"
        "2024-01-01T10:00:02Z,a,,in_progress\n"
        "2024-01-01T10:00:03Z,a,complete,inprogress\n"
        "2024-01-01T10:00:04Z,b,none,\n"
        "2024-01-01T10:00:05Z,c,,done\n",
    )
    log, reading = read_log_with_reading(path)
    lifecycles = ["start", "none", "none", "complete", "none", "complete"]
    states = ["none", "inprogress", "inprogress", "none", "none", "none"]
    assert log[schema.LIFECYCLE].tolist() == lifecycles
    assert log[schema.STATE].tolist() == states
    assert reading.events == {"start": 1, "complete": 2, "instant": 1, "sample": 2}
    assert "1 start and 1 complete rows say the state is in progress" in reading.notes[0]


def test_other_transitions_are_dropped_and_named(tmp_path):
    path = write(
        tmp_path,
        "xes_like.csv",
        "time,activity,lifecycle\n"
        "2024-01-01T10:00:00Z,a,schedule\n"
        "2024-01-01T10:00:01Z,a,start\n"
        "2024-01-01T10:00:02Z,a,suspend\n"
        "2024-01-01T10:00:03Z,a,schedule\n"
        "2024-01-01T10:00:04Z,a,complete\n",
    )
    log, reading = read_log_with_reading(path)
    assert reading.dropped == {
        "lifecycle 'schedule' is not a start, an end or none": [2, 5],
        "lifecycle 'suspend' is not a start, an end or none": [4],
    }
    assert reading.rows == 5 and reading.kept == len(log) == 2
    assert log[schema.EVENT_ID].tolist() == ["1", "4"], "ids are the rows' places in the file"


def test_lowercase_none_is_an_instant_event_and_markers_are_missing(tmp_path):
    path = write(
        tmp_path,
        "markers.csv",
        "time,activity,lifecycle,robot,msg_id\n"
        "2024-01-01T10:00:00Z,a,none,r1,null\n"
        "2024-01-01T10:00:01Z,b,None,N/A,-\n"
        "2024-01-01T10:00:02Z,c,NULL,r2, \n"
        "2024-01-01T10:00:03Z,d,complete,NaN,NA\n",
    )
    log, reading = read_log_with_reading(path)
    assert log[schema.LIFECYCLE].tolist() == ["none", "complete", "complete", "complete"]
    assert log[schema.ROBOT].isna().tolist() == [False, True, False, True]
    assert log[schema.MSG_ID].tolist()[3] == "NA", "only the listed markers mean missing"
    assert reading.missing == {"lifecycle": 2, "robot": 2, "msg_id": 3}


def test_warnings_no_pairs_and_one_valued_entity(tmp_path):
    path = write(
        tmp_path,
        "flat.csv",
        "time,activity,robot_id,mission_id\n"
        "2024-01-01T10:00:00Z,a,r1,m7\n"
        "2024-01-01T10:00:05Z,b,r1,m7\n",
    )
    _, reading = read_log_with_reading(path)
    assert reading.warnings == [
        "The column 'robot_id' (robot) has one value, 'r1', on every row that has one: it "
        "tells nothing apart.",
        "The column 'mission_id' (an id) has one value, 'm7', on every row that has one: it "
        "tells nothing apart.",
        "No start/complete pairs found: every activity lasts 0 s (map the column that says "
        "start and complete with --map COLUMN=lifecycle if there is one).",
    ]


def test_org_resource_alone_is_the_robot(tmp_path):
    path = write(
        tmp_path,
        "org.csv",
        "time,activity,org:resource,org:role\n2024-01-01T10:00:00Z,a,drone,Drone\n",
    )
    _, reading = read_log_with_reading(path)
    assert reading.columns == {
        "time": "time",
        "activity": "activity",
        "org:resource": "robot",
        "org:role": "robot type",
    }
    assert reading.robots == {"drone": "Drone"}


def test_case_gap_counts_pauses_of_the_whole_log(tmp_path):
    times = ["10:00:00", "10:00:50", "10:02:30", "10:02:40", "10:04:10"]
    rows = "".join(f"2024-01-01T{t}Z,a\n" for t in times)
    path = write(tmp_path, "gaps.csv", "time,activity\n" + rows)
    # hand-counted: pauses of 50 s, 100 s, 10 s, 90 s
    assert read_log(path, case_gap="90s")[schema.CASE].tolist() == ["1", "1", "2", "2", "3"]
    assert read_log(path, case_gap="2min")[schema.CASE].tolist() == ["1"] * 5


@pytest.mark.parametrize(
    ("gap", "message"),
    [
        ("soon", r"--case-gap 'soon' is not a duration such as 1h, 90s, 30min or 2d\."),
        ("0s", r"--case-gap '0s' must be longer than nothing\."),
    ],
)
def test_bad_case_gap(thesis_csv, gap, message):
    with pytest.raises(InputError, match=message):
        read_log(thesis_csv, case_gap=gap)


def test_case_gap_needs_a_log_without_cases(tmp_path):
    path = write_robotale_csv(TRUTH, tmp_path / "log.csv")
    with pytest.raises(InputError, match=r"by the column 'case'; --case-gap splits only a log"):
        read_log(path, case_gap="1h")


def test_a_log_of_dropped_rows_is_refused(tmp_path):
    path = write(tmp_path, "odd.csv", "time,activity,lifecycle\n2024-01-01T10:00Z,a,assign\n")
    with pytest.raises(InputError, match=r"odd\.csv: no row is an event \(lifecycle 'assign'"):
        read_log(path)


def test_aborted_and_cancelled_ends_keep_their_outcome_and_close_their_activity(tmp_path):
    """Robots fail: an aborted or cancelled goal ends its activity (it has a duration) and the
    log says how it went; XES' abort transitions read the same way."""
    path = write(
        tmp_path,
        "goals.csv",
        "case,time,activity,lifecycle,robot\n"
        "1,2024-01-01T10:00:00Z,navigate,start,r1\n"
        "1,2024-01-01T10:00:30Z,navigate,aborted,r1\n"
        "1,2024-01-01T10:01:00Z,navigate,start,r1\n"
        "1,2024-01-01T10:01:05Z,navigate,Cancelled,r1\n"
        "1,2024-01-01T10:02:00Z,dock,start,r1\n"
        "1,2024-01-01T10:02:20Z,dock,ate_abort,r1\n"
        "1,2024-01-01T10:03:00Z,dock,start,r1\n"
        "1,2024-01-01T10:03:10Z,dock,complete,r1\n",
    )
    log, reading = read_log_with_reading(path)
    assert reading.dropped == {}
    assert (reading.events["aborted"], reading.events["cancelled"]) == (2, 1)
    found = activity_instances(log)
    assert found["duration"].tolist() == [30.0, 5.0, 20.0, 10.0]
    assert found[schema.LIFECYCLE].tolist() == ["aborted", "cancelled", "aborted", "complete"]


def test_pairs_that_all_last_nothing_are_warned_of(tmp_path):
    rows = ["case,time,activity,lifecycle"]
    for case in ("1", "2"):
        for second, activity in ((0, "takeoff"), (5, "explore")):
            for lifecycle in ("start", "complete"):
                rows.append(f"{case},2024-01-01T10:00:0{second}Z,{activity},{lifecycle}")
    _, reading = read_log_with_reading(write(tmp_path, "flat.csv", "\n".join(rows) + "\n"))
    pairs = sum(row.endswith(",start") for row in rows)  # counted by hand: 4
    assert reading.warnings == [
        f"Every one of the {pairs} start/complete pairs has one time for both: every activity "
        "lasts 0 s (are the starts stamped with the completion's time?)."
    ]
    # one pair that lasts is enough for no warning
    rows[-1] = rows[-1].replace("10:00:05", "10:00:07")
    _, reading = read_log_with_reading(write(tmp_path, "lasting.csv", "\n".join(rows) + "\n"))
    assert reading.warnings == []


_HEADER = "case,activity,timestamp,lifecycle,robot,extra\n"
_ROWS = "1,a,2024-01-01T00:00:00Z,start,r1,{}\n1,a,2024-01-01T00:00:01Z,complete,r1,{}\n"
#: the ``extra`` column's two cells, and whether pyarrow's reader takes the file (else it goes
#: to pandas' parser; ``None``: either may)
_CELLS = {
    "integers": ("1", "2", True),
    "a float and a missing cell": ("1.5", "", True),
    "markers": ("null", "-", True),
    "text that is not a marker": ("NA", "n.a.", True),
    "quoted text with a quote": ('"x ""y"""', '""', True),
    "numbers with exponents": ("1e3", "1E-2", True),
    "leading zeros in text": ("007", "x", True),
    "truth values": ("True", "False", False),
    "dates": ("2024-01-02", "2024-01-03", False),
    "clock times": ("10:00:00", "11:00:00", False),
    "blanks beside a number": (" 1", "2 ", False),
    "quoted text with a comma and a blank": ('"x, y"', "z", False),
    "a line break in a cell": ('"two\nlines"', "z", None),
}


@pytest.mark.parametrize("cells", _CELLS.values(), ids=_CELLS.keys())
def test_a_csv_reads_as_pandas_parser_reads_it(tmp_path, cells):
    """Whichever reader a file goes to, its cells are pandas' parser's with robotale's
    options (markers missing, the text columns and the time column as text)."""
    first, second, fast = cells
    text = _HEADER + _ROWS.format(first, second)
    names = ["case", "activity", "lifecycle", "robot"]
    if fast is not None:
        assert (reading.arrow_csv(text, names, "timestamp") is not None) == fast
    table, missing = _csv_table(tmp_path / "log.csv", text, names, "timestamp")
    pandas = pd.read_csv(
        io.StringIO(text),
        dtype=dict.fromkeys([*names, "timestamp"], str),
        keep_default_na=False,
        na_values=sorted(reading.MISSING_MARKERS),
        index_col=False,
    )
    pd.testing.assert_frame_equal(table, pandas)
    assert missing == {c: int(n) for c, n in pandas.isna().sum().items() if n}


def test_a_long_integer_keeps_every_digit(tmp_path):
    """pyarrow's reader would take 12345678901234567890 for a float (12345678901234567168):
    such a file is read by pandas' parser, which keeps the integer."""
    path = tmp_path / "log.csv"
    path.write_text(_HEADER + _ROWS.format("12345678901234567890", "1"))
    assert read_log(path)["extra"].tolist() == [12345678901234567890, 1]
