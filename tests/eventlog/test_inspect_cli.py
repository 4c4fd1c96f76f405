"""`robotale inspect`, and the reading that `discover` and `perspectives` show on stderr."""

from __future__ import annotations

import json
import re

import pandas as pd
from conventions import ground_truth, write_inprogress_xes, write_robot_id_csv

from robotale.cli import main

TRUTH = ground_truth()


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_inspect_shows_roles_cases_robots_and_counts(tmp_path, capsys):
    path = write_robot_id_csv(TRUTH, tmp_path / "team.csv")
    rows = len(pd.read_csv(path))
    code, out, err = run(capsys, "inspect", str(path))
    assert code == 0 and err == ""
    assert re.search(r"^    robot_id\s+-> robot$", out, re.M)
    assert re.search(r"^    org:resource\s+-> robot type$", out, re.M)
    assert re.search(r"^    concept:instance\s+-> pairing key$", out, re.M)
    assert re.search(r"^    msg_receiver\s+-> message receiver$", out, re.M)
    assert "  cases:     2 (the column 'case_id')\n" in out
    assert "  robots:    drone (Drone), tractor_1 (Tractor), tractor_2 (Tractor)\n" in out
    assert f"  rows:      {rows} read, {rows} kept, 0 dropped\n" in out
    # the markers this file writes for no value are among those named as such
    named = out.split("  no value:  empty cells and ")[1].splitlines()[0].split(", ")
    assert {"null", "-", "N/A", "None", "NaN"} <= set(named) and "NA" not in named
    assert "pairs by concept:instance within case, robot, activity" in out
    assert "warning" not in out


def test_inspect_names_dropped_rows_and_notes(tmp_path, capsys):
    path = tmp_path / "odd.csv"
    path.write_text(
        "time,activity,lifecycle\n"
        "2024-01-01T10:00:00Z,a,schedule\n"
        "2024-01-01T10:00:01Z,a,start\n"
        "2024-01-01T10:00:04Z,a,complete\n"
    )
    code, out, _ = run(capsys, "inspect", str(path))
    assert code == 0
    assert out.startswith("Read odd.csv: 2 of 3 rows kept, 1 case (no case column: one case)")
    assert "  1 dropped: lifecycle 'schedule' is not a start, an end or none (line 2)\n" in out


def test_inspect_reports_the_lifecycle_winning_over_the_state(tmp_path, capsys):
    path = write_inprogress_xes(TRUTH, tmp_path / "log.xes")
    code, out, _ = run(capsys, "inspect", str(path))
    starts = sum(not i.instant for i in TRUTH.instances)
    assert code == 0
    assert f"note: {starts} start rows say the state is in progress" in out
    assert f"  events:    {starts} start, " in out
    assert f"{len(TRUTH.samples)} sample\n" in out


def test_inspect_thesis_log_with_and_without_case_gap(thesis_csv, capsys):
    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"], format="ISO8601").dt.date.nunique()
    code, out, _ = run(capsys, "inspect", str(thesis_csv))
    assert code == 0
    assert f"warning: robotic_data.csv has no case column and spans {days} days" in out
    code, out, _ = run(capsys, "inspect", str(thesis_csv), "--case-gap", "1h")
    assert code == 0 and "warning" not in out
    assert f"  cases:     {days} (a new case after every pause of 1h or more)\n" in out


def test_bad_case_gap_is_one_sentence(thesis_csv, capsys):
    code, out, err = run(capsys, "inspect", str(thesis_csv), "--case-gap", "an hour")
    assert code == 1 and out == ""
    assert err == (
        "robotale: --case-gap 'an hour' is not a duration such as 1h, 90s, 30min or 2d.\n"
    )


def test_discover_shows_the_reading_on_stderr_and_splits_by_gap(thesis_csv, tmp_path, capsys):
    out = tmp_path / "dfg.json"
    code, _, err = run(
        capsys, "discover", "dfg", str(thesis_csv), "--case-gap", "1h", "--out", str(out)
    )
    assert code == 0
    assert err.startswith("Read robotic_data.csv: 3,648 of 3,648 rows kept, 5 cases")
    edges = {(e["source"], e["target"]) for e in json.loads(out.read_text())["edges"]}
    assert ("land", "takeoff") not in edges, "no run flows into the next day's run"


def test_perspectives_show_the_reading_on_stderr(tmp_path, capsys):
    path = write_robot_id_csv(TRUTH, tmp_path / "team.csv")
    report = tmp_path / "report.json"
    code, _, err = run(capsys, "perspectives", str(path), "--json", str(report))
    assert code == 0 and report.exists()
    assert err.startswith("Read team.csv: ")
    assert "note: " in err and "take their role from msg_sender / msg_receiver" in err
    # the roles the reader gave the messages make the communication figures of the truth
    summary = json.loads(report.read_text())["communication"]["summary"]
    lost = sum(m.received is None for m in TRUTH.messages)
    assert (summary["messages"], summary["lost"]) == (len(TRUTH.messages), lost)
    assert summary["received"] == len(TRUTH.messages) - lost


def test_ingest_splits_the_thesis_log_by_case_gap(thesis_csv, capsys, neo4j_driver, log_name):
    from robotale.ekg.logs import log_summary

    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"], format="ISO8601").dt.date.nunique()
    code, out, err = run(capsys, "ingest", str(thesis_csv), "--log", log_name, "--case-gap", "1h")
    assert code == 0, err
    assert out.startswith(f"Read robotic_data.csv: 3,648 of 3,648 rows kept, {days} cases")
    assert log_summary(neo4j_driver, log_name)["counts"]["cases"] == days
