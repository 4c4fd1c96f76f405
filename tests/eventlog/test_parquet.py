"""Event logs as Parquet: ``prepare --out NAME.parquet`` writes a dataset partitioned by run,
and every command that reads a log reads Parquet files and datasets as it reads CSV.

The reference is always the CSV of the same runs, read back by the CSV reader; pyarrow and
pandas read the dataset on their own to show it is one table to other tools too."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pyarrow.dataset as pads
import pytest
from bagbuilder import agri_like

from robotale.cli import main
from robotale.errors import InputError
from robotale.eventlog import dataset, schema
from robotale.eventlog.prepare import prepare
from robotale.eventlog.readers import read_log, read_log_with_reading
from robotale.storage import place

pytestmark = pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning")


@pytest.fixture
def runs(tmp_path, bag_builder) -> Path:
    """Three runs of a drone and a tractor, each starting elsewhere; in the second the drone
    sends one message more, so the runs have different numbers of events."""
    folder = tmp_path / "runs"
    agri_like(bag_builder).write(folder / "run_0001", manifest={"robots": {"drone": "Drone"}})
    second = agri_like(bag_builder, x0=5)
    second.tag(8.0, "drone", "status!", "start", "m2", "send", "{}")
    second.tag(8.0, "drone", "status!", "complete", "m2", "send", "{}")
    second.write(folder / "run_0002")
    agri_like(bag_builder, x0=9).write(folder / "run_0003")
    return folder


def prepared(runs: Path, out: Path, *extra: str) -> None:
    assert main(["prepare", str(runs), "--out", str(out), *extra]) == 0


@pytest.mark.parametrize("executor", [None, "local:2"])
def test_the_dataset_reads_back_as_the_csv_of_the_same_runs(tmp_path, runs, executor, capsys):
    csv, parquet = tmp_path / "agri.csv", tmp_path / "agri.parquet"
    prepared(runs, csv)
    prepared(runs, parquet, *(["--executor", executor] if executor else []))
    rows = len(pd.read_csv(csv))
    assert capsys.readouterr().out.splitlines()[-1] == (
        f"{rows} events from 3 run(s) written to {parquet}"
    )
    pd.testing.assert_frame_equal(read_log(csv), read_log(parquet))
    expected = pd.read_csv(csv)["case"].value_counts().sort_index()
    table = pads.dataset(parquet, format="parquet", partitioning="hive").to_table().to_pandas()
    per_run = table["case"].astype(str).value_counts().sort_index()
    assert per_run.to_dict() == expected.to_dict()
    assert per_run["run_0002"] == per_run["run_0001"] + 2
    assert len(pd.read_parquet(parquet)) == rows
    manifest = json.loads((parquet / dataset.MANIFEST).read_text())
    assert [p["rows"] for p in manifest["parts"]] == expected.tolist()
    assert not (parquet / dataset.WRITING).exists()


def test_the_parts_keep_the_canonical_column_types(tmp_path, runs):
    parquet = tmp_path / "agri.parquet"
    prepared(runs, parquet)
    log = prepare(runs)
    part = pads.dataset(parquet / "case=run_0001", format="parquet").to_table()
    types = {field.name: str(field.type) for field in part.schema}
    assert types["time"] == "timestamp[ns, tz=UTC]"
    for column in ("activity", "robot", "msg_id", "event_id"):
        assert types[column] == "string"
    for column in ("x", "y", "z", "battery", "source_index"):
        assert types[column] == "double"
    assert "case" not in types  # the folder names the case
    first = log[log[schema.CASE] == "run_0001"].reset_index(drop=True)
    assert part.column("time").to_pandas().tolist() == first[schema.TIMESTAMP].tolist()
    assert part.column("battery").to_pylist() == pytest.approx(first[schema.BATTERY].tolist())


def test_a_dataset_is_an_event_log_for_inspect_and_discover(tmp_path, runs, capsys):
    csv, parquet = tmp_path / "agri.csv", tmp_path / "agri.parquet"
    prepared(runs, csv)
    prepared(runs, parquet)
    capsys.readouterr()
    answers = {}
    for log in (csv, parquet):
        assert main(["discover", "dfg", str(log)]) == 0
        answers[log.suffix] = json.loads(capsys.readouterr().out)
    assert answers[".parquet"]["edges"] == answers[".csv"]["edges"]
    _, by_csv = read_log_with_reading(csv)
    _, by_parquet = read_log_with_reading(parquet)
    assert by_parquet.case == "the column 'case'" == by_csv.case
    assert by_parquet.events == by_csv.events and by_parquet.robots == by_csv.robots
    assert main(["inspect", str(parquet)]) == 0
    assert "3 case" in capsys.readouterr().out


def test_a_parquet_file_of_the_thesis_log_discovers_the_csvs_graph(tmp_path, thesis_csv, capsys):
    copy = tmp_path / "thesis.parquet"
    pd.read_csv(thesis_csv).to_parquet(copy)
    graphs = []
    for log in (thesis_csv, copy):
        assert main(["discover", "dfg", str(log), "--robot", "drone"]) == 0
        graphs.append(json.loads(capsys.readouterr().out))
    assert graphs[0]["edges"] == graphs[1]["edges"] and graphs[0]["edges"]
    pd.testing.assert_frame_equal(read_log(thesis_csv), read_log(copy))


def test_a_dataset_whose_writing_stopped_is_one_sentence(tmp_path, runs):
    # what a preparation killed after its first run leaves: the marker, one part, no manifest
    parquet = tmp_path / "agri.parquet"
    target = place(parquet)
    dataset.begin(target, str(runs))
    log = prepare(runs / "run_0001")
    dataset.write_part(log, target)
    with pytest.raises(InputError, match=r"agri\.parquet is a Parquet dataset whose writing did"):
        read_log(parquet)
    assert pads.dataset(parquet, format="parquet", partitioning="hive").count_rows() == len(log)


def test_a_damaged_dataset_is_one_sentence_naming_the_file(tmp_path, runs, capsys):
    parquet = tmp_path / "agri.parquet"
    prepared(runs, parquet)
    part = parquet / "case=run_0002" / dataset.PART
    data = part.read_bytes()
    part.write_bytes(data[: len(data) // 2])
    capsys.readouterr()
    assert main(["inspect", str(parquet)]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"robotale: {part} is not a readable Parquet file (")
    assert len(err.splitlines()) == 1
    part.unlink()
    with pytest.raises(InputError, match=r"run_0002/part-0\.parquet is missing, though the"):
        read_log(parquet)
    (parquet / dataset.MANIFEST).write_text("{")
    with pytest.raises(InputError, match=r"_robotale_dataset\.json is damaged"):
        read_log(parquet)


def test_a_part_with_rows_the_manifest_does_not_record_is_refused(tmp_path, runs):
    parquet = tmp_path / "agri.parquet"
    prepared(runs, parquet)
    manifest = json.loads((parquet / dataset.MANIFEST).read_text())
    manifest["parts"][0]["rows"] += 1
    (parquet / dataset.MANIFEST).write_text(json.dumps(manifest))
    with pytest.raises(InputError, match=r"run_0001/part-0\.parquet holds \d+ rows where the"):
        read_log(parquet)


def test_a_failed_preparation_leaves_no_dataset(tmp_path, runs, bag_builder, capsys):
    bag_builder().odom(0, "drone", 0, 0, 0).tag(1, "drone", "land", "finished").write(
        runs / "run_0004"
    )
    parquet = tmp_path / "agri.parquet"
    assert main(["prepare", str(runs), "--out", str(parquet), "--executor", "local:2"]) == 1
    assert "lifecycle 'finished'" in capsys.readouterr().err
    assert not parquet.exists()


def test_a_dataset_replaces_an_earlier_one_but_no_other_folder(tmp_path, runs, capsys):
    parquet = tmp_path / "agri.parquet"
    prepared(runs / "run_0001", parquet)
    prepared(runs, parquet)
    assert sorted(p.name for p in parquet.glob("case=*")) == [
        "case=run_0001",
        "case=run_0002",
        "case=run_0003",
    ]
    other = tmp_path / "photos.parquet"
    other.mkdir()
    (other / "cat.jpg").write_bytes(b"\xff\xd8")
    assert main(["prepare", str(runs), "--out", str(other)]) == 1
    assert "holds other files, not a robotale Parquet dataset" in capsys.readouterr().err
    assert [p.name for p in other.iterdir()] == ["cat.jpg"]


def test_ingest_stores_a_dataset_as_it_stores_the_csv(tmp_path, runs, neo4j_driver, log_name):
    from robotale.ekg.logs import delete_log, log_summary

    csv, parquet = tmp_path / "agri.csv", tmp_path / "agri.parquet"
    prepared(runs, csv)
    prepared(runs, parquet)
    counts = {}
    for log in (csv, parquet):
        name = f"{log_name}_{log.suffix[1:]}"
        args = ["ingest", str(log), "--log", name, "--entities", "robot,msg_id"]
        try:
            assert main(args) == 0
            counts[log.suffix] = log_summary(neo4j_driver, name)["counts"]
        finally:
            delete_log(neo4j_driver, name)
    assert counts[".parquet"] == counts[".csv"]
    assert counts[".csv"]["events"] == len(pd.read_csv(csv))
