"""``benchmarks/stored_log.py`` checks every stored run's output against the CSV's: the check
on a small log's perspectives, once the same and once where the log lost a message."""

from __future__ import annotations

from benchmark_scripts import benchmark

from robotale.cli import main
from robotale.eventlog import schema
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv


def stored_log():
    return benchmark("stored_log")


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
