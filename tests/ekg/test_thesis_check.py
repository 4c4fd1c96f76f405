"""``benchmarks/ekg_build.py`` checks that robotale and the thesis' Cypher built the same
events, entities, CORR and DF edges before it compares their times: the check on a small
log, where the thesis' DF crosses runs (robotale's stays within one) and where it does not."""

from __future__ import annotations

from benchmark_scripts import benchmark

from robotale.eventlog.schema import CASE


def ekg_build():
    return benchmark("ekg_build")


def test_the_thesis_graph_is_counted_against_robotales(neo4j_driver, log_name):
    from robotale.ekg.build import build_ekg

    bench = ekg_build()
    log = bench.synthetic_log(1_000)
    entities = ["case", "robot", "msg_id"]
    graphs: list[dict] = []
    assert bench.thesis_build(neo4j_driver, log, entities, 300.0, graphs) is not None
    [theirs] = graphs
    summary = build_ekg(
        neo4j_driver, log, log_name, entities=entities, aggregate=[], progress=False
    )
    ours = bench.built_counts(log, summary)
    # by hand: every event one node, CORR to its run, its robot and its message if it has one
    assert theirs["events"] == len(log)
    assert theirs["corr"] == 2 * len(log) + int(log["msg_id"].notna().sum())
    # robotale's DF stays within a run; the thesis' follows an entity across the log: one DF
    # edge more for each run boundary a robot (or a message id) crosses, counted by hand
    crossings = sum(
        int((log.dropna(subset=[kind]).groupby(kind)[CASE].nunique() - 1).sum())
        for kind in ("robot", "msg_id")
    )
    assert crossings > 0 and theirs["df"] == ours["df"] + crossings
    assert bench.same_graph(ours, theirs) == [
        f"df: robotale {ours['df']:,}, thesis {theirs['df']:,}"
    ]
    across = ours | {"df": ours["df"] + crossings}
    assert bench.same_graph(across, theirs) == []
    # the thesis' graph was removed after it was counted
    graphs.clear()
    assert (
        neo4j_driver.execute_query(
            "MATCH (e:Event) WHERE e.Log IS NOT NULL RETURN count(e) AS n"
        ).records[0]["n"]
        == 0
    )
