"""``robotale prepare`` end to end on bags written in the test."""

from __future__ import annotations

import pandas as pd
import pm4py
import pytest
from bagbuilder import agri_like

from robotale.cli import main

pytestmark = pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")


def test_prepare_writes_the_three_formats_and_says_what_it_did(tmp_path, bag_builder, capsys):
    runs = tmp_path / "runs" / "agri"
    agri_like(bag_builder).write(runs / "run_0001", manifest={"robots": {"drone": "Drone"}})
    agri_like(bag_builder, x0=5).write(runs / "run_0002")
    logs = tmp_path / "logs"
    status = main(
        [
            "prepare", str(runs), "--out", str(logs / "agri.csv"), "--xes", str(logs / "agri.xes"),
            "--ocel", str(logs / "agri.ocel.json"), "--rate", "2",
        ]
    )  # fmt: skip
    out = capsys.readouterr().out
    assert status == 0
    assert out.strip() == (
        f"48 events from 2 run(s) written to {logs / 'agri.csv'}, {logs / 'agri.xes'}, "
        f"{logs / 'agri.ocel.json'}"
    )
    csv = pd.read_csv(logs / "agri.csv")
    assert csv["case"].unique().tolist() == ["run_0001", "run_0002"]
    assert (csv["state"] == "inprogress").sum() == 2 * 12  # at 2 Hz, as test_prepare counts
    assert len(pm4py.read_xes(str(logs / "agri.xes"))) == len(csv)
    assert len(pm4py.read_ocel2_json(str(logs / "agri.ocel.json")).events) == len(csv)


def test_prepare_defaults_to_a_csv_named_after_the_source(
    tmp_path, bag_builder, monkeypatch, capsys
):
    agri_like(bag_builder).write(tmp_path / "run_0007")
    monkeypatch.chdir(tmp_path)
    assert main(["prepare", "run_0007", "--perspectives", "odom", "--rate", "0"]) == 0
    assert pd.read_csv(tmp_path / "run_0007.csv").columns[-4:].tolist() == [
        "x",
        "y",
        "z",
        "event_id",
    ]
    assert "written to run_0007.csv" in capsys.readouterr().out


def test_warnings_and_errors_are_one_line_each(tmp_path, bag_builder, capsys):
    b = bag_builder().odom(0, "drone", 0, 0, 0).tag(1, "drone", "land", "complete")
    bag = b.write(tmp_path / "run")
    assert main(["prepare", str(bag), "--out", str(tmp_path / "log.csv")]) == 0
    err = capsys.readouterr().err.splitlines()
    warnings = [line for line in err if line.startswith("robotale: warning: ")]
    assert len(warnings) == 2
    assert "1 complete event(s) have no start" in warnings[1]

    assert main(["prepare", str(bag), "--tags", "/nothing", "--out", "x.csv"]) == 1
    err = capsys.readouterr().err
    assert (
        err.strip()
        .splitlines()[-1]
        .endswith(
            f"robotale: {bag} has no tag topic matching '/nothing'; its topics are /drone/odom, "
            "/drone/tag (name the tag topics with --tags)."
        )
    )
    assert not (tmp_path / "x.csv").exists()


def _four_runs_one_corrupted(folder, bag_builder):
    """Four runs of real bags; the third's database cut short (an interrupted copy)."""
    for number in range(1, 5):
        agri_like(bag_builder, x0=number).write(folder / f"run_{number:04d}")
    [database] = (folder / "run_0003").glob("*.db3")
    database.write_bytes(database.read_bytes()[:4096])
    return folder / "run_0003"


def test_a_corrupted_run_stops_prepare_before_anything_is_written(tmp_path, bag_builder, capsys):
    bad = _four_runs_one_corrupted(tmp_path / "runs", bag_builder)
    out = tmp_path / "log.csv"
    assert main(["prepare", str(tmp_path / "runs"), "--out", str(out)]) == 1
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error.startswith(f"robotale: {bad} is not a readable rosbag2 directory")
    assert not out.exists()


def test_skip_bad_keeps_the_good_runs_and_names_the_bad_one(tmp_path, bag_builder, capsys):
    bad = _four_runs_one_corrupted(tmp_path / "runs", bag_builder)
    out = tmp_path / "log.csv"
    assert main(["prepare", str(tmp_path / "runs"), "--out", str(out), "--skip-bad"]) == 0
    captured = capsys.readouterr()
    skipped = [line for line in captured.err.splitlines() if "skipped" in line]
    assert len(skipped) == 1
    assert (
        skipped[0]
        .split("robotale: ")[-1]
        .startswith(f"skipped run_0003: {bad} is not a readable rosbag2 directory")
    )
    assert captured.out.strip().splitlines()[-1] == "kept 3 of 4 run(s); skipped 1: run_0003"
    written = pd.read_csv(out)
    assert written["case"].unique().tolist() == ["run_0001", "run_0002", "run_0004"]
    # the three good runs' events are exactly those prepared without the bad one
    (tmp_path / "good").mkdir()
    for run in ("run_0001", "run_0002", "run_0004"):
        (tmp_path / "good" / run).symlink_to(tmp_path / "runs" / run)
    alone = tmp_path / "alone.csv"
    assert main(["prepare", str(tmp_path / "good"), "--out", str(alone)]) == 0
    pd.testing.assert_frame_equal(written, pd.read_csv(alone))


@pytest.mark.parametrize(
    ("suffix", "executor"), [(".csv", "local:2"), (".parquet", None), (".parquet", "local:2")]
)
def test_skip_bad_keeps_the_good_runs_on_workers_and_in_datasets(
    tmp_path, bag_builder, capsys, suffix, executor
):
    from robotale.eventlog.readers import read_log

    bad = _four_runs_one_corrupted(tmp_path / "runs", bag_builder)
    out = tmp_path / f"log{suffix}"
    options = ["--executor", executor] if executor else []
    assert main(["prepare", str(tmp_path / "runs"), "--out", str(out), "--skip-bad", *options]) == 0
    captured = capsys.readouterr()
    [skipped] = [line for line in captured.err.splitlines() if "skipped" in line]
    assert skipped.split("robotale: ")[-1].startswith(
        f"skipped run_0003: {bad} is not a readable rosbag2 directory"
    )
    assert captured.out.strip().splitlines()[-1] == "kept 3 of 4 run(s); skipped 1: run_0003"
    # exactly what the three good runs give alone, read back by robotale's own reader
    (tmp_path / "good").mkdir()
    for run in ("run_0001", "run_0002", "run_0004"):
        (tmp_path / "good" / run).symlink_to(tmp_path / "runs" / run)
    alone = tmp_path / f"alone{suffix}"
    assert main(["prepare", str(tmp_path / "good"), "--out", str(alone)]) == 0
    written = read_log(out)
    assert sorted(written["case:concept:name"].unique()) == ["run_0001", "run_0002", "run_0004"]
    pd.testing.assert_frame_equal(written, read_log(alone))
    if suffix == ".parquet":  # nothing of the bad run was written
        assert sorted(p.name for p in out.glob("case=*")) == [
            "case=run_0001",
            "case=run_0002",
            "case=run_0004",
        ]


def test_a_corrupted_run_stops_a_dataset_on_workers_and_leaves_nothing(
    tmp_path, bag_builder, capsys
):
    bad = _four_runs_one_corrupted(tmp_path / "runs", bag_builder)
    out = tmp_path / "log.parquet"
    arguments = ["prepare", str(tmp_path / "runs"), "--out", str(out), "--executor", "local:2"]
    assert main(arguments) == 1
    error = capsys.readouterr().err.strip().splitlines()[-1]
    assert error.startswith(f"robotale: {bad} is not a readable rosbag2 directory")
    assert not out.exists()


def test_a_full_disk_is_one_sentence_and_leaves_nothing(tmp_path, bag_builder, small_disk, capsys):
    runs = tmp_path / "runs"
    for number in (1, 2):
        agri_like(bag_builder, x0=number).write(runs / f"run_{number:04d}")
    rate = ["--rate", "20"]  # inprogress events: a log larger than the disk
    assert main(["prepare", str(runs), "--out", str(tmp_path / "whole.csv"), *rate]) == 0
    size = (tmp_path / "whole.csv").stat().st_size
    disk = small_disk("8k")
    assert size > 8 * 1024  # the log does not fit
    out = disk / "log.csv"
    capsys.readouterr()
    assert main(["prepare", str(runs), "--out", str(out), *rate]) == 1
    error = capsys.readouterr().err.strip().splitlines()[-1].split("\r")[-1]
    assert error.startswith(f"robotale: The disk of {disk} is full: {out} needs more than the ")
    assert error.endswith(
        "that fitted there; nothing was written (free some space or write elsewhere)."
    )
    assert list(disk.iterdir()) == []
