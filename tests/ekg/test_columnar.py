"""The columnar copy of stored logs (robotale.ekg.columnar) against a real Neo4j: the copy and
the events read back from the graph are the reader's own DataFrame, dtypes included, and a
copy of another build, a missing one or a damaged one is never used."""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq
import pytest
from conventions import ground_truth, write_inprogress_xes, write_robot_id_csv, write_robotale_csv

from robotale.cli import main
from robotale.discovery.dfg import discover_dfg
from robotale.discovery.ekg import read_stored_log
from robotale.ekg import build_ekg
from robotale.ekg.columnar import (
    EVENTS,
    build_folder,
    log_build,
    log_folder,
    store_copy,
    stored_table,
)
from robotale.enhancement.report import all_perspectives
from robotale.eventlog.readers import read_log

ENTITIES = ["robot"]


@pytest.fixture(scope="module")
def convention_files(tmp_path_factory, thesis_csv) -> dict[str, Path]:
    """One execution written in three tools' conventions, and the thesis' own recording."""
    folder = tmp_path_factory.mktemp("conventions")
    truth = ground_truth()
    return {
        "robotale_csv": write_robotale_csv(truth, folder / "robotale.csv"),
        "inprogress_xes": write_inprogress_xes(truth, folder / "inprogress.xes"),
        "robot_id_csv": write_robot_id_csv(truth, folder / "robot_id.csv"),
        "thesis": thesis_csv,
    }


def ingest(driver, log: pd.DataFrame, name: str, replace: bool = False) -> Path | None:
    """Store ``log`` as ``robotale ingest`` does: the graph, then the copy."""
    build_ekg(driver, log, name, entities=ENTITIES, replace=replace, progress=False)
    return store_copy(driver, name, log)


def copy_path(driver, name: str) -> Path:
    return build_folder(log_build(driver, name)) / EVENTS


@pytest.mark.parametrize("convention", ["robotale_csv", "inprogress_xes", "robot_id_csv", "thesis"])
def test_the_copy_and_the_graph_give_back_the_readers_dataframe(
    neo4j_driver, log_name, convention_files, convention
):
    original = read_log(convention_files[convention])
    path = ingest(neo4j_driver, original, log_name)
    assert path is not None and path.is_file()
    pd.testing.assert_frame_equal(stored_table(neo4j_driver, log_name), original)
    path.unlink()  # as on another machine: only the graph is there
    rebuilt = stored_table(neo4j_driver, log_name)
    pd.testing.assert_frame_equal(rebuilt, original)
    assert path.is_file(), "the copy read back from the graph was not kept"
    pd.testing.assert_frame_equal(pq.read_table(path).to_pandas(), original)


def test_a_stored_logs_analysis_is_that_of_its_file(neo4j_driver, log_name, thesis_csv):
    original = read_log(thesis_csv)
    ingest(neo4j_driver, original, log_name)
    stored = read_stored_log(log_name, driver=neo4j_driver)
    from_file = {k: v.to_dict() for k, v in all_perspectives(original).items()}
    from_graph = {k: v.to_dict() for k, v in all_perspectives(stored).items()}
    assert from_graph == from_file
    assert discover_dfg(stored).to_dict() == discover_dfg(original).to_dict()


def test_a_copy_of_an_earlier_build_is_not_used(
    neo4j_driver, log_name, thesis_csv, tmp_path, monkeypatch
):
    first = read_log(thesis_csv)
    old_path = ingest(neo4j_driver, first, log_name)
    # rebuilt on another machine: its copy is kept in that machine's robotale home
    second = first[first["robot"] == "drone"].reset_index(drop=True)
    with monkeypatch.context() as elsewhere:
        elsewhere.setenv("ROBOTALE_HOME", str(tmp_path / "other-machine"))
        build_ekg(neo4j_driver, second, log_name, entities=ENTITIES, replace=True, progress=False)
    assert old_path.is_file()
    back = stored_table(neo4j_driver, log_name)
    assert len(back) == len(second) < len(first)
    pd.testing.assert_frame_equal(back, second, check_dtype=False)
    assert not old_path.exists(), "the earlier build's copy was left behind"
    assert [p.name for p in log_folder(log_name).iterdir()] == [
        copy_path(neo4j_driver, log_name).parent.name
    ]


def test_a_rebuild_under_the_same_name_replaces_the_copy(neo4j_driver, log_name, thesis_csv):
    first = read_log(thesis_csv)
    old_path = ingest(neo4j_driver, first, log_name)
    second = first.head(100)
    new_path = ingest(neo4j_driver, second, log_name, replace=True)
    assert new_path != old_path and not old_path.exists()
    pd.testing.assert_frame_equal(stored_table(neo4j_driver, log_name), second)
    # the rebuild ran under a temporary name: no copy of it is left under any other name
    assert list(log_folder(log_name).iterdir()) == [new_path.parent]


def test_a_damaged_copy_is_read_again_from_the_graph(neo4j_driver, log_name, thesis_csv, caplog):
    original = read_log(thesis_csv)
    path = ingest(neo4j_driver, original, log_name)
    path.write_bytes(b"PAR1 this is not a Parquet file")
    pd.testing.assert_frame_equal(stored_table(neo4j_driver, log_name), original)
    assert "damaged" in caplog.text
    pd.testing.assert_frame_equal(pq.read_table(path).to_pandas(), original)


def test_a_log_stored_without_column_types_reads_with_inferred_ones(
    neo4j_driver, log_name, thesis_csv
):
    original = read_log(thesis_csv)
    build_ekg(neo4j_driver, original, log_name, entities=ENTITIES, progress=False)
    back = stored_table(neo4j_driver, log_name)
    assert back["concept:name"].dtype == "string" and back["x"].dtype == "float64"
    assert str(back["time:timestamp"].dt.tz) == str(original["time:timestamp"].dt.tz)
    pd.testing.assert_frame_equal(back[original.columns], original, check_dtype=False)


def test_logs_delete_removes_the_copy(neo4j_server, neo4j_driver, log_name, thesis_csv, capsys):
    ingest(neo4j_driver, read_log(thesis_csv), log_name)
    assert log_folder(log_name).is_dir()
    assert main(["logs", "delete", log_name]) == 0
    assert not log_folder(log_name).exists()


def test_the_ingest_command_keeps_a_copy(neo4j_server, neo4j_driver, log_name, thesis_csv):
    assert main(["ingest", str(thesis_csv), "--log", log_name, "--entities", "robot"]) == 0
    path = copy_path(neo4j_driver, log_name)
    pd.testing.assert_frame_equal(pq.read_table(path).to_pandas(), read_log(thesis_csv))


def test_discover_dfg_of_a_stored_log_writes_what_its_file_gives(
    neo4j_server, neo4j_driver, log_name, thesis_csv, tmp_path
):
    ingest(neo4j_driver, read_log(thesis_csv), log_name)
    from_file, from_store = tmp_path / "file.json", tmp_path / "stored.json"
    assert main(["discover", "dfg", str(thesis_csv), "--out", str(from_file)]) == 0
    assert main(["discover", "dfg", "--log", log_name, "--out", str(from_store)]) == 0
    assert from_store.read_text() == from_file.read_text()
