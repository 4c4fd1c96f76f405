import json

from robotale.cli import main


def test_perspectives_of_a_file(thesis_csv, tmp_path, capsys):
    page, data = tmp_path / "report.html", tmp_path / "report.json"
    code = main([
        "perspectives", str(thesis_csv), "--out", str(page), "--json", str(data),
        "--field", "0,10,0,10",
    ])  # fmt: skip
    assert code == 0
    report = json.loads(data.read_text())
    assert report["communication"]["summary"]["lost"] == 17
    assert "<h2>Bottlenecks</h2>" in page.read_text()
    printed = capsys.readouterr().out
    assert "421 messages, 404 received, 17 lost" in printed
    assert "battery: 7 low-battery events" in printed


def test_perspectives_of_a_stored_log_drilled_down(
    thesis_csv, thesis_log, neo4j_driver, log_name, tmp_path, capsys
):
    from robotale.ekg import build_ekg

    build_ekg(neo4j_driver, thesis_log, log_name, entities=["robot"], progress=False)
    data = tmp_path / "explore.json"
    code = main([
        "perspectives", "--log", log_name, "--json", str(data),
        "--activity", "explore", "--robot", "drone",
    ])  # fmt: skip
    assert code == 0
    report = json.loads(data.read_text())
    explore = (thesis_log["concept:name"] == "explore") & (thesis_log["robot"] == "drone")
    assert report["spatial"]["summary"]["positions"] == explore.sum()
    assert report["communication"]["message"].startswith("no message involves")
    assert [row["activity"] for row in report["performance"]["tables"]["activities"]] == ["explore"]


def test_perspectives_need_somewhere_to_write(thesis_csv, capsys):
    assert main(["perspectives", str(thesis_csv)]) == 1
    assert "--out report.html" in capsys.readouterr().err


def test_messages_delayed_above_a_given_latency(tmp_path, capsys):
    import mission_findings as mission
    import pandas as pd

    log = mission.write_injected("robot_id.csv", tmp_path / "mission.csv")
    data = tmp_path / "report.json"
    assert main(["perspectives", str(log), "--json", str(data), "--delay", "2"]) == 0
    communication = json.loads(data.read_text())["communication"]
    truth = pd.DataFrame([vars(m) for m in mission.injected_truth().messages])
    latency = (truth["received"] - truth["sent"]).dt.total_seconds()
    assert communication["summary"]["delayed"] == (latency > 2).sum() == 13
    channels = pd.DataFrame(communication["tables"]["channels"]).set_index("receiver")
    late = truth[latency > 2].groupby("receiver").size()
    assert channels["delayed"].to_dict() == late.to_dict()
    assert "13 delayed" in capsys.readouterr().out
    assert main(["perspectives", str(log), "--json", str(data), "--delay", "-1"]) == 1
    assert "--delay -1 is not usable" in capsys.readouterr().err
