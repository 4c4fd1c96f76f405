"""Interrupted activities, ties and copied rows, on small logs counted by hand."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from robotale.commands.inspect import inspect_command
from robotale.discovery.dfg import discover_dfg
from robotale.enhancement import communication_perspective, performance_perspective
from robotale.enhancement.bottlenecks import find_bottlenecks
from robotale.eventlog.readers import read_log


def write(path: Path, rows: list[str]) -> Path:
    path.write_text("case,robot,activity,lifecycle,time,msg_id\n" + "\n".join(rows) + "\n")
    return path


def at(second: int) -> str:
    return f"2024-01-01T10:00:{second:02d}Z"


def test_an_aborted_activity_is_an_instance_and_keeps_its_edge(tmp_path):
    """The drone explores (0-5), low battery interrupts its second explore (6-9, ended with
    XES' ate_abort), it handles low_battery (9-10) and lands (11-12). By hand: explore has 2
    instances, 1 interrupted; the DFG has explore -> low_battery (figure 7.4's edge)."""
    log = read_log(
        write(
            tmp_path / "abort.csv",
            [
                f"1,drone,explore,start,{at(0)},",
                f"1,drone,explore,complete,{at(5)},",
                f"1,drone,explore,start,{at(6)},",
                f"1,drone,explore,ate_abort,{at(9)},",
                f"1,drone,low_battery,start,{at(9)},",
                f"1,drone,low_battery,complete,{at(10)},",
                f"1,drone,land,start,{at(11)},",
                f"1,drone,land,complete,{at(12)},",
            ],
        )
    )
    graph = discover_dfg(log)
    edges = {(e.source, e.target): e.count for e in graph.edges}
    assert edges[("explore", "low_battery")] == 1 and edges[("explore", "explore")] == 1
    explore = next(n for n in graph.nodes if n.id == "explore")
    assert explore.count == 2
    assert explore.properties == {"unfinished": 0, "interrupted": 1}
    performance = performance_perspective(log)
    durations = performance.tables["activities"].set_index("activity")
    assert durations.loc["explore", "count"] == 2 and durations.loc["explore", "interrupted"] == 1
    assert durations.loc["explore", "total"] == 5 + 3
    assert performance.summary["interrupted"] == 1


def test_the_raw_xes_abort_transition_pairs_without_the_reader(tmp_path):
    """A log handed over as a DataFrame with the raw lifecycle ``ate_abort``: the same."""
    log = read_log(
        write(
            tmp_path / "raw.csv",
            [
                f"1,drone,explore,start,{at(0)},",
                f"1,drone,explore,complete,{at(4)},",
                f"1,drone,low_battery,start,{at(4)},",
                f"1,drone,low_battery,complete,{at(5)},",
            ],
        )
    )
    log.loc[1, "lifecycle:transition"] = "ate_abort"
    edges = {(e.source, e.target) for e in discover_dfg(log).edges}
    assert ("explore", "low_battery") in edges


TIES = [
    # two robots start at the same second; the file order differs between the two files
    (f"1,r2,b,start,{at(0)},", f"1,r1,a,start,{at(0)},"),
    (f"1,r1,a,complete,{at(3)},", f"1,r2,b,complete,{at(3)},"),
    (f"1,r2,c,start,{at(3)},", f"1,r1,d,start,{at(3)},"),
    (f"1,r2,c,complete,{at(5)},", f"1,r1,d,complete,{at(5)},"),
]


def test_variants_do_not_depend_on_the_order_of_rows_at_one_moment(tmp_path):
    """The same events in two orders: each gives the variant 'a -> b -> d -> c' (at 0 s r1
    before r2; at 3 s the starts before the completions, then r1's d before r2's c)."""
    variants = []
    for n, order in enumerate((0, 1)):
        rows = [pair[order] for pair in TIES] + [pair[1 - order] for pair in TIES]
        rows.sort(key=lambda row: row.split(",")[4])  # time order, ties as written
        log = read_log(write(tmp_path / f"ties{n}.csv", rows))
        variants.append(performance_perspective(log).tables["variants"]["variant"].tolist())
    assert variants[0] == variants[1] == ["a -> b -> d -> c"]


def test_an_exact_copy_is_flagged_and_counted_once(tmp_path, capsys):
    """Line 4 repeats line 3 cell for cell (a send logged twice): inspect names it, and there
    is one message, one send attempt, no resend, one activity instance, no rework."""
    path = write(
        tmp_path / "copy.csv",
        [
            f"1,r1,go,start,{at(0)},",
            f"1,r1,report!,complete,{at(2)},m1",
            f"1,r1,report!,complete,{at(2)},m1",
            f"1,r2,report?,complete,{at(3)},m1",
            f"1,r1,go,complete,{at(6)},",
        ],
    )
    inspect_command(path)
    printed = capsys.readouterr().out
    copy = "1 dropped: an exact copy of an earlier row (the event counts once) (line 4)"
    assert copy in printed
    log = read_log(path)
    assert len(log) == 4
    messages = communication_perspective(log).tables["messages"]
    assert len(messages) == 1 and messages["attempts"].tolist() == [1]
    assert messages["resends"].tolist() == [0]
    durations = performance_perspective(log).tables["activities"].set_index("activity")
    assert durations.loc["report!", "count"] == 1
    ranking = find_bottlenecks(log)
    kinds = set(ranking.table["kind"]) if ranking.has_data else set()
    assert "rework" not in kinds and "loop" not in kinds


def test_copies_across_two_cases_are_not_copies(tmp_path):
    """The same event in two cases differs by its case: both are kept."""
    log = read_log(
        write(
            tmp_path / "cases.csv",
            [f"1,r1,go,complete,{at(0)},", f"2,r1,go,complete,{at(0)},"],
        )
    )
    assert len(log) == 2
    assert sorted(pd.unique(log["case:concept:name"])) == ["1", "2"]
