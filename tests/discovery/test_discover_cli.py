"""The discover command line, on files (the EKG command is tested with Neo4j in test_ekg)."""

import json
import re

from robotale.cli import main


def test_dfg_of_the_drone_to_json_and_svg(thesis_csv, tmp_path, capsys):
    out, svg = tmp_path / "drone_dfg.json", tmp_path / "drone_dfg.svg"
    code = main([
        "discover", "dfg", str(thesis_csv), "--robot", "drone", "--case", "1",
        "--out", str(out), "--svg", str(svg), "--labels", "performance",
    ])  # fmt: skip
    assert code == 0
    graph = json.loads(out.read_text())
    assert graph["info"]["filter"] == {"cases": ["1"], "robots": ["drone"]}
    assert {n["id"] for n in graph["nodes"]} >= {"takeoff", "explore", "land"}
    assert "10.0s (110)" in re.findall(r"<text[^>]*>(.*?)</text>", svg.read_text())
    assert "DFG:" in capsys.readouterr().out


def test_dfg_without_out_prints_json(thesis_csv, capsys):
    assert main(["discover", "dfg", str(thesis_csv), "--activity", "takeoff,land"]) == 0
    graph = json.loads(capsys.readouterr().out)
    edges = {(e["source"], e["target"]): e["count"] for e in graph["edges"]}
    assert edges[("land", "takeoff")] == 4  # five runs in one case


def test_a_filter_that_matches_nothing_fails_cleanly(thesis_csv, tmp_path, capsys):
    out = tmp_path / "x.json"
    assert main(["discover", "dfg", str(thesis_csv), "--robot", "rover", "--out", str(out)]) == 1
    assert "no event has robot rover" in capsys.readouterr().err
    assert not out.exists()


def test_missing_graphviz_is_reported_before_any_output(thesis_csv, tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))
    out = tmp_path / "x.json"
    code = main(
        ["discover", "dfg", str(thesis_csv), "--out", str(out), "--svg", str(tmp_path / "x.svg")]
    )
    assert code == 1 and "Graphviz" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_conformance_command(engine_log, tmp_path, capsys):
    from pathlib import Path

    from robotale.eventlog.schema import to_csv_names

    model = Path(__file__).parent / "models" / "scout_workers.bpmn"
    log = engine_log(model, robots=["scout", "worker_1"], variables={"scout": {"planned": 2}})
    csv = tmp_path / "run.csv"
    to_csv_names(log).to_csv(csv, index=False)
    report = tmp_path / "conformance.json"
    assert (
        main(["discover", "conformance", str(csv), "--model", str(model), "--json", str(report)])
        == 0
    )
    printed = capsys.readouterr().out
    assert "No deviations" in printed and "worker_1" in printed
    assert json.loads(report.read_text())["summary"]["fitness"] == 1.0

    broken = to_csv_names(log[log["concept:name"] != "survey"])
    broken.to_csv(csv, index=False)
    assert main(["discover", "conformance", str(csv), "--model", str(model)]) == 0
    printed = capsys.readouterr().out
    assert "missing" in printed and "survey" in printed

    strangers = to_csv_names(log.assign(robot=log["robot"].replace({"scout": "drone"})))
    strangers.to_csv(csv, index=False)
    assert main(["discover", "conformance", str(csv), "--model", str(model)]) == 1
    assert "matches no pool" in capsys.readouterr().err
