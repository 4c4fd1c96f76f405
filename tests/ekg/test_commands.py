"""`robotale ingest`, `logs` and `demo` against the session's Neo4j."""

from __future__ import annotations

import itertools
import shutil

import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.logs import delete_log, list_logs, log_summary


def run(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_ingest_list_show_delete(tmp_path, capsys, neo4j_driver, log_name, thesis_csv):
    code, out, err = run(
        capsys,
        "ingest",
        str(thesis_csv),
        "--log",
        log_name,
        "--entities",
        "robot,msg_id",
        "--aggregate",
        "activity,robot",
    )
    assert code == 0, err
    assert f"Log '{log_name}': 3,648 events" in out
    # the edges between consecutive activity instances of each robot and each message, by
    # activity and robot, counted in pandas from the completions (the log has no samples)
    ends = pd.read_csv(thesis_csv).query("lifecycle != 'start'")
    ends = ends.sort_values("time", kind="stable")  # one offset: the text sorts as the time
    pairs = set()
    for column in ("resource", "msg_id"):
        chains = ends.dropna(subset=[column]).groupby(column, sort=False)
        for _, chain in chains:
            classes = list(zip(chain["activity"], chain["resource"], strict=True))
            pairs |= {(column, *a, *b) for a, b in itertools.pairwise(classes)}
    assert f"DF_C      activity+robot {len(pairs)}" in out

    code, out, _ = run(capsys, "logs", "list")
    line = next(line for line in out.splitlines() if line.startswith(log_name))
    assert "[complete]  3,648 events  entities: robot, msg_id  classes: activity+robot" in line

    code, out, _ = run(capsys, "logs", "show", log_name)
    assert code == 0 and f"from {thesis_csv}" in out
    shown = {" ".join(line.split()[:-1]): line.split()[-1] for line in out.splitlines()[1:]}
    assert shown["events"] == "3,648" and shown["entities:robot"] == "3"

    code, out, _ = run(capsys, "logs", "delete", log_name)
    assert code == 0 and log_name not in {log["name"] for log in list_logs(neo4j_driver)}
    code, _, err = run(capsys, "logs", "delete", log_name)
    assert code == 1 and f"There is no log named '{log_name}'" in err


def test_ingest_maps_columns_and_picks_the_case(tmp_path, capsys, neo4j_driver, log_name):
    path = tmp_path / "shift.csv"
    pd.DataFrame(
        {
            "Zeit": [
                "2024-01-01T08:00:00+01:00",
                "2024-01-01T08:01:00+01:00",
                "2024-01-01T08:02:00+01:00",
            ],
            "Tätigkeit": ["load", "drive", "unload"],
            "wer": ["truck, crane", "truck", "truck, crane"],
            "schicht": ["s1", "s1", "s2"],
        }
    ).to_csv(path, index=False)
    code, _, err = run(
        capsys,
        "ingest",
        str(path),
        "--log",
        log_name,
        "--map",
        "Zeit=time",
        "--map",
        "Tätigkeit=activity",
        "--map",
        "wer=robot",
        "--case",
        "schicht",
    )
    assert code == 0, err
    counts = log_summary(neo4j_driver, log_name)["counts"]
    assert counts["cases"] == 2
    assert counts["entities:robot"] == 2
    assert counts["CORR:robot"] == 5
    # Directly-follows stays inside a case: truck's load -> drive in shift s1; its unload and
    # crane's second event are in shift s2, so they start new chains.
    assert counts["DF:robot"] == 1


def test_bad_map_option(capsys, tmp_path):
    code, _, err = run(capsys, "ingest", str(tmp_path / "x.csv"), "--map", "Zeit")
    assert code == 1 and "--map 'Zeit' is not COLUMN=FIELD" in err


@pytest.mark.parametrize("name", ["", "   "])
def test_an_empty_log_name_is_refused_not_replaced_by_the_files(capsys, thesis_csv, name):
    code, _, err = run(capsys, "ingest", str(thesis_csv), "--log", name)
    assert code == 1
    assert err.strip() == (
        f"robotale: --log {name!r} names no log: give it a name, or leave --log out to use "
        "'robotic_data'."
    )


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")
def test_ingest_skips_a_corrupted_run_when_asked(
    capsys, neo4j_driver, log_name, agri_recordings, tmp_path
):
    from robotale.eventlog.prepare import prepare

    runs = tmp_path / "runs"
    for recorded in sorted(p for p in agri_recordings.iterdir() if p.is_dir()):
        shutil.copytree(recorded, runs / recorded.name)
    bad = runs / "run_0000"
    bad.mkdir()
    (bad / "metadata.yaml").write_text("rosbag2_bagfile_information: [\n")
    capsys.readouterr()
    code, _, err = run(capsys, "ingest", str(runs), "--log", log_name)
    assert code == 1 and f"robotale: {bad} is not a readable rosbag2 directory" in err
    assert log_name not in {log["name"] for log in list_logs(neo4j_driver)}
    code, out, err = run(capsys, "ingest", str(runs), "--log", log_name, "--skip-bad")
    assert code == 0, err
    assert f"skipped run_0000: {bad} is not a readable rosbag2 directory" in err
    assert out.strip().splitlines()[-1] == "kept 2 of 3 run(s); skipped 1: run_0000"
    assert log_summary(neo4j_driver, log_name)["counts"]["events"] == len(prepare(agri_recordings))


def test_a_full_disk_under_the_home_keeps_the_graph_and_says_what_was_not_kept(
    capsys, caplog, neo4j_driver, log_name, thesis_csv, small_disk, monkeypatch
):
    home = small_disk("64k")  # the graph fits in Neo4j, the log's columnar copy not here
    monkeypatch.setenv("ROBOTALE_HOME", str(home))
    capsys.readouterr()
    code, _, err = run(capsys, "ingest", str(thesis_csv), "--log", log_name)
    assert code == 0, err
    assert log_summary(neo4j_driver, log_name)["counts"]["events"] == len(pd.read_csv(thesis_csv))
    [said] = [r.getMessage() for r in caplog.records if "was not kept" in r.getMessage()]
    assert said.startswith(f"The columnar copy of {log_name!r} was not kept (The disk of {home}")
    assert "is full" in said and not list(home.rglob("events.parquet*"))


def test_xes_log_with_a_named_time_zone(tmp_path, capsys, neo4j_driver, log_name):
    from robotale.queries import cypher

    path = tmp_path / "zones.xes"
    path.write_text(
        """<log xmlns="http://www.xes-standard.org/"><trace><string key="concept:name" value="r1"/>
        <event><string key="concept:name" value="a"/><date key="time:timestamp"
          value="2024-03-31T01:30:00+01:00"/><string key="org:resource" value="rex"/></event>
        <event><string key="concept:name" value="b"/><date key="time:timestamp"
          value="2024-03-31T01:45:00+01:00"/><string key="org:resource" value="rex"/></event>
        </trace></log>"""
    )
    code, _, err = run(capsys, "ingest", str(path), "--log", log_name)
    assert code == 0, err
    records, _, _ = neo4j_driver.execute_query(cypher("ekg_event"), log=log_name, id="1")
    event = records[0]["e"]
    assert event["case"] == "r1" and event["robot"] == "rex" and event["activity"] == "b"
    assert event["timestamp"].iso_format() == "2024-03-31T01:45:00.000000000+01:00"
    counts = log_summary(neo4j_driver, log_name)["counts"]
    assert counts["DF:robot"] == 1 and counts["DF_C:activity / robot"] == 1


@pytest.fixture
def agri_recordings(tmp_path):
    out = tmp_path / "agri"
    assert main(["simulate", "agri", "--runs", "2", "--seed", "3", "--out", str(out)]) == 0
    return out


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")
def test_ingest_prepares_a_folder_of_recordings(capsys, neo4j_driver, log_name, agri_recordings):
    from robotale.eventlog import schema
    from robotale.eventlog.prepare import prepare

    capsys.readouterr()
    code, out, err = run(
        capsys, "ingest", str(agri_recordings), "--log", log_name, "--entities", "robot,msg_id"
    )
    assert code == 0, err
    # the graph holds exactly what `robotale prepare` makes of the same bags
    log = prepare(agri_recordings)
    counts = log_summary(neo4j_driver, log_name)["counts"]
    assert counts["events"] == len(log) and f"{len(log):,} events" in out
    assert counts["cases"] == 2
    assert counts["entities:robot"] == log[schema.ROBOT].nunique()
    assert counts["entities:msg_id"] == log[schema.MSG_ID].dropna().nunique()


def test_ingest_refuses_case_and_map_for_recordings(
    capsys, neo4j_driver, log_name, agri_recordings
):
    capsys.readouterr()
    code, _, err = run(capsys, "ingest", str(agri_recordings), "--log", log_name, "--case", "x")
    assert code == 1
    assert err.strip() == (
        f"robotale: {agri_recordings} holds recordings: --map and --case apply to CSV and XES "
        "files (each run of a recording is its own case)."
    )
    assert log_name not in {log["name"] for log in list_logs(neo4j_driver)}


def test_ingest_names_the_log_after_the_folder(capsys, neo4j_driver, agri_recordings, monkeypatch):
    monkeypatch.chdir(agri_recordings)
    delete_log(neo4j_driver, "agri")
    capsys.readouterr()
    try:
        code, out, err = run(capsys, "ingest", ".", "--rate", "0")
        assert code == 0, err
        assert out.startswith("Log 'agri': ")
    finally:
        delete_log(neo4j_driver, "agri")
