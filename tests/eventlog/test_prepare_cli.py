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
