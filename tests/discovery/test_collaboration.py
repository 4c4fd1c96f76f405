"""``discover bpmn`` on the thesis' own log: pools Drone and Tractor, the three signals, the
low battery as an event sub-process, a model that ``fame check`` accepts and that replays the
log (robotale's conformance, pm4py alignments)."""

from __future__ import annotations

import pytest
from collaboration_checks import (
    check_problems_besides_skills,
    handlers,
    missing_skills,
    overlaps,
    read,
    signal_events,
    unshaped,
)

from robotale.cli import main
from robotale.discovery.collaboration import discover_collaboration
from robotale.discovery.conformance import check_conformance
from robotale.eventlog.readers import read_log
from robotale.sim.skills import SKILLS

B = "{http://www.omg.org/spec/BPMN/20100524/MODEL}"


@pytest.fixture(scope="module")
def thesis_days(thesis_csv):
    """The thesis log cut into its five days (one run each)."""
    return read_log(thesis_csv, case_gap="1h")


@pytest.fixture(scope="module")
def discovered(thesis_csv, tmp_path_factory):
    out = tmp_path_factory.mktemp("bpmn") / "mission.bpmn"
    assert main(["discover", "bpmn", str(thesis_csv), "--case-gap", "1h", "--out", str(out)]) == 0
    return out


def test_pools_drone_and_tractor_the_tractors_sharing_one(discovered):
    root = read(discovered)
    pools = {p.get("name"): p for p in root.iter(f"{B}participant")}
    assert set(pools) == {"Drone", "Tractor"}
    assert pools["Tractor"].find(f"{B}participantMultiplicity").get("maximum") == "2"
    assert pools["Drone"].find(f"{B}participantMultiplicity") is None


def test_signals_thrown_and_caught_where_the_log_sends_and_receives_them(discovered, thesis_days):
    root = read(discovered)
    thrown = signal_events(root, "intermediateThrowEvent")
    caught = signal_events(root, "intermediateCatchEvent")
    # the log's own message activities, counted with pandas
    names = thesis_days["concept:name"].astype(str)
    assert thrown == {n[:-1] for n in names if n.endswith("!")}
    assert caught == {n[:-1] for n in names if n.endswith("?")}
    assert {"weed_position", "tractor_position", "closest_tractor"} <= thrown & caught


def test_low_battery_is_an_interrupting_event_subprocess_of_both_robot_types(discovered):
    root = read(discovered)
    assert handlers(root) == {"Drone": {"low_battery"}, "Tractor": {"low_battery"}}
    for start in root.iter(f"{B}startEvent"):
        if start.get("name") == "low_battery":
            assert start.get("isInterrupting") == "true"
    # the handler is not also part of the main flow
    assert not [e for e in root.iter(f"{B}callActivity") if e.get("name") == "Low Battery"]


def test_fame_check_names_only_the_skills_the_simulation_lacks(discovered, thesis_days):
    assert check_problems_besides_skills(discovered) == []
    lacking = missing_skills(discovered)
    assert lacking and not lacking & set(SKILLS)


def test_every_element_drawn_and_no_shapes_overlap(discovered):
    root = read(discovered)
    assert unshaped(root) == []
    assert overlaps(root) == []


def test_replaying_the_log_fits_each_robot(discovered, thesis_days):
    report = check_conformance(thesis_days, discovered)
    assert set(report.robots["robot"]) == {"drone", "tractor_1", "tractor_2"}
    assert (report.robots["fitness"] >= 0.95).all(), report.robots


def test_robot_type_filter_keeps_one_pool(thesis_days, tmp_path):
    from robotale.discovery.filters import LogFilter

    collaboration = discover_collaboration(thesis_days, LogFilter(robot_types=["Tractor"]))
    assert [p.name for p in collaboration.pools] == ["Tractor"]
    assert collaboration.pool("Tractor").robots == ["tractor_1", "tractor_2"]


def test_conformance_reports_precision_one_only_where_the_model_allows_nothing_more(
    thesis_days, discovered, tmp_path
):
    import pandas as pd

    from robotale.discovery.bpmn_writer import write_bpmn

    # three runs of one robot doing a, b, c in order: the mined model is that sequence
    times = pd.date_range("2024-01-01", periods=9, freq="s", tz="UTC")
    log = pd.DataFrame(
        {
            "case:concept:name": [str(i // 3) for i in range(9)],
            "concept:name": ["a", "b", "c"] * 3,
            "time:timestamp": times,
            "robot": "rover",
        }
    )
    model = tmp_path / "sequence.bpmn"
    model.write_text(write_bpmn(discover_collaboration(log)))
    exact = check_conformance(log, model).robots
    assert exact["fitness"].tolist() == [1.0] and exact["precision"].tolist() == [1.0]
    # the thesis' tractors' model allows any interleaving of their loops: far from exact
    loose = check_conformance(thesis_days, discovered).robots
    assert (loose["precision"] < 0.9).all() and (loose["precision"] > 0).all()


def test_the_tractors_cut_grass_when_closest_tractor_names_them(thesis_days):
    """The payload rule of FAME's tractor (``tractor === namespace``), found in the log: the
    test of the caught ``name`` against the tractor's own name separates cutting grass from
    not, in every catch (the thesis' duplicate deliveries read once). The miner draws the
    catch beside the tractors' work rather than before a choice, so the written model has
    no choice to put it on."""
    from robotale.discovery.payload_choices import Test, separating

    tractor = discover_collaboration(thesis_days).pool("Tractor")
    caught = tractor.caught["closest_tractor?"]
    assert separating(caught, [frozenset(), frozenset({"cut_grass"})]) == (Test("name", None), 1)
    # with pandas: each tractor cut grass once per closest_tractor naming it
    starts = thesis_days[thesis_days["lifecycle:transition"] == "start"]
    names = starts["concept:name"].astype(str)
    got = starts[(names == "closest_tractor?") & starts["robot"].str.startswith("tractor")]
    mine = got[[robot in str(p) for p, robot in zip(got["msg_payload"], got["robot"], strict=True)]]
    cut = starts[names == "cut_grass"]
    assert mine.groupby("robot").size().to_dict() == cut.groupby("robot").size().to_dict()
    assert sum(Test("name", None).holds(one) for one in caught) == len(cut)


def test_conformance_precision_is_the_hand_count_and_pm4pys_on_its_own_net(tmp_path, capsys):
    """A choice of three first steps, two of which the replayed runs take: ETConformance by
    hand, over the prefixes of the three runs (the empty one allows b, c and e where b and c
    were seen, three times; after b or c only d is allowed, three times): 1 - 3 / 12. pm4py's
    token-based precision on its own inductive miner's net of the same traces agrees, and
    ``discover conformance`` prints it and writes it."""
    import json

    import pandas as pd
    import pm4py

    from robotale.discovery.bpmn_writer import write_bpmn

    def log_of(traces: list[str]) -> pd.DataFrame:
        t0 = pd.Timestamp("2024-01-01", tz="UTC")
        rows = [
            (str(n), step, t0 + pd.Timedelta(hours=n, seconds=i), "rover")
            for n, trace in enumerate(traces)
            for i, step in enumerate(trace)
        ]
        return pd.DataFrame(
            rows, columns=["case:concept:name", "concept:name", "time:timestamp", "robot"]
        )

    mined, replayed = log_of(["bd", "cd", "ed"]), log_of(["bd", "bd", "cd"])
    model = tmp_path / "choice.bpmn"
    model.write_text(write_bpmn(discover_collaboration(mined)))
    robots = check_conformance(replayed, model).robots
    assert robots["fitness"].tolist() == [1.0]
    assert robots["precision"].tolist() == [pytest.approx(1 - 3 / 12)]
    net, initial, final = pm4py.discover_petri_net_inductive(mined)
    assert pm4py.precision_token_based_replay(replayed, net, initial, final) == pytest.approx(
        1 - 3 / 12
    )
    csv, out = tmp_path / "replayed.csv", tmp_path / "conformance.json"
    replayed.to_csv(csv, index=False)
    assert (
        main(["discover", "conformance", str(csv), "--model", str(model), "--json", str(out)]) == 0
    )
    header, row = capsys.readouterr().out.splitlines()[:2]
    assert header.split() == [
        "robot",
        "pool",
        "runs",
        "fitness",
        "precision",
        "fitting_runs",
        "method",
    ]
    assert row.split()[3:5] == ["1.000", "0.750"]
    written = json.loads(out.read_text(encoding="utf-8"))["robots"]
    assert [r["precision"] for r in written] == [pytest.approx(0.75)]
