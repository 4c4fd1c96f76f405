"""The perspectives of one known execution give the same answers whichever tool wrote its log.

The log files come from ``tests/conventions.py`` (robotale's CSV, an XES whose starts say
``state=inprogress`` with ``null`` markers, a CSV with ``robot_id`` + ``org:resource`` and
senders/receivers); every expected figure is computed here from the ground truth with plain
pandas, never by the code under test.
"""

from __future__ import annotations

import pytest
from conventions import (
    busy_seconds,
    ground_truth,
    write_inprogress_xes,
    write_robot_id_csv,
    write_robotale_csv,
)

from robotale.enhancement.report import all_perspectives
from robotale.eventlog.readers import read_log

WRITERS = {
    "robotale.csv": write_robotale_csv,
    "inprogress.xes": write_inprogress_xes,
    "robot_id.csv": write_robot_id_csv,
}
TRUTH = ground_truth()


@pytest.fixture(scope="module", params=list(WRITERS))
def perspectives(request, tmp_path_factory):
    path = WRITERS[request.param](TRUTH, tmp_path_factory.mktemp("log") / request.param)
    return all_perspectives(read_log(path))


def _truth_working_and_waiting() -> tuple[float, float]:
    """Working time: the time each robot is doing at least one activity; waiting: the gaps
    between its first start and last end in a case, summed over robots and cases."""
    table = TRUTH.instance_table()
    working = waiting = 0.0
    for _, own in table.groupby(["case", "robot"]):
        busy = busy_seconds(own)
        working += busy
        waiting += (own["end"].max() - own["start"].min()).total_seconds() - busy
    return working, waiting


def test_working_and_waiting_time(perspectives):
    working, waiting = _truth_working_and_waiting()
    summary = perspectives["performance"].summary
    assert summary["working_time"] == pytest.approx(working)
    assert summary["waiting_time"] == pytest.approx(waiting)


def test_case_durations_and_variants(perspectives):
    table = TRUTH.instance_table()
    spans = table.groupby("case").agg(first=("start", "min"), last=("end", "max"))
    durations = (spans["last"] - spans["first"]).dt.total_seconds()
    summary = perspectives["performance"].summary
    assert summary["cases"] == len(TRUTH.cases)
    assert summary["case_duration_mean"] == pytest.approx(durations.mean())
    # both runs follow the same plan, so one variant holds every case
    assert summary["variants"] == 1
    assert summary["top_variant_cases"] == len(TRUTH.cases)


def test_messages_lost_and_resent_under_a_new_id(perspectives):
    messages = TRUTH.messages
    summary = perspectives["communication"].summary
    assert summary["messages"] == len(messages)
    assert summary["received"] == sum(m.received is not None for m in messages)
    assert summary["lost"] == sum(m.received is None for m in messages)
    assert summary["resends_new_id"] == sum(m.resend_of is not None for m in messages)
    assert summary["resends_same_id"] == 0
    recovered = {m.resend_of for m in messages if m.resend_of and m.received is not None}
    assert summary["recovered"] == len(recovered)


def test_low_battery_events_whatever_their_lifecycle(perspectives):
    expected = sum(i.activity == "low_battery" for i in TRUTH.instances)
    assert perspectives["battery"].summary["low_battery_events"] == expected
