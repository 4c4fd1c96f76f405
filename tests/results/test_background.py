"""``robotale ingest`` ends when the log is stored and its pages are prepared by a process of
its own (``--pages background``, the default outside the tests), or before it ends (``now``),
or on the first visit (``visit``)."""

from __future__ import annotations

import re
import time

import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.columnar import results_folder
from robotale.ekg.logs import log_exists
from robotale.results.background import done_file
from robotale.results.findings import stored_findings
from robotale.results.logdata import LogData, current_build


def ingest(thesis_csv, log_name: str, *options: str) -> int:
    return main(["ingest", str(thesis_csv), "--log", log_name, "--case-gap", "1h", *options])


def test_the_pages_are_prepared_after_the_command_by_a_process_of_their_own(
    neo4j_driver, log_name, thesis_csv, capsys, monkeypatch
):
    monkeypatch.delenv("ROBOTALE_PAGES")  # the default a user gets
    assert ingest(thesis_csv, log_name) == 0
    out = capsys.readouterr().out
    started = re.search(r"in the background \(process (\d+)\)", out)
    assert started, out
    done = done_file(neo4j_driver, log_name)
    deadline = time.monotonic() + 600
    while not done.exists():
        assert time.monotonic() < deadline, "the background preparation did not finish"
        time.sleep(0.5)
    logs = LogData()
    findings = stored_findings(neo4j_driver, logs, log_name)
    assert not logs.computed  # read from what the background process kept
    days = pd.to_datetime(pd.read_csv(thesis_csv)["time"]).dt.date.nunique()
    assert f'"runs":{days},' in findings.decode()  # five runs, counted by hand from the CSV


def test_pages_prepared_on_the_first_visit_are_not_prepared_by_the_ingest(
    neo4j_driver, log_name, thesis_csv
):
    assert ingest(thesis_csv, log_name, "--pages", "visit") == 0
    assert list(results_folder(current_build(neo4j_driver, log_name)).iterdir()) == []
    logs = LogData()
    stored_findings(neo4j_driver, logs, log_name)
    assert logs.computed[(log_name, "findings")] == 1  # the visit computed them


@pytest.mark.parametrize("where", ["flag", "environment"])
def test_an_unknown_time_to_prepare_is_refused_before_anything_is_stored(
    neo4j_driver, log_name, thesis_csv, capsys, monkeypatch, where
):
    if where == "flag":
        code = ingest(thesis_csv, log_name, "--pages", "soon")
    else:
        monkeypatch.setenv("ROBOTALE_PAGES", "soon")
        code = ingest(thesis_csv, log_name)
    assert code == 1
    err = capsys.readouterr().err
    assert "'soon' is not a time to prepare the pages: give one of background, now, visit" in err
    assert not log_exists(neo4j_driver, log_name)
