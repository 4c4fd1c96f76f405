"""``robotale report`` on a file and on a stored log: the printed sentences, the HTML page
and the JSON file say the same, counted independently here."""

from __future__ import annotations

import json

import mission_findings as mission
import pandas as pd

from robotale.cli import main
from robotale.eventlog.readers import read_log


def test_report_of_a_file(tmp_path, capsys):
    log = mission.write_injected("robotale.csv", tmp_path / "mission.csv")
    page, data = tmp_path / "report.html", tmp_path / "report.json"
    assert main(["report", str(log), "--out", str(page), "--json", str(data)]) == 0
    printed = capsys.readouterr().out
    report = json.loads(data.read_text())
    events = pd.read_csv(log)
    sends = events[events["activity"].str.endswith("!") & events["lifecycle"].eq("start")]
    messages = report["answers"][4]
    assert messages["facts"]["messages"] == sends["msg_id"].nunique()
    for answer in report["answers"]:
        assert answer["question"] in printed
        for sentence in answer["sentences"]:
            assert sentence in printed
    assert report["answers"][1]["facts"]["bottlenecks"][0]["activity"] == mission.REFILL
    html = page.read_text()
    assert f"Cases with {mission.REFILL} by tractor_1" in html
    assert html.count("<script") >= 1 and "lost message" in html


def test_report_of_a_stored_log(thesis_csv, neo4j_driver, log_name, tmp_path, capsys):
    from robotale.ekg import build_ekg

    log = read_log(thesis_csv, case_gap="1h")
    build_ekg(neo4j_driver, log, log_name, entities=["robot"], progress=False)
    data = tmp_path / "report.json"
    assert main(["report", "--log", log_name, "--json", str(data)]) == 0
    report = json.loads(data.read_text())
    assert report["answers"][0]["facts"]["runs"] == log["time:timestamp"].dt.date.nunique()
    sends = log[log["concept:name"].astype(str).str.endswith("!")]
    assert report["answers"][4]["facts"]["messages"] == sends["msg_id"].nunique()
    assert "421 messages sent" in capsys.readouterr().out


def test_report_of_a_bad_file_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("time,activity\nyesterday,takeoff\n")
    page = tmp_path / "report.html"
    assert main(["report", str(bad), "--out", str(page)]) == 1
    error = capsys.readouterr().err.strip().splitlines()
    assert len(error) == 1 and "bad.csv" in error[0]
    assert not page.exists()
