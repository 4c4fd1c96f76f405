"""A choice after a message catch written as a test of the caught payload only where the
payload decides the branch in every catch of the log; generated logs with a known rule."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from collaboration_checks import check_problems_besides_skills

from robotale.discovery.bpmn_writer import write_bpmn
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.conformance import check_conformance
from robotale.discovery.payload_choices import payload_fields
from robotale.eventlog.schema import (
    ACTIVITY,
    CASE,
    LIFECYCLE,
    MSG_ID,
    MSG_PAYLOAD,
    MSG_ROLE,
    ROBOT,
    ROBOT_TYPE,
    TIMESTAMP,
)

ROBOTS = ["worker_1", "worker_2"]


def orders(decides: bool, runs: int = 12, seed: int = 5) -> pd.DataFrame:
    """Each run the boss sends ``order`` naming one worker; each worker catches it, then
    works or rests. ``decides``: the named worker works and the other rests; otherwise each
    worker works or rests at random whoever is named."""
    rng = np.random.default_rng(seed)
    rows = []

    def event(case, t, robot, kind, activity, lifecycle, message=None, role=None, payload=None):
        rows.append({CASE: case, TIMESTAMP: t, ROBOT: robot, ROBOT_TYPE: kind,
                     ACTIVITY: activity, LIFECYCLE: lifecycle, MSG_ID: message,
                     MSG_ROLE: role, MSG_PAYLOAD: payload})  # fmt: skip

    start = pd.Timestamp("2024-01-01", tz="UTC")
    for run in range(runs):
        case, t = f"run_{run}", start + pd.Timedelta(hours=run)
        named = ROBOTS[int(rng.integers(2))]
        payload, message = json.dumps({"to": named}), f"m_{run}"
        for lifecycle in ("start", "complete"):
            event(case, t, "boss", "Boss", "order!", lifecycle, message, "send", payload)
        for robot in ROBOTS:
            at = t + pd.Timedelta(seconds=1)
            for lifecycle in ("start", "complete"):
                event(case, at, robot, "Worker", "order?", lifecycle, message, "receive", payload)
            works = robot == named if decides else bool(rng.integers(2))
            for n, lifecycle in enumerate(("start", "complete")):
                event(case, at + pd.Timedelta(seconds=2 + 5 * n), robot, "Worker",
                      "work" if works else "rest", lifecycle)  # fmt: skip
    return pd.DataFrame(rows).sort_values(TIMESTAMP, kind="stable", ignore_index=True)


@pytest.mark.parametrize("decides", [True, False])
def test_a_payload_condition_only_where_the_payload_decides(decides, tmp_path):
    log = orders(decides)
    text = write_bpmn(discover_collaboration(log))
    # the rule, counted with pandas: a worker works exactly when the order names it
    starts = log[log[LIFECYCLE] == "start"]
    did = starts[starts[ACTIVITY].isin(["work", "rest"])].set_index([CASE, ROBOT])[ACTIVITY]
    got = starts[starts[ACTIVITY] == "order?"].set_index([CASE, ROBOT])[MSG_PAYLOAD]
    named = pd.Series(
        [json.loads(p)["to"] == robot for (_, robot), p in got.items()], index=got.index
    )
    exact = bool(((did.loc[named.index] == "work") == named).all())
    assert exact == decides
    assert ("order.get('to') == robot.name" in text) is decides
    assert ("order.get('to') != robot.name" in text) is decides
    model = tmp_path / "discovered.bpmn"
    model.write_text(text)
    assert check_problems_besides_skills(model) == []
    assert check_conformance(log, model).summary["fitness"] == 1.0


def test_payload_fields_read_json_plain_values_and_the_thesis_form():
    assert payload_fields('{"to": "worker_1", "n": 2}') == (("n", "2"), ("to", "worker_1"))
    assert payload_fields('"tractor_2"') == (("data", "tractor_2"),)
    assert payload_fields("{ name: tractor_2 }") == (("name", "tractor_2"),)
    assert payload_fields(None) == () and payload_fields("  ") == ()
