"""Time at the resolution of the recording: nanoseconds from the bag to the files and Neo4j.

The bags are written with rosbags' writer; what they hold is read back with rosbags alone
(never robotale's reader), and the expected order and durations are counted from that.
"""

from __future__ import annotations

import itertools
import warnings

import pandas as pd
import pytest
from bagbuilder import EPOCH, BagBuilder
from lxml import etree
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from robotale.eventlog import schema
from robotale.eventlog.dataset import read_table
from robotale.eventlog.enrich import PreparationWarning
from robotale.eventlog.prepare import prepare, prepare_dataset
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv, write_xes
from robotale.fame_runtime.tags import TAG_TYPE, register_tag_type
from robotale.storage import place

ACTIVITIES = ("plan", "move", "grip", "place")
TAGS = 40


def one_ns_apart(path, storage: str):
    """One robot's tags, each a start, 1 ns after the previous (as a busy recorder stamps
    them), and two at one same instant at the end."""
    b = BagBuilder()
    for k in range(TAGS):
        b.tag(k * 1e-9, "arm", ACTIVITIES[k % 4], "start")
    b.tag(TAGS * 1e-9, "arm", "release", "start").tag(TAGS * 1e-9, "arm", "rest", "start")
    return b.write(path, storage=storage)


def stamps_by_rosbags(bag) -> list[tuple[int, str]]:
    """(stamp in ns, activity) of every tag, in the order the bag recorded them."""
    store = get_typestore(Stores.ROS2_HUMBLE)
    register_tag_type(store)
    found = []
    with Reader(bag) as reader:
        for _, _, raw in reader.messages():
            tag = store.deserialize_cdr(raw, TAG_TYPE)
            found.append((tag.stamp.sec * 10**9 + tag.stamp.nanosec, tag.activity))
    return found


def implicit_log(bag) -> pd.DataFrame:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PreparationWarning)
        return prepare(bag, perspectives=[], rate=0, lifecycle="implicit")


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_tags_one_nanosecond_apart_keep_their_times_and_order(tmp_path, storage):
    bag = one_ns_apart(tmp_path / "bag", storage)
    recorded = stamps_by_rosbags(bag)
    log = implicit_log(bag)
    starts = log[log[schema.LIFECYCLE] == schema.START]
    found = zip(starts[schema.TIMESTAMP], starts[schema.ACTIVITY], strict=True)
    assert [(t.value, a) for t, a in found] == recorded
    # every activity ends when the next tag begins: start, complete, start, complete ...
    assert log[schema.LIFECYCLE].tolist() == ["start", "complete"] * len(recorded)
    assert log[schema.ACTIVITY].tolist()[::2] == log[schema.ACTIVITY].tolist()[1::2]
    nanos = log[schema.TIMESTAMP].astype("int64").to_numpy()
    durations = (nanos[1::2] - nanos[::2]).tolist()
    expected = [b[0] - a[0] for a, b in itertools.pairwise(recorded)]
    # the last one ends with the recording (its last message), which is its own instant
    assert durations == [*expected, 0]
    assert expected.count(1) == TAGS and expected.count(0) == 1


def test_a_completion_at_its_starts_instant_comes_after_it(tmp_path):
    """release and rest share an instant: release's implied completion is at that instant,
    after release's start and before rest's."""
    log = implicit_log(one_ns_apart(tmp_path / "bag", "sqlite3"))
    tail = log.tail(4)
    assert list(zip(tail[schema.ACTIVITY], tail[schema.LIFECYCLE], strict=True)) == [
        ("release", "start"),
        ("release", "complete"),
        ("rest", "start"),
        ("rest", "complete"),
    ]
    assert tail[schema.TIMESTAMP].nunique() == 1


def test_the_csv_and_the_parquet_dataset_keep_nanoseconds(tmp_path):
    bag = one_ns_apart(tmp_path / "runs" / "run_1", "mcap")
    log = implicit_log(bag)
    write_csv(log, tmp_path / "log.csv")
    first = (tmp_path / "log.csv").read_text().splitlines()[2].split(",")[1]
    assert first == (EPOCH + pd.Timedelta(1, "ns")).strftime("%Y-%m-%dT%H:%M:%S.000000001+00:00")
    again = read_log(tmp_path / "log.csv")
    assert again[schema.TIMESTAMP].tolist() == log[schema.TIMESTAMP].tolist()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PreparationWarning)
        manifest = prepare_dataset(
            tmp_path / "runs", tmp_path / "log.parquet", perspectives=[], rate=0,
            lifecycle="implicit",
        )  # fmt: skip
    table = read_table(place(tmp_path / "log.parquet"), manifest).to_pandas()
    assert str(table["time"].dtype) == "datetime64[ns, UTC]"
    assert table["time"].tolist() == log[schema.TIMESTAMP].tolist()


def test_xes_writes_the_nanoseconds_as_text(tmp_path):
    log = implicit_log(one_ns_apart(tmp_path / "bag", "sqlite3"))
    write_xes(log, tmp_path / "log.xes")
    ns = {"x": "http://www.xes-standard.org/"}
    tree = etree.parse(str(tmp_path / "log.xes"))
    dates = tree.xpath("//x:event/x:date[@key='time:timestamp']/@value", namespaces=ns)
    assert pd.to_datetime(pd.Series(dates), format="ISO8601").tolist() == (
        log[schema.TIMESTAMP].tolist()
    )


def test_neo4j_keeps_nanoseconds_and_no_df_edge_goes_back(tmp_path, neo4j_driver, log_name):
    from robotale.ekg import build_ekg  # why: only this test needs Neo4j

    log = implicit_log(one_ns_apart(tmp_path / "bag", "sqlite3"))
    build_ekg(neo4j_driver, log, log_name, entities=["robot"], progress=False)
    with neo4j_driver.session() as session:
        stored = session.run(
            "MATCH (e:Event {log: $log}) RETURN e.timestamp.epochSeconds AS s, "
            "e.timestamp.nanosecond AS n ORDER BY e.order",
            log=log_name,
        ).values()
        back = session.run(
            "MATCH (a:Event {log: $log})-[:DF]->(b:Event) WHERE b.timestamp < a.timestamp OR "
            "(a.lifecycle = 'complete' AND b.lifecycle = 'start' AND a.activity = b.activity "
            "AND a.timestamp = b.timestamp) RETURN count(*)",
            log=log_name,
        ).single()[0]
        mean = session.run(
            "MATCH (:Class {log: $log, id: 'plan'})-[r:DF_C]->(:Class {id: 'move'}) "
            "RETURN r.meanSeconds",
            log=log_name,
        ).single()
    assert [s * 10**9 + n for s, n in stored] == log[schema.TIMESTAMP].astype("int64").tolist()
    assert back == 0
    # a plan ends and the move after it ends 1 ns later (DF_C joins activity instances)
    assert mean is not None and mean[0] == pytest.approx(1e-9)
