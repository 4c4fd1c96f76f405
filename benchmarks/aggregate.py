"""How fast robotale runs an aggregation specification, against the same steps as plain Cypher.

    python benchmarks/aggregate.py [--sizes 35000 1000000 5000000] [--repeat 3]

Starts a private Neo4j (a temporary robotale home on free ports; the jars come from the usual
cache). For each size it generates a logistics log shaped like OCEAN's published one
(containers, customer orders, forklifts, trucks, vehicles; tests/ekg/ocean_shaped.py),
ingests it with robotale (one entity type per object type) and sets the objects'
attributes, then runs OCEAN's logistics specification of five steps (two entity steps
splitting the orders by a where, an event step grouped by activity and the orders'
aggregates, a time-split event step; attributes with MULTISET, AVG, MINMAX, SUM, MIN, MAX):

- robotale: ``robotale.ekg.steps.run_spec`` (nodes read and grouped in pandas, aggregates
  and memberships written in batches, the log's edges read once and lifted in memory, the
  lifted edges written in batches);
- plain: the same steps as the field writes them, one ``MATCH ... CREATE`` per step, then
  (as OCEAN relates its classes once, after its steps) one query per step and kind of
  lifted edge, the edges created in batches (``CALL ... IN TRANSACTIONS``) so a million
  events fit the server's limit on a transaction's memory
  (``benchmarks/aggregate_plain.cypher``).

Both write the lifted edges of the level the five steps end at, one per pair of ends, kind
(and entity type, for DF) with its count, each owned by the later step of its two ends.

Interleaved (robotale, plain, robotale, plain ...), the best of ``--repeat`` each (wall time,
and CPU time of this process and Neo4j's, which a busy shared machine does not inflate), every
output (the aggregates with all their properties, every lifted edge with its count, read one
aggregate at a time) checked equal, the graph restored between runs. After each robotale run
it prints robotale's parts (wall and CPU time of each, timed by wrapping robotale's own
functions) and the floor of its largest part: as many relationships between the same ends,
with a lifted edge's properties, written by a trivial ``UNWIND ... CREATE``
(``cypher/aggr_bound_edges.cypher``) in robotale's batches. Printed beside: OCEAN's
published figures (its logistics log of 35k events in 1.9 s; BPIC17, 1.2M events and 224k
entities, in 28.6 s).
Targets: robotale at least 3x the plain queries; a 1.2M-event specification of five steps
under 15 s.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import pandas as pd

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests" / "ekg"))
from ekg_build import private_neo4j  # noqa: E402
from ocean_shaped import LOGISTICS_SPEC, logistics  # noqa: E402
from whole_ingest import process_cpu  # noqa: E402

from robotale.ekg import lift, steps, writelock  # noqa: E402
from robotale.ekg.build import build_ekg  # noqa: E402
from robotale.ekg.connection import database  # noqa: E402
from robotale.ekg.load import Loader  # noqa: E402
from robotale.ekg.spec import parse_spec  # noqa: E402
from robotale.ekg.steps import run_spec, undo  # noqa: E402
from robotale.eventlog.readers import read_csv  # noqa: E402
from robotale.queries import split_statements, statements  # noqa: E402

OCEAN = {35_413: 1.9, 1_200_000: 28.6}  # events -> seconds, OCEAN's paper
CUTOFF = pd.Timestamp("2024-03-01T00:00:00Z").to_pydatetime()
PLAIN = split_statements((HERE / "aggregate_plain.cypher").read_text(), comments=True)


def plain(name: str) -> list[str]:
    """The statements of aggregate_plain.cypher with a comment line starting with ``name``."""
    return [s for s in PLAIN if re.search(rf"^// {re.escape(name)}", s, re.MULTILINE)]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[35_000])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each, the best counts")
    parser.add_argument("--heap", default="3g", help="heap of the private Neo4j (3g)")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    neo4j = private_neo4j(args.heap)
    with neo4j as driver:
        for size in args.sizes:
            measure(driver, size, args.repeat, neo4j.server.running().pid)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


def measure(driver, size: int, repeat: int, server: int) -> None:
    """``server``: the pid of the Neo4j process, whose CPU time is counted with ours."""
    name = f"logistics_{size}"
    started = time.perf_counter()
    ingest(driver, size, name)
    print(f"\n{size:,} events: generated and ingested in {time.perf_counter() - started:.0f} s")
    spec = parse_spec(LOGISTICS_SPEC)
    times: dict[str, list[float]] = {"robotale": [], "plain": []}
    cpu: dict[str, list[float]] = {"robotale": [], "plain": []}
    outputs: dict[str, object] = {}
    runs: dict[str, Callable[[], None]] = {
        "robotale": lambda: run_spec(driver, name, spec),
        "plain": lambda: run_plain(driver, name),
    }
    for _ in range(repeat):
        for kind, run in runs.items():  # interleaved: robotale, plain, robotale, plain ...
            with timed_parts(server) as parts:
                began, spent = time.perf_counter(), cpu_seconds(server)
                run()
                times[kind].append(time.perf_counter() - began)
                cpu[kind].append(cpu_seconds(server) - spent)
            found = output(driver, name)
            if outputs.setdefault(kind, found) != found:
                raise SystemExit(f"{kind} wrote something else on a second run")
            if kind == "robotale":
                print(f"  robotale's parts, wall/CPU s: {parts.line()}")
                print_bound(driver, name, server, parts.spent["creating the lifted edges"])
            undo(driver, name, 1) if kind == "robotale" else clear(driver, name)
        print(f"  load {os.getloadavg()[0]:.1f}: " + ", ".join(
            f"{k} {v[-1]:.2f} s (CPU {cpu[k][-1]:.2f} s)" for k, v in times.items()))  # fmt: skip
    if outputs["robotale"] != outputs["plain"]:
        raise SystemExit("robotale and the plain queries wrote different aggregates or edges")
    aggregates, edges = outputs["robotale"]  # type: ignore[misc]
    best = {k: min(v) for k, v in times.items()}
    print(f"  outputs equal: {len(aggregates):,} aggregates, {len(edges):,} lifted edges")
    ratio = best["plain"] / best["robotale"]
    print(f"  best of {repeat}: robotale {best['robotale']:.2f} s, plain Cypher "
          f"{best['plain']:.2f} s: {ratio:.1f}x (target 3x)")  # fmt: skip
    least = {k: min(v) for k, v in cpu.items()}
    ratio = least["plain"] / least["robotale"]
    print(
        f"  least CPU (this process and Neo4j) of {repeat}: robotale "
        f"{least['robotale']:.2f} s, plain Cypher {least['plain']:.2f} s: {ratio:.1f}x"
    )
    if size >= 1_000_000:
        scaled = best["robotale"] * 1_200_000 / size
        print(
            f"  robotale scaled to 1.2M events: {scaled:.1f} s (target < 15 s), CPU "
            f"{least['robotale'] * 1_200_000 / size:.1f} s"
        )
    for events, seconds in OCEAN.items():
        print(f"  OCEAN's published figure: {events:,} events in {seconds} s (its machine)")


#: robotale's parts timed in each of its runs: (label, owner, attribute)
PARTS = [
    ("reading the copy and deriving its edges", lift.LogEdges, "of_log"),
    # the lock's transaction: the run's checks, its Log node's build, the entities' keys
    ("the lock and the run's reads", writelock, "_take"),
    ("reading entities", steps, "_read_nodes"),
    ("events and their where", steps, "_event_nodes"),
    ("grouping", steps, "aggregate_table"),
    ("member lists", steps, "_write_members"),
    ("lifting in memory", lift.LogEdges, "lift_level"),
    ("creating the lifted edges", steps, "_write_lifted"),
    # a part of the one above: the one read of the element ids of the edges' free ends
    ("(of which the ends' element ids)", lift.LogEdges, "_read_stored"),
]


class timed_parts:
    """Wraps robotale's functions named in :data:`PARTS` with timers (wall, and CPU of this
    process and Neo4j) while a run lasts."""

    def __init__(self, server: int) -> None:
        self.server = server
        self.spent: dict[str, list[float]] = {label: [0.0, 0.0] for label, _, _ in PARTS}

    def __enter__(self) -> timed_parts:
        self.saved = [(owner, name, getattr(owner, name)) for _, owner, name in PARTS]
        for (label, owner, name), (_, _, function) in zip(PARTS, self.saved, strict=True):
            setattr(owner, name, self._timer(label, function))
        return self

    def __exit__(self, *exc: object) -> None:
        for owner, name, function in self.saved:
            setattr(owner, name, function)

    def _timer(self, label: str, function):
        """A plain function in ``function``'s place: on a class it is bound as the instance
        method was, and a classmethod taken from the class is already bound."""
        spent, server = self.spent[label], self.server

        def timed(*args, **kwargs):
            began, cpu = time.perf_counter(), cpu_seconds(server)
            try:
                return function(*args, **kwargs)
            finally:
                spent[0] += time.perf_counter() - began
                spent[1] += cpu_seconds(server) - cpu

        return timed

    def line(self) -> str:
        return "; ".join(f"{k} {w:.1f}/{c:.1f}" for k, (w, c) in self.spent.items())


def cpu_seconds(server: int) -> float:
    """CPU seconds this process and the Neo4j process ``server`` have used so far: on a
    shared machine wall time also counts the others' work."""
    own = os.times()
    return own.user + own.system + process_cpu(server)


def ingest(driver, size: int, name: str) -> None:
    log = logistics(size)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "events.csv"
        log.events.to_csv(path, index=False)
        events = read_csv(path)
    build_ekg(driver, events, name, entities=log.types, replace=True, progress=False)
    [query] = plain("attributes")
    for kind, table in log.objects.items():
        rows = table.to_dict("records")
        for start in range(0, len(rows), 10_000):
            driver.execute_query(
                query, rows=rows[start : start + 10_000], log=name, type=kind, database_=database()
            )


def run_plain(driver, name: str) -> None:
    """The five steps, then their lifted edges (auto-commit: the edges go in batches)."""
    with driver.session(database=database()) as session:
        for step in range(1, 6):
            for statement in plain(f"step {step}:"):
                session.run(statement, log=name, cutoff=CUTOFF).consume()
        for step in range(1, 6):
            for statement in plain("lift:"):
                session.run(statement, log=name, step=step).consume()


def output(driver, name: str) -> tuple[list, list]:
    """Every aggregate (all properties, times as Unix nanoseconds, floats to 9 digits) and
    every lifted edge, sorted; the edges read one aggregate at a time, streamed."""
    [nodes] = plain("output: every aggregate")
    out, into = plain("output: every lifted edge")
    records, _, _ = driver.execute_query(nodes, log=name, database_=database())
    aggregates = sorted(tuple(sorted((k, comparable(v)) for k, v in r["a"].items()))
                        for r in records)  # fmt: skip
    lifted = []
    with driver.session(database=database()) as session:
        for aggregate in [r["element"] for r in records]:
            for query in (out, into):
                for r in session.run(query, log=name, aggregate=aggregate):
                    lifted.append(tuple((k, "" if v is None else v) for k, v in r.items()))
    return aggregates, sorted(lifted)


def print_bound(driver, name: str, server: int, writing: list[float]) -> None:
    """Neo4j's own rate for the lifted edges just written: as many relationships between the
    same ends, with a lifted edge's properties, written by a trivial ``UNWIND ... CREATE``
    (``cypher/aggr_bound_edges.cypher``) in robotale's batches; robotale's undo removes them."""
    [nodes] = plain("output: every aggregate")
    [ends] = plain("ends:")
    records, _, _ = driver.execute_query(nodes, log=name, database_=database())
    sources: list[str] = []
    targets: list[str] = []
    with driver.session(database=database()) as session:
        for aggregate in [r["element"] for r in records]:
            for r in session.run(ends, log=name, aggregate=aggregate):
                sources.append(r["source"])
                targets.append(r["target"])
    loader = Loader(driver, name, workers=steps.LIFT_WORKERS)
    began, spent = time.perf_counter(), cpu_seconds(server)
    loader.run("aggr_bound_edges", {"sources": sources, "targets": targets,
                                    "counts": [1] * len(sources)}, step=0)  # fmt: skip
    wall, cpu = time.perf_counter() - began, cpu_seconds(server) - spent
    print(
        f"  floor, load {os.getloadavg()[0]:.1f}: {len(sources):,} relationships between the "
        f"same ends by trivial UNWIND CREATE in {wall:.1f} s (CPU {cpu:.1f} s); robotale "
        f"created its lifted edges in {writing[0]:.1f} s (CPU {writing[1]:.1f} s): "
        f"{writing[0] / wall:.2f}x the floor's wall, {writing[1] / cpu:.2f}x its CPU"
    )


def comparable(value: object) -> object:
    if hasattr(value, "to_native") and hasattr(value, "nanosecond"):
        return pd.Timestamp(value.iso_format()).value  # a time: the same instant in any zone
    if isinstance(value, float):
        return float(f"{value:.9g}")
    if isinstance(value, list):
        return tuple(value)
    return value


def clear(driver, name: str) -> None:
    """Remove the plain queries' aggregates as robotale's undo does (batched: auto-commit)."""
    with driver.session(database=database()) as session:
        for statement in statements("aggr_undo"):
            session.run(statement, log=name, step=1).consume()


if __name__ == "__main__":
    sys.exit(main())
