"""``benchmarks/stored_log.py`` checks every stored run's output against the CSV's: the check
on a small log's perspectives, once the same and once where the log lost a message."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

from robotale.cli import main
from robotale.eventlog import schema
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


def stored_log():
    if str(BENCHMARKS) not in sys.path:  # the benchmark imports its sibling scripts by name
        sys.path.insert(0, str(BENCHMARKS))
    spec = importlib.util.spec_from_file_location("stored_log", BENCHMARKS / "stored_log.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_stored_logs_outputs_are_checked_against_the_csvs(tmp_path, capsys, thesis_csv):
    differences = stored_log().differences
    same, again, fewer = (tmp_path / f"{n}.json" for n in ("same", "again", "fewer"))
    assert main(["perspectives", str(thesis_csv), "--json", str(same)]) == 0
    assert main(["perspectives", str(thesis_csv), "--json", str(again)]) == 0
    assert differences(same, again) == []
    # the log without the events of its first message: its communication is other work
    log = read_log(thesis_csv)
    first = log[schema.MSG_ID].dropna().iloc[0]
    smaller = tmp_path / "smaller.csv"
    write_csv(log[log[schema.MSG_ID].ne(first).fillna(True)], smaller)
    assert main(["perspectives", str(smaller), "--json", str(fewer)]) == 0
    assert "communication differs" in differences(same, fewer)
    capsys.readouterr()
