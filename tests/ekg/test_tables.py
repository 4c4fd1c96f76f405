"""The EKG tables computed before anything is written, checked by hand."""

from __future__ import annotations

import pandas as pd
import pytest

from robotale.ekg.tables import communication_roles, graph_tables
from robotale.errors import InputError
from robotale.eventlog import schema


def log(rows: list[tuple], extra: dict | None = None) -> pd.DataFrame:
    """A canonical log from (seconds, activity, robot) rows."""
    table = pd.DataFrame(rows, columns=["t", schema.ACTIVITY, schema.ROBOT])
    table[schema.TIMESTAMP] = pd.Timestamp("2024-01-01T00:00Z") + pd.to_timedelta(
        table.pop("t"), unit="s"
    )
    table[schema.CASE] = "1"
    for column, values in (extra or {}).items():
        table[column] = values
    return table


def pairs(tables, entity_type: str) -> list[tuple[int, int]]:
    df = tables.df[tables.df["entityType"] == entity_type]
    return list(zip(df["source"], df["target"], strict=True))


def test_df_follows_time_then_log_order():
    # Rows 1 and 2 share a time: the file's order decides; row 3 happened first.
    tables = graph_tables(
        log([(5, "a", "r"), (7, "b", "r"), (7, "c", "r"), (1, "d", "r")]), ["robot"]
    )
    assert pairs(tables, "robot") == [(3, 0), (0, 1), (1, 2)]


def test_a_cell_may_name_several_entities():
    tables = graph_tables(
        log([(1, "load", "r1, r2"), (2, "move", "r1"), (3, "move", "r2"), (4, "unload", "r2")]),
        ["robot"],
    )
    entities = dict(zip(tables.entities.index, tables.entities["id"], strict=True))
    corr = sorted(
        (e, entities[n]) for e, n in zip(tables.corr["event"], tables.corr["entity"], strict=True)
    )
    assert corr == [(0, "r1"), (0, "r2"), (1, "r1"), (2, "r2"), (3, "r2")]
    assert sorted(pairs(tables, "robot")) == [(0, 1), (0, 2), (2, 3)]
    ids = dict(
        zip(
            zip(tables.df["source"], tables.df["target"], strict=True),
            tables.df["entityId"],
            strict=True,
        )
    )
    assert ids == {(0, 1): "r1", (0, 2): "r2", (2, 3): "r2"}


def test_list_cells_and_missing_values():
    table = log(
        [(1, "a", "r1"), (2, "b", "r1"), (3, "c", "r1")], {"parts": [["p1", "p2"], None, ["p2"]]}
    )
    tables = graph_tables(table, ["parts"])
    assert sorted(tables.entities["id"]) == ["p1", "p2"]
    assert pairs(tables, "parts") == [(0, 2)]


def test_comm_joins_every_send_to_every_receive_of_a_message():
    table = log(
        [
            (1, "ask!", "a"),
            (2, "ask?", "b"),
            (3, "ask?", "c"),
            (4, "ask!", "a"),
            (5, "tell!", "b"),
            (6, "tell?", "a"),
            (7, "think", "a"),
        ],
        {schema.MSG_ID: ["m1", "m1", "m1", "m1", "m2", "m2", "m2"]},
    )
    comm = graph_tables(table, ["robot"]).comm
    assert sorted(zip(comm["source"], comm["target"], comm["msgId"], strict=True)) == [
        (0, 1, "m1"),
        (0, 2, "m1"),
        (3, 1, "m1"),
        (3, 2, "m1"),
        (4, 5, "m2"),
    ]


def test_df_and_comm_never_cross_a_case():
    # Two simulated runs: both start at the same instant and both number their messages m_1.
    table = log(
        [
            (0, "take_off", "drone"),
            (1, "weed_position!", "tractor_1"),
            (2, "weed_position?", "drone"),
            (0, "take_off", "drone"),
            (1, "weed_position!", "tractor_1"),
            (3, "weed_position?", "drone"),
        ],
        {schema.MSG_ID: [None, "m_1", "m_1", None, "m_1", "m_1"]},
    )
    table[schema.CASE] = ["run_1"] * 3 + ["run_2"] * 3
    tables = graph_tables(table, ["robot", "msg_id"])
    assert sorted(pairs(tables, "robot")) == [(0, 2), (3, 5)]
    assert sorted(pairs(tables, "msg_id")) == [(1, 2), (4, 5)]
    assert sorted(zip(tables.comm["source"], tables.comm["target"], strict=True)) == [
        (1, 2),
        (4, 5),
    ]


def test_without_the_naming_convention_msg_role_decides():
    table = log(
        [(1, "send", "a"), (2, "get", "b"), (3, "other", "c")],
        {schema.MSG_ID: ["m", "m", "m"], schema.MSG_ROLE: ["send", "receive", None]},
    )
    tables = graph_tables(table, ["robot"])
    assert communication_roles(tables.events).tolist() == ["send", "receive", None]
    assert tables.comm[["source", "target"]].values.tolist() == [[0, 1]]


def test_with_the_naming_convention_names_decide():
    # As in the thesis' log: a decision tagged with the message's fields is no message.
    table = log(
        [(1, "select", "a"), (2, "tell!", "a"), (3, "tell?", "b")],
        {schema.MSG_ID: ["m", "m", "m"], schema.MSG_ROLE: ["send", "send", "receive"]},
    )
    assert graph_tables(table, ["robot"]).comm[["source", "target"]].values.tolist() == [[1, 2]]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda t: t.assign(**{schema.TIMESTAMP: t[schema.TIMESTAMP].dt.tz_localize(None)}),
            "timestamps must be timezone-aware",
        ),
        (lambda t: t.assign(order=1), "The column 'order' would overwrite the event's own"),
        (lambda t: t.assign(timestamp=1), "both become the property 'timestamp'"),
        (lambda t: t.assign(**{"bad`name": 1}), "The column name 'bad`name' cannot be used"),
        (lambda t: t.drop(columns=schema.ACTIVITY), "has no 'activity' column"),
        (lambda t: t.iloc[:0], "has no events"),
        (lambda t: t.assign(**{schema.EVENT_ID: ["e1", "e1"]}), "'e1' is missing or not unique"),
    ],
)
def test_logs_that_cannot_be_stored(change, message):
    with pytest.raises(InputError, match=message):
        graph_tables(change(log([(1, "a", "r"), (2, "b", "r")])), ["robot"])


def test_a_named_zone_is_kept_and_offsets_are_written_as_such():
    from robotale.ekg.load import timezone_name

    rome = pd.Series(pd.to_datetime(["2024-03-31T01:30:00"]).tz_localize("Europe/Rome"))
    assert timezone_name(rome) == "Europe/Rome"
    fixed = pd.Series(pd.to_datetime(["2024-03-31T01:30:00-03:30"]))
    assert timezone_name(fixed) == "-03:30"
    assert timezone_name(pd.Series(pd.to_datetime(["2024-03-31T01:30:00Z"]))) == "+00:00"


def test_a_log_whose_events_name_no_entity_is_refused_saying_why():
    """Building nothing from a non-empty log and saying nothing would look like success."""
    frame = pd.DataFrame(
        {
            "case:concept:name": ["run"] * 3,
            "concept:name": ["a", "b", "c"],
            "time:timestamp": pd.to_datetime([1, 2, 3], unit="s", utc=True),
            "robot": [None, None, None],
        }
    )
    with pytest.raises(InputError) as error:
        graph_tables(frame, ["robot"])
    assert str(error.value) == (
        "None of the log's 3 events has a value in its entity column(s) robot, so no entity "
        "and no DF edge would be built; name the columns that identify what the events belong "
        "to with --entities (e.g. --entities case)."
    )
