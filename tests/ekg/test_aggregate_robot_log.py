"""Spatial and temporal aggregation of a simulated agricultural mission (drone and tractors in
pybullet, recorded as rosbag2, prepared by robotale): grid cells, named regions and time
windows, each aggregate's count and attributes equal to pandas on the prepared log."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from robotale.cli import main
from robotale.ekg.connection import database
from robotale.ekg.spec import parse_spec
from robotale.ekg.steps import level_graph, run_spec

pytestmark = [
    pytest.mark.slow,
    pytest.mark.filterwarnings("ignore:Install the optional requirement:UserWarning"),
]
CELL = 5.0


@pytest.fixture(scope="module")
def agri_csv(tmp_path_factory):
    folder = tmp_path_factory.mktemp("agri")
    runs, csv = folder / "runs", folder / "agri.csv"
    assert main(["simulate", "agri", "--runs", "1", "--tractors", "2", "--seed", "4",
                 "--out", str(runs), "--quiet"]) == 0  # fmt: skip
    assert main(["prepare", str(runs), "--out", str(csv)]) == 0
    return csv


@pytest.fixture
def agri(agri_csv, capsys, log_name) -> tuple[str, pd.DataFrame]:
    assert main(["ingest", str(agri_csv), "--log", log_name, "--entities", "robot,msg_id"]) == 0
    capsys.readouterr()
    events = pd.read_csv(agri_csv)
    events["when"] = pd.to_datetime(events["time"], format="ISO8601", utc=True)
    return log_name, events


def stored(driver, log: str, step: int) -> dict[str, dict]:
    records, _, _ = driver.execute_query(
        "MATCH (a:Aggregate {log: $log, step: $step}) RETURN properties(a) AS a",
        log=log,
        step=step,
        database_=database(),
    )
    return {r["a"]["name"]: dict(r["a"]) for r in records}


def test_grid_cells_and_regions_of_positioned_events(neo4j_driver, agri):
    log, events = agri
    spec = parse_spec({"steps": [
        {"aggr_type": "EVENTS", "group_by": [{"grid": {"x": "x", "y": "y", "size": CELL}}],
         "where": "x is not null and y is not null and robot in ['drone', 'tractor_1']",
         "attr_aggrs": [{"name": "x", "function": "AVG"}, {"name": "y", "function": "MINMAX"}]},
        {"aggr_type": "EVENTS", "group_by": ["robot", {"regions": {"areas": {
            "west": {"box": [-100, -100, 10, 100]},
            "east": [[10, -100], [100, -100], [100, 100], [10, 100]]}}}],
         "where": "x is not null"},
    ]})  # fmt: skip
    first, second = run_spec(neo4j_driver, log, spec)
    placed = events[events["x"].notna() & events["y"].notna()]
    chosen = placed[placed["robot"].isin(["drone", "tractor_1"])]
    assert len(chosen) > 20  # a mission that moved
    cells = (
        np.floor(chosen["x"] / CELL).astype(int).astype(str)
        + ","
        + np.floor(chosen["y"] / CELL).astype(int).astype(str)
    )
    found = stored(neo4j_driver, log, 1)
    assert set(found) == set(cells)
    for cell, part in chosen.groupby(cells):
        aggregate = found[cell]
        assert aggregate["count"] == len(part)
        assert aggregate["x_avg"] == pytest.approx(part["x"].mean(), rel=1e-9)
        assert (aggregate["y_min"], aggregate["y_max"]) == (part["y"].min(), part["y"].max())
    rest = events[events["x"].notna() & ~events.index.isin(chosen.index)]
    region = np.where(rest["x"] < 10, "west", "east")
    expected = (rest["robot"] + "|" + region).value_counts().to_dict()
    assert {n: a["count"] for n, a in stored(neo4j_driver, log, 2).items()} == expected
    assert (first.initial_events, first.final_events) == (len(events), len(events) - len(chosen))
    assert second.final_events == len(events) - len(chosen) - len(rest)
    # the dashboard's level 2: every aggregate of both steps
    assert len(level_graph(neo4j_driver, log, 2)["aggregates"]) == len(found) + len(expected)


def test_time_windows_per_robot(neo4j_driver, agri):
    log, events = agri
    spec = parse_spec({"steps": [
        {"aggr_type": "EVENTS",
         "group_by": ["robot", {"window": {"property": "timestamp", "size": "10s"}}],
         "attr_aggrs": [{"name": "activity", "function": "MULTISET"},
                        {"name": "timestamp", "function": "MINMAX"}]},
    ]})  # fmt: skip
    [result] = run_spec(neo4j_driver, log, spec)
    start = events["when"].dt.floor("10s").dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")
    names = events["robot"].fillna("unknown") + "|" + start
    found = stored(neo4j_driver, log, 1)
    assert set(found) == set(names)
    for name, part in events.groupby(names):
        aggregate = found[name]
        assert aggregate["count"] == len(part)
        counts = part["activity"].value_counts()
        assert aggregate["activity_multiset"] == [f"{a}:{c}" for a, c in sorted(counts.items())]
        first = aggregate["timestamp_min"].to_native()
        assert pd.Timestamp(first) == part["when"].min().floor("us")
    assert result.final_events == 0 and result.aggregates == len(found)
    # DF per robot lifted between the windows: as many DF edges as consecutive events of a
    # robot that fall in different windows, and self-loops for the rest
    edges = level_graph(neo4j_driver, log, 1)["edges"]
    df = sum(e["count"] for e in edges if e["type"] == "DF" and e["entityType"] == "robot")
    ordered = events.sort_values(["when"], kind="stable").dropna(subset=["robot"])
    assert df == sum(len(p) - 1 for _, p in ordered.groupby(["case", "robot"]))
