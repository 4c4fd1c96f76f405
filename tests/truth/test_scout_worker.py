"""The scout-and-worker mission: every message arrives, and the analysis must say so.

The scout's Explore consumes the worker's ``target_done`` itself (``resume_on``), with no catch
event; the runtime tags that as a receive, so no message the truth delivered is reported
lost, and no resend is invented (every target is a message of its own).
"""

from __future__ import annotations

from pathlib import Path

import oracle
import pytest
from compare import _message_table, prepared

from robotale.sim.batch import simulate_batch
from robotale.sim.run import RunPlan
from robotale.sim.worldspec import load_world

MISSION = Path(__file__).parent / "missions" / "scout_worker.yaml"


@pytest.fixture(scope="module")
def scout_worker(tmp_path_factory):
    world = load_world(MISSION)
    out = tmp_path_factory.mktemp("scout_worker")
    summary = simulate_batch([RunPlan(world, i, 1) for i in range(1, 6)], out, workers=0)
    assert summary["outcomes"] == {"ended": 5}
    return out, prepared(out)


def test_every_message_the_truth_delivered_is_received_and_none_is_lost(scout_worker):
    out, log = scout_worker
    runs = oracle.load_batch(out)
    truth = [m for run in runs for m in oracle.messages(run)]
    done = [m for m in truth if m.type == "target_done"]
    assert len(runs) == 5 and len(done) >= 15  # 3-5 weeds a run, each answered
    assert all(m.delivered for m in truth)  # nothing was lost in this mission
    assert all(m.receivers == ("scout",) for m in done)  # the skill consumed each
    table = _message_table(log, 1.0)
    reported = {(row["case"], row["msg_id"]): row for _, row in table.iterrows()}
    assert set(reported) == {(m.case, m.msg_id) for m in truth}
    wrongly_lost = [key for key, row in reported.items() if row["lost"]]
    assert wrongly_lost == []
    # the scout's consumption is a receive tag with the send's id, as a catch event leaves
    receives = log[(log["msg_role"] == "receive") & (log["concept:name"] == "target_done?")]
    assert set(zip(receives["case:concept:name"], receives["msg_id"], strict=True)) == {
        (m.case, m.msg_id) for m in done
    }
    assert set(receives["robot"]) == {"scout"}


def test_every_resend_the_analysis_names_is_real(scout_worker):
    out, log = scout_worker
    truth = {
        (run.case, m.msg_id): m.resend_of
        for run in oracle.load_batch(out)
        for m in oracle.messages(run)
    }
    assert not any(truth.values())  # each target is its own message: nothing is resent
    table = _message_table(log, 1.0)
    column = "resent_as" if "resent_as" in table.columns else "resend_of"
    named = table[table[column].notna() & (table[column].astype(str) != "")]
    assert named[["case", "msg_id", column]].values.tolist() == []
