import json

import pytest

from robotale.enhancement import Field, all_perspectives, write_report
from robotale.errors import InputError


@pytest.fixture(scope="module")
def thesis_perspectives(thesis_log):
    return all_perspectives(thesis_log, field=Field(0, 10, 0, 10))


def test_html_and_json_report(thesis_perspectives, tmp_path):
    page, data = tmp_path / "report.html", tmp_path / "report.json"
    write_report(thesis_perspectives, html_path=page, json_path=data)

    text = page.read_text(encoding="utf-8")
    for heading in ("Spatial", "Communication", "Battery", "Performance", "Bottlenecks"):
        assert f"<h2>{heading}</h2>" in text
    assert text.count("plotly.js v") == 1  # the library inlined once, so the page works offline
    assert "weed_position!" in text
    report = json.loads(data.read_text(encoding="utf-8"))
    assert set(report) == {"spatial", "communication", "battery", "performance", "bottlenecks"}
    assert report["spatial"]["summary"]["field"]["cells"] == 100
    comm = {row["message_type"]: row for row in report["communication"]["tables"]["message_types"]}
    assert comm["weed_position!"]["lost"] == thesis_perspectives["communication"].summary["lost"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report.html", "report.json"]


def test_a_log_without_perspective_data_still_reports(events, tmp_path):
    log = events({"case": "1", "robot": "r", "activity": "a", "lifecycle": "start", "t": 0})
    perspectives = all_perspectives(log)
    assert [n for n, p in perspectives.items() if not p.has_data] == [
        "spatial",
        "communication",
        "battery",
        "performance",
        "bottlenecks",
    ]
    write_report(perspectives, html_path=tmp_path / "r.html")
    assert "no positions" in (tmp_path / "r.html").read_text(encoding="utf-8")


def test_a_failed_write_leaves_nothing(thesis_perspectives, tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        write_report(
            thesis_perspectives,
            html_path=tmp_path / "report.html",
            json_path=tmp_path / "missing" / "report.json",
        )
    assert list(tmp_path.iterdir()) == []


def test_drill_down_for_one_class(thesis_log):
    perspectives = all_perspectives(thesis_log, activity="weed_position!", robot="drone")
    assert perspectives["communication"].summary["messages"] == (
        thesis_log.loc[thesis_log["concept:name"] == "weed_position!", "msg_id"].nunique()
    )
    assert set(perspectives["spatial"].table["activity"]) == {"weed_position!"}
    assert set(perspectives["bottlenecks"].table["activity"]) == {"weed_position!"}
