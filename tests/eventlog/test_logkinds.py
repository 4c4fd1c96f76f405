"""One decision what a path holds: each kind of log, from a real file of that kind, is told
apart by ``kind_of`` and read by ``open_log`` into the events an independent reader finds in
the same file (pandas for CSV, pm4py for XES and OCEL, pyarrow for Parquet, the tags written
into the bags for recordings); and the Tag contract's fields are the same everywhere."""

from __future__ import annotations

import dataclasses
import inspect

import pandas as pd
import pm4py
import pyarrow.parquet as pq
import pytest
from bagbuilder import BagBuilder
from object_logs import order_log
from rosbags.typesys import get_types_from_msg

from robotale.cli import build_parser
from robotale.eventlog import schema
from robotale.eventlog.logkinds import CSV, KINDS, OCEL, PARQUET, RECORDINGS, XES, kind_of
from robotale.eventlog.logsource import log_name, open_log
from robotale.eventlog.options import PrepareOptions
from robotale.eventlog.prepare import TagFields, preparation
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv, write_xes
from robotale.fame_runtime.tags import TAG_MSGDEF, TAG_TYPE, TEXT_FIELDS, Tag, tag_line

pytestmark = pytest.mark.filterwarnings("ignore::UserWarning", "ignore::FutureWarning")


def _tags(builder: BagBuilder, robot: str, activities: list[str]) -> BagBuilder:
    for i, activity in enumerate(activities):
        builder.tag(2.0 * i, robot, activity, "start")
        builder.tag(2.0 * i + 1.0, robot, activity, "complete")
    return builder


def test_each_kind_is_told_from_a_real_file_and_read_as_its_own_reader_reads_it(
    tmp_path, thesis_csv
):
    expected = pd.read_csv(thesis_csv)  # the thesis' log, as pandas reads it
    log = read_log(thesis_csv)
    parquet, xes = tmp_path / "log.parquet", tmp_path / "log.xes"
    log.to_parquet(parquet)
    write_xes(log, xes)
    jsonocel = tmp_path / "log.jsonocel"
    ocel = order_log()
    pm4py.write_ocel2_json(ocel, str(jsonocel))
    bag = _tags(BagBuilder(), "drone", ["take_off", "explore", "land"]).write(tmp_path / "bag")
    runs = tmp_path / "runs"
    for n in (1, 2):
        _tags(BagBuilder(), "tractor", ["drive"] * n).write(runs / f"run_000{n}")

    found = {path.name: kind_of(path) for path in (thesis_csv, parquet, xes, jsonocel, bag, runs)}
    assert found == {
        thesis_csv.name: CSV,
        "log.parquet": PARQUET,
        "log.xes": XES,
        "log.jsonocel": OCEL,
        "bag": RECORDINGS,
        "runs": RECORDINGS,
    }
    assert set(found.values()) == set(KINDS)  # every registered kind met by a real file

    csv = open_log(thesis_csv)
    assert len(csv.events) == len(expected)
    assert csv.events[schema.ACTIVITY].tolist() == expected["activity"].tolist()
    assert len(open_log(parquet).events) == pq.read_metadata(parquet).num_rows == len(expected)
    from_xes = open_log(xes).events
    assert len(from_xes) == len(pm4py.read_xes(str(xes))) == len(expected)
    assert sorted(from_xes[schema.ACTIVITY]) == sorted(expected["activity"])
    opened_ocel = open_log(jsonocel)
    assert opened_ocel.objects is not None
    assert len(opened_ocel.events) == len(pm4py.read_ocel2_json(str(jsonocel)).events)

    one = open_log(bag, preparation=PrepareOptions(perspectives=""))
    assert one.reading is None and one.kind is RECORDINGS
    assert one.events[schema.ACTIVITY].tolist() == ["take_off"] * 2 + ["explore"] * 2 + ["land"] * 2
    both = open_log(runs, preparation=PrepareOptions(perspectives=""))
    assert both.events.groupby(schema.CASE).size().to_dict() == {"run_0001": 2, "run_0002": 4}


def test_a_dataset_folder_is_named_like_its_file_and_a_folder_by_its_name(tmp_path, thesis_csv):
    dataset = tmp_path / "agri.parquet"
    dataset.mkdir()
    assert kind_of(dataset) is PARQUET and log_name(dataset) == "agri"
    assert log_name(tmp_path / "runs.d") == "runs"  # a file's stem
    folder = tmp_path / "runs.d"
    folder.mkdir()
    assert kind_of(folder) is RECORDINGS and log_name(folder) == "runs.d"


def test_recordings_refuse_the_options_of_a_file_in_one_sentence(tmp_path):
    bag = _tags(BagBuilder(), "drone", ["explore"]).write(tmp_path / "bag")
    with pytest.raises(Exception, match="holds recordings: --map and --case apply"):
        open_log(bag, case="run")


def test_the_tag_contract_is_one_list_of_fields():
    names = [f.name for f in dataclasses.fields(Tag)]
    assert tuple(names[1:]) == TEXT_FIELDS and names[0] == "stamp"
    # the message definition, as rosbags reads it: the stamp, then every text field
    _, fields = get_types_from_msg(TAG_MSGDEF, TAG_TYPE)[TAG_TYPE]
    assert [name for name, _ in fields] == names
    # the printed line: one tab-separated cell per field, in that order
    tag = Tag(12.5, *(f"<{name}>" for name in TEXT_FIELDS))
    assert tag_line(tag, begin=10.0).split("\t") == ["     2.500", *(f"<{n}>" for n in TEXT_FIELDS)]
    # a bag's tag message is read by the same fields
    assert {f.name for f in dataclasses.fields(TagFields)} == set(TEXT_FIELDS)


def test_the_preparation_options_are_the_clis_and_prepares_spelling():
    fields = {f.name for f in dataclasses.fields(PrepareOptions)}
    assert fields == set(inspect.signature(preparation).parameters)
    assert set(PrepareOptions().keywords()) <= fields
    for command in ("prepare", "ingest", "annotate"):
        parser = build_parser()
        args = parser.parse_args([command, "x", *(["--out", "y"] if command == "annotate" else [])])
        dests = {k for k in vars(args) if not k.startswith("_")}
        assert fields <= dests, (command, fields - dests)


def test_the_kinds_written_by_robotale_are_told_apart_from_its_csv(tmp_path, thesis_csv):
    log = read_log(thesis_csv)
    copy = tmp_path / "copy.csv"
    write_csv(log, copy)
    assert kind_of(copy) is CSV
    assert len(open_log(copy).events) == len(log)
