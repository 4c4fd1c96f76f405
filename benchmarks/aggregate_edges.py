"""How many lifted edges each step of benchmarks/aggregate.py's specification writes, by what
the edge's other end is: another aggregate, a node a later step of the specification
collapses, or a node no step collapses.

    python benchmarks/aggregate_edges.py [--sizes 35000 1200000]

No Neo4j: the logistics log of the benchmark (tests/ekg/ocean_shaped.py) is generated, its
graph tables derived as the build derives them, and the five steps of OCEAN's logistics
specification replayed on :class:`robotale.ekg.lift.LogEdges` (the members of each step
chosen in pandas as the steps' group-bys and wheres say; the totals are the benchmark's
lifted-edge counts, checked by it against the plain queries). It tells how much of the edge
writing per step was spent on edges whose other end a later step of the same specification
replaces, and prints how many edges the level the five steps end at has (robotale writes
those, each by the later step of its two ends).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests" / "ekg"))
from ocean_shaped import ObjectLog, logistics  # noqa: E402

from robotale.ekg.build import prepare  # noqa: E402
from robotale.ekg.lift import FREE, LogEdges  # noqa: E402
from robotale.eventlog.readers import read_csv  # noqa: E402

CUTOFF = pd.Timestamp("2024-03-01T00:00:00Z")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[35_000])
    for size in parser.parse_args().sizes:
        count(size)
    return 0


def count(size: int) -> None:
    log = logistics(size)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "events.csv"
        log.events.to_csv(path, index=False)
        events = read_csv(path)
    edges = LogEdges.of_tables(prepare(events, log.types, ["activity"], "count").tables)
    lifted = []
    for step in range(1, 6):
        nodes, names = members(edges, log, step)
        held = edges.hold(nodes, [f"{step}:{name}" for name in names], ["-"] * len(nodes), step)
        lifted.append(edges.lift(np.unique(held)))  # each step's edges at its own level
    aggregate = ~pd.isna(edges.element_ids)  # as the step's aggregates were held
    totals = np.zeros(3, dtype=np.int64)
    print(f"{size:,} events:")
    for step, frame in enumerate(lifted, 1):
        source, target = frame["source"].to_numpy(), frame["target"].to_numpy()
        both = aggregate[source] & aggregate[target]
        other = np.where(aggregate[source], target, source)
        later = ~both & (edges.holder[other] != FREE)
        counts = np.array([both.sum(), later.sum(), (~both & ~later).sum()])
        totals += counts
        print(f"  step {step}: {len(frame):,} lifted edges: {counts[0]:,} between aggregates, "
              f"{counts[1]:,} to a node a later step collapses, {counts[2]:,} to a node no "
              "step collapses")  # fmt: skip
    print(f"  all steps: {totals.sum():,}: {totals[0]:,} between aggregates, {totals[1]:,} to "
          f"a node a later step collapses, {totals[2]:,} to a node no step collapses")  # fmt: skip
    final = sum(len(edges.lift(edges.aggregates_of(step), upto=step)) for step in range(1, 6))
    print(f"  at the level the five steps end at (what robotale writes): {final:,}")


def members(edges: LogEdges, log: ObjectLog, step: int) -> tuple[np.ndarray, np.ndarray]:
    """The nodes step ``step`` collapses (codes) and the name of each one's aggregate."""
    if step <= 3:
        kind, key = ("Container", "Status") if step == 1 else ("Customer_Order", "Type")
        table = log.objects[kind]
        if step > 1:
            goods = table["Amount_of_Goods"]
            table = table[goods >= 1000] if step == 2 else table[goods < 1000]
        codes = edges.entity_codes(kind, table["id"].astype(str).tolist())
        free = edges.holder[codes] == FREE
        return codes[free], table[key].astype(str).to_numpy()[free]
    free = edges.free_events()
    times = edges.events["timestamp"].iloc[free]
    chosen = free[(times <= CUTOFF).to_numpy() if step == 4 else (times > CUTOFF).to_numpy()]
    names = edges.events["activity"].iloc[chosen].astype(str).to_numpy(dtype=object)
    if step == 5:
        return chosen, names
    corr = edges.corr[edges.types[edges.corr["entity"].to_numpy()] == "Customer_Order"]
    pairs = pd.DataFrame(
        {"event": corr["event"].to_numpy(), "value": edges.standing(corr["entity"].to_numpy())}
    ).astype({"value": str})
    pairs = pairs.drop_duplicates().sort_values(["event", "value"])
    orders = pairs.groupby("event")["value"].agg(",".join).reindex(chosen).fillna("unknown")
    return chosen, names + "|" + orders.to_numpy(dtype=object)


if __name__ == "__main__":
    sys.exit(main())
