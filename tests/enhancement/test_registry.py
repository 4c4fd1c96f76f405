"""Every registered perspective is what the command line offers and prints, and what the
report holds: ``robotale perspectives --only NAME`` accepts each registered name (and only
those), and its JSON equals the perspective's own function called on the same log."""

from __future__ import annotations

import json

import pytest

from robotale.cli import build_parser, main
from robotale.enhancement import (
    all_perspectives,
    battery_perspective,
    communication_perspective,
    find_bottlenecks,
    performance_perspective,
    spatial_perspective,
)
from robotale.enhancement.registry import PERSPECTIVES, names, perspective_kind
from robotale.eventlog.readers import read_log

#: the functions of the perspectives, as the package exports them
FUNCTIONS = {
    "spatial": spatial_perspective,
    "communication": communication_perspective,
    "battery": battery_perspective,
    "performance": performance_perspective,
    "bottlenecks": find_bottlenecks,
}


def test_the_cli_offers_exactly_the_registered_perspectives(thesis_csv):
    parser = build_parser()
    for name in names():
        args = parser.parse_args(["perspectives", str(thesis_csv), "--only", name])
        assert args.only == [name]
    with pytest.raises(SystemExit):
        parser.parse_args(["perspectives", str(thesis_csv), "--only", "smell"])
    assert {kind.name: kind.compute for kind in PERSPECTIVES} == FUNCTIONS


def test_the_report_holds_each_registered_perspective_as_its_function_computes_it(thesis_csv):
    log = read_log(thesis_csv)
    report = all_perspectives(log)
    assert list(report) == list(names())
    for name, function in FUNCTIONS.items():
        assert report[name].to_dict() == function(log).to_dict(), name


def test_perspectives_only_writes_and_prints_the_named_ones(tmp_path, thesis_csv, capsys):
    out = tmp_path / "report.json"
    code = main(
        [
            "perspectives",
            str(thesis_csv),
            "--json",
            str(out),
            "--only",
            "battery",
            "--only",
            "spatial",
        ]
    )
    assert code == 0
    written = json.loads(out.read_text())
    assert list(written) == ["spatial", "battery"]  # the registry's order, not the flags'
    log = read_log(thesis_csv)
    lines = capsys.readouterr().out.splitlines()
    battery = battery_perspective(log)
    assert f"      battery: {perspective_kind('battery').headline(battery.summary)}" in lines
    assert (
        written["battery"]["summary"]["low_battery_events"]
        == (battery.summary["low_battery_events"])
    )
    assert len(lines) == 2
