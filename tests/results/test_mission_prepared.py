"""The Mission page reads what counts as a slow activity from the prepared results instead of
computing it from the whole log for every run it loads: its answers are those it gives when
nothing was prepared."""

from __future__ import annotations

import pandas as pd

from robotale.cli import main
from robotale.ekg.columnar import stored_table
from robotale.enhancement.mission import mission_run, slow_limits
from robotale.enhancement.timeline import run_list
from robotale.results.findings import stored_slow_limits
from robotale.results.logdata import LogData
from robotale.results.mission import stored_mission


def answers(run) -> dict:
    """What the Mission page asks of a run: its summary (with its moments), a state, a window."""
    middle = run.duration / 2
    return {"summary": run.summary(), "state": run.state(middle), "window": run.window(0, middle)}


def test_mission_answers_are_the_same_with_the_prepared_slow_table(
    neo4j_driver, log_name, thesis_csv
):
    # the tests' ingest prepares the pages before it ends
    assert main(["ingest", str(thesis_csv), "--log", log_name, "--case-gap", "1h"]) == 0
    log = stored_table(neo4j_driver, log_name)
    cases = [str(c) for c in run_list(log)["case"]]
    # nothing kept: each run computes the whole log's slow table itself
    unprepared = {case: answers(mission_run(log, case)) for case in cases}

    logs = LogData()
    prepared = {case: answers(stored_mission(neo4j_driver, logs, log_name, case)) for case in cases}
    assert not logs.computed  # the slow table was read from what the preparation kept
    assert prepared == unprepared
    moments = [m for a in prepared.values() for m in a["summary"]["moments"]]
    assert any(m["kind"] == "slow activity" for m in moments)  # the comparison covers them
    # the kept table reads back exactly as computed, numbers to the last bit
    kept = stored_slow_limits(neo4j_driver, logs, log_name)
    pd.testing.assert_frame_equal(kept, slow_limits(log), check_dtype=False, rtol=0, atol=0)
