"""The benchmarks' "same output" checks tell the same work from other work: each on a small
input, once where both sides compute the same and once where one computes something else."""

from __future__ import annotations

import signal
import sys

import pandas as pd
import pytest
from benchmark_scripts import benchmark
from pandas import Timedelta

from robotale.enhancement.findings import find
from robotale.eventlog.schema import ACTIVITY, CASE, LIFECYCLE, MSG_ID, TIMESTAMP


@pytest.fixture(scope="module")
def ekg_build():
    return benchmark("ekg_build")


def test_the_directly_follows_counts_of_robotale_and_pm4py_are_checked_equal(ekg_build):
    log = ekg_build.synthetic_log(3_000)
    ours, theirs = ekg_build.robotale_dfg(log), ekg_build.pm4py_dfg(log)
    assert len(ours) > 50 and sum(ours.values()) > 2_000
    assert ekg_build.same_dfg(ours, theirs) == []


def test_a_dfg_of_other_flows_is_told_apart(ekg_build):
    import pm4py

    from robotale.eventlog import schema

    log = ekg_build.synthetic_log(3_000)
    # each robot's flow across all runs: pm4py computing other work than robotale's DF_C
    dfg, _, _ = pm4py.discover_dfg(log, case_id_key=schema.ROBOT)
    across = {(str(a), str(b)): int(n) for (a, b), n in dfg.items()}
    assert ekg_build.same_dfg(ekg_build.robotale_dfg(log), across) != []
    # one activity named otherwise on one side only
    renamed = log.assign(**{schema.ACTIVITY: log[schema.ACTIVITY].replace("scan", "look")})
    differences = ekg_build.same_dfg(ekg_build.robotale_dfg(log), ekg_build.pm4py_dfg(renamed))
    assert any("scan" in line or "look" in line for line in differences)


def test_the_whole_ingests_graphs_are_checked_equal_where_both_build_the_same(
    neo4j_driver, log_name, thesis_csv
):
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import graph_counts
    from robotale.eventlog.readers import read_log

    whole = benchmark("whole_ingest")
    build_ekg(
        neo4j_driver, read_log(thesis_csv), log_name, entities=["robot", "msg_id"], progress=False
    )
    ours = graph_counts(neo4j_driver)
    # the benchmark's counts (Neo4j's count store) are those of a scan
    assert benchmark("peers").counts(neo4j_driver) == ours
    # PromG's names for the same nodes and edges: the check compares them row by row
    theirs = {
        "node:Event": ours["node:Event"],
        "node:Entity": ours["node:Entity"],
        "relationship:CORR": ours["relationship:CORR"],
        "node:Activity": ours["node:Class"],
        "relationship:OBSERVED": ours["relationship:OBSERVED"],
    }
    assert whole.same_counts(ours, theirs) == []
    fewer = theirs | {"relationship:CORR": theirs["relationship:CORR"] - 1}
    assert whole.same_counts(ours, fewer) == [
        f"CORR: robotale {ours['relationship:CORR']:,}, PromG {fewer['relationship:CORR']:,}"
    ]


def test_an_ingest_ended_by_a_signal_is_told_in_one_sentence(tmp_path):
    whole = benchmark("whole_ingest")
    from robotale.neo4j_server.server import LocalServer

    server = LocalServer(tmp_path)  # an empty home: no server runs there
    killed = "import os, signal, sys; print('reading', file=sys.stderr, flush=True); "
    killed += "os.kill(os.getpid(), signal.SIGKILL)"
    run, status, _, stderr = whole.timed_process([sys.executable, "-c", killed], server)
    said = whole.failure("robotale ingest", status, stderr, run, server)
    assert status == -signal.SIGKILL
    assert said.startswith("robotale ingest was ended by SIGKILL")
    assert "saying: reading; its Neo4j server no longer runs" in said


def test_the_importers_bound_checks_what_it_imported():
    importer_bound = benchmark("importer_bound")
    done = importer_bound.importer_seconds(200, 5, 700)
    # the importer's own report, read back: the graph asked for, counted by Neo4j
    assert done.imported == (200, 700, 1000)
    assert 0 < done.own <= done.wall


def test_the_importers_report_is_read_and_a_short_one_is_refused():
    from robotale.neo4j_server.importer import parse_report

    report = (
        "IMPORT DONE in 1m 2s 500ms. \nImported:\n  12 nodes\n  30 relationships\n  60 properties"
    )
    done = parse_report(report)
    assert done is not None
    assert (done.seconds, done.nodes, done.relationships, done.properties) == (62.5, 12, 30, 60)
    assert parse_report("IMPORT DONE in 3s 1ms. \nImported:\n  12 nodes") is None


def test_the_graphs_shape_counts_each_node_once_and_every_relationship():
    importer_bound = benchmark("importer_bound")
    counts = {"node:Event": 10, "node:Entity": 3, "node:Class": 2, "node:Robot": 3}
    counts |= {"relationship:DF": 9, "relationship:CORR": 12}
    assert importer_bound.shape(counts) == (15, 21)


# -- findings_against.py: the findings of two revisions ----------------------------------------


@pytest.fixture(scope="module")
def runs():
    return benchmark("dashboard").thesis_runs(3_000)


@pytest.fixture(scope="module")
def against():
    return benchmark("findings_against")


def test_the_same_answers_are_checked_equal(runs, against):
    ours = against.comparable(find(runs))
    # the sent messages by hand: the distinct message ids of the log, per run
    assert ours["sent"] == runs.dropna(subset=[MSG_ID]).drop_duplicates([CASE, MSG_ID]).shape[0]
    assert against.compared(ours, against.comparable(find(runs.copy()))).startswith("equal")


def test_a_longer_activity_is_told_apart(runs, against):
    ours = against.comparable(find(runs))
    # the last completion of an activity whose starts the log has: its instance ends later
    started = set(runs.loc[runs[LIFECYCLE].eq("start").fillna(False), ACTIVITY])
    ends = runs[LIFECYCLE].eq("complete").fillna(False) & runs[ACTIVITY].isin(started)
    last = runs[ends].index[-1]
    later = runs.copy()
    later.loc[last, TIMESTAMP] = later.loc[last, TIMESTAMP] + Timedelta(seconds=5)
    verdict = against.compared(ours, against.comparable(find(later)))
    assert verdict.startswith("DIFFERENT") and "activities" in verdict


def test_a_missing_message_is_told_apart(runs, against):
    ours = against.comparable(find(runs))
    first = runs[MSG_ID].dropna().iloc[0]
    fewer = runs[runs[MSG_ID].ne(first).fillna(True)].reset_index(drop=True)
    verdict = against.compared(ours, against.comparable(find(fewer)))
    assert verdict.startswith("DIFFERENT") and "sent" in verdict


@pytest.fixture(scope="module")
def live():
    return benchmark("live")


def test_the_live_benchmark_checks_every_tag_stored_once_as_published(live):
    """Tags read back as the monitor stores them (the stamp through a DDS sample's seconds and
    nanoseconds, then a float) match those published; one lost, one stored twice and one never
    published are each named."""
    from robotale.fame_runtime.rostypes import tag_fields
    from robotale.fame_runtime.tags import Tag

    published, stored = [], []
    for robot in live.robots_of(3):
        stamp = 1_800_000_000.0
        for _, (gap, activity, lifecycle) in zip(range(7), live.tag_steps(robot, 1), strict=False):
            stamp += gap
            published.append(live.key(robot, activity, lifecycle, stamp))
            wire = tag_fields(Tag(stamp, robot, activity, lifecycle))["stamp"]
            heard = wire["sec"] + wire["nanosec"] / 1e9
            stored.append(live.key(robot, activity, lifecycle, heard))
    assert len(set(published)) == 21
    assert live.same_tags(published, stored[::-1]) == ([], [])
    lost, twice, foreign = stored[4], stored[9], ("rover_9", "survey", "start", 1)
    changed = [t for t in stored if t != lost] + [twice, foreign]
    missing, extra = live.same_tags(published, changed)
    assert missing == [published[4]]
    assert sorted(extra) == sorted([twice, foreign])


def test_the_live_benchmark_robots_tag_what_their_pool_allows(live, tmp_path):
    """The synthetic robots start their activities in an order the benchmark's model allows
    (replayed as the monitor replays them), so the monitor raises no deviation."""
    from robotale.discovery.online import pool_replays
    from robotale.fame_runtime.tags import Tag

    model = tmp_path / "rover.bpmn"
    model.write_text(live.MODEL)
    robots = live.robots_of(2)
    replays = pool_replays(model, robots)
    for robot in robots:
        steps = zip(range(40), live.tag_steps(robot, 3), strict=False)
        tags = [Tag(float(i), robot, a, lc) for i, (_, (_, a, lc)) in enumerate(steps)]
        assert {t.activity for t in tags} == set(live.ACTIVITIES)
        assert all(replays[robot].allows(t) for t in tags)
    # a robot that skips measure deviates: the replay can tell
    skipping = [("survey", "start"), ("survey", "complete"), ("report", "start")]
    fresh = pool_replays(model, ["rover_1"])["rover_1"]
    allowed = [fresh.allows(Tag(0.0, "rover_1", a, lc)) for a, lc in skipping]
    assert allowed == [True, True, False]


def test_the_live_benchmark_times_a_tag_from_the_first_answer_within_two_microseconds(live):
    published = [
        ("rover_1", "survey", "start", 10_000_000),
        ("rover_1", "survey", "complete", 12_000_000),
    ]
    seen = {10_000_002: 10.5, 10_000_000: 11.0, 12_000_003: 13.0}
    assert live.shown(published, seen) == {published[0]: 10.5}
    stamps = {k: k[3] / 1e6 for k in published}
    assert live.lags(stamps, live.shown(published, seen)) == [(10.0, 0.5)]


def test_the_live_benchmark_judges_growth_from_minutes_2_3_and_the_last_two(live):
    """Six whole minutes of lags, one tag a second: 5 s in minute 1 (the start, left out),
    0.2 s in minutes 2-3, 0.3 s in 4, 0.5 s in 5-6, and a partial seventh minute of 9 s left
    out. By hand: last two over minutes 2-3 0.5 / 0.2 = 2.5x; the per-minute p95s 0.2, 0.2,
    0.3, 0.5, 0.5 at minutes 0-4 have a least-squares slope of 0.9 / 10 s per minute (their
    co-deviation over the minutes' squared deviation). The same lag throughout: 1.0x, slope
    0. Under five whole minutes: not judged."""
    levels = [5.0, 0.2, 0.2, 0.3, 0.5, 0.5]
    measured = [(100.0 + s, levels[s // 60]) for s in range(360)] + [(470.0, 9.0)]
    ratio, slope = live.growth(measured)
    assert ratio == pytest.approx(2.5) and slope == pytest.approx(0.09)
    flat = [(100.0 + s, 0.3) for s in range(360)]
    assert live.growth(flat) == (pytest.approx(1.0), pytest.approx(0.0))
    assert live.growth(flat[:300]) is None


# -- aggregate.py: robotale's aggregation against the plain queries ----------------------------


@pytest.fixture(scope="module")
def aggregation():
    return benchmark("aggregate")


def test_the_aggregation_log_is_written_a_slice_at_a_time_as_it_is_made_whole(tmp_path):
    """At 5M events the benchmark writes the logistics log a slice at a time: the same file and
    object tables as the log made at once and written by pandas."""
    from ocean_shaped import logistics, write_logistics

    whole = logistics(1_000)
    whole.events.to_csv(tmp_path / "whole.csv", index=False)
    assert write_logistics(1_000, tmp_path, chunk=333) == whole.types
    assert (tmp_path / "events.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()
    for kind, table in whole.objects.items():
        written = pd.read_csv(tmp_path / "objects" / f"{kind}.csv", dtype={"id": str})
        pd.testing.assert_frame_equal(written, table)


def test_robotale_and_the_plain_queries_are_checked_equal_and_a_changed_edge_told_apart(
    tmp_path, capsys, neo4j_driver, log_name, aggregation
):
    from ocean_shaped import write_logistics

    from robotale.cli import main
    from robotale.ekg.connection import database

    types = write_logistics(600, tmp_path)
    code = main(["ingest", str(tmp_path / "events.csv"), "--log", log_name,
                 "--entities", ",".join(types)])  # fmt: skip
    assert code == 0, capsys.readouterr().err
    aggregation.set_attributes(neo4j_driver, tmp_path / "objects", log_name, types)
    spec = aggregation.parse_spec(aggregation.LOGISTICS_SPEC)
    aggregation.run_spec(neo4j_driver, log_name, spec)
    ours = aggregation.output(neo4j_driver, log_name)
    aggregation.restore(neo4j_driver, log_name, "robotale")
    aggregation.run_plain(neo4j_driver, log_name)
    theirs = aggregation.output(neo4j_driver, log_name)
    # OCEAN's five steps: three container statuses, two order types twice, then events
    assert len(ours[0]) > 3 + 2 + 2 + 12 and ours[1] > 100
    assert ours == theirs
    # one lifted edge counted once more on the plain side: the same number, another hash
    neo4j_driver.execute_query(
        "MATCH (a:Aggregate {log: $log})-[r:CORR]->() WITH r LIMIT 1 SET r.count = r.count + 1",
        log=log_name,
        database_=database(),
    )
    changed = aggregation.output(neo4j_driver, log_name)
    assert changed[:2] == theirs[:2] and changed[2] != theirs[2]
    aggregation.restore(neo4j_driver, log_name, "plain")
    nothing = aggregation.hashlib.sha256().hexdigest()
    assert aggregation.output(neo4j_driver, log_name) == ([], 0, nothing)


def test_a_run_past_its_time_is_stopped_and_its_writes_removed(
    tmp_path, capsys, neo4j_server, neo4j_driver, log_name, aggregation
):
    """A side still running at its time limit is ended (its process, its server-side
    transactions) and said not to have finished; the graph is as before it."""
    from ocean_shaped import write_logistics

    from robotale.cli import main

    types = write_logistics(300, tmp_path)
    code = main(["ingest", str(tmp_path / "events.csv"), "--log", log_name,
                 "--entities", ",".join(types)])  # fmt: skip
    assert code == 0, capsys.readouterr().err

    class NoServer:  # the test server's pid is not this test's to watch
        def pid(self) -> int:
            return 0

    limits = aggregation.Limits(seconds=0.5, available=0)
    run = aggregation.run_side("plain", neo4j_server, log_name, 0, limits, NoServer())
    assert run.failed.startswith("did not finish in")
    aggregation.restore(neo4j_driver, log_name, "plain")
    assert aggregation.output(neo4j_driver, log_name)[:2] == ([], 0)
