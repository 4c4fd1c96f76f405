"""One stored log read through robotale.ekg.logs, checked against the CSV it came from."""

from __future__ import annotations

import pandas as pd
import pytest

from robotale.ekg import build_ekg
from robotale.ekg.logs import (
    delete_log,
    end_look,
    log_build_row,
    log_info,
    log_robots,
    log_summary,
    log_values,
    require_log,
    start_look,
    stored_events,
)
from robotale.errors import InputError, LogNotFound
from robotale.eventlog import schema
from robotale.eventlog.readers import read_csv


@pytest.fixture
def stored(neo4j_driver, log_name, thesis_csv) -> tuple[str, pd.DataFrame]:
    """The thesis' log under a fresh name, with its rows as the CSV holds them."""
    log = read_csv(thesis_csv)
    build_ekg(neo4j_driver, log, log_name, entities=["robot"], source="thesis", progress=False)
    return log_name, log


def test_a_logs_description_and_values_are_those_of_its_file(neo4j_driver, stored):
    name, log = stored
    raw = log.rename(columns=schema.CSV_NAMES)
    info = log_info(neo4j_driver, name)
    assert (info["name"], info["status"], info["events"]) == (name, "complete", len(raw))
    assert info["source"] == "thesis"
    assert info["entityTypes"] == ["robot"] and info["classTypes"] == ["activity"]
    assert {"activity", "robot", "case"} <= set(info["properties"]) and info["created"]
    values = log_values(neo4j_driver, name)
    assert values["events"] == len(raw)
    assert sorted(values["robot"]) == sorted(raw["robot"].unique())
    assert sorted(values["activity"]) == sorted(raw["activity"].unique())
    assert sorted(values["case"]) == sorted(raw["case"].unique())
    assert sorted(log_robots(neo4j_driver, name)) == sorted(raw["robot"].unique())
    assert stored_events(neo4j_driver, name) == len(raw)
    assert log_summary(neo4j_driver, name)["counts"]["events"] == len(raw)
    require_log(neo4j_driver, name)  # there: nothing raised


def test_within_a_look_the_log_node_is_read_once(neo4j_driver, stored):
    name, _ = stored
    outside = log_info(neo4j_driver, name), log_build_row(neo4j_driver, name)
    look = start_look()
    try:
        seen = log_info(neo4j_driver, name), log_build_row(neo4j_driver, name)
        delete_log(neo4j_driver, name)
        # the same answers as outside a look, and read once: the deletion is not seen
        assert seen == outside
        assert (log_info(neo4j_driver, name), log_build_row(neo4j_driver, name)) == outside
    finally:
        end_look(look)
    with pytest.raises(LogNotFound):
        log_info(neo4j_driver, name)
    with pytest.raises(LogNotFound):
        log_build_row(neo4j_driver, name)


def test_a_missing_log_is_one_sentence_with_the_callers_hint(neo4j_driver, log_name):
    for read in (log_info, log_summary, require_log):
        with pytest.raises(LogNotFound) as raised:
            read(neo4j_driver, log_name)
        assert str(raised.value) == (
            f"There is no log named {log_name!r} in Neo4j (see `robotale logs list`)."
        )
        assert isinstance(raised.value, InputError) and raised.value.name == log_name
    with pytest.raises(LogNotFound, match=r"in Neo4j \(upload it on the Logs page\)\.$"):
        log_info(neo4j_driver, log_name, "upload it on the Logs page")
    assert stored_events(neo4j_driver, log_name) == 0 and log_robots(neo4j_driver, log_name) == []
