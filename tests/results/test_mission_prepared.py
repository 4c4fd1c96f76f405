"""The Mission page reads what counts as a slow activity from the prepared results instead of
computing it from the whole log for every run it loads, and keeps each run it built with the
log's build (the preparation keeps the first): its answers are those it gives when nothing
was prepared or kept."""

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
    # the slow table was read from what the preparation kept, and so was the first run; the
    # others were built (from the kept slow table) and kept
    assert dict(logs.computed) == {(log_name, "mission"): len(cases) - 1}
    assert prepared == unprepared
    # a restarted dashboard reads every run back from what was kept: the same answers
    restarted = LogData()
    kept_runs = {
        case: answers(stored_mission(neo4j_driver, restarted, log_name, case)) for case in cases
    }
    assert not restarted.computed
    assert kept_runs == unprepared
    moments = [m for a in prepared.values() for m in a["summary"]["moments"]]
    assert any(m["kind"] == "slow activity" for m in moments)  # the comparison covers them
    # the kept table reads back exactly as computed, numbers to the last bit
    kept = stored_slow_limits(neo4j_driver, logs, log_name)
    pd.testing.assert_frame_equal(kept, slow_limits(log), check_dtype=False, rtol=0, atol=0)


def test_a_run_of_a_log_nobody_prepared_is_built_once_and_kept(neo4j_driver, log_name, thesis_csv):
    assert main(["ingest", str(thesis_csv), "--log", log_name, "--pages", "visit"]) == 0
    log = stored_table(neo4j_driver, log_name)
    case = str(run_list(log)["case"].iloc[0])
    logs = LogData()
    # the run needs the log's slow limits first: computed and kept on the way
    built = answers(stored_mission(neo4j_driver, logs, log_name, case))
    assert dict(logs.computed) == {(log_name, "slow-limits"): 1, (log_name, "mission"): 1}
    assert built == answers(mission_run(log, case))
    restarted = LogData()
    assert answers(stored_mission(neo4j_driver, restarted, log_name, case)) == built
    assert not restarted.computed
