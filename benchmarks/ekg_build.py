"""How fast robotale builds an event knowledge graph in Neo4j.

    python benchmarks/ekg_build.py [--sizes 100000 1000000] [--baseline-sizes 20000 100000]
    python benchmarks/ekg_build.py --whole-command --sizes 100000 1000000 10000000
        [--build auto|online|bulk] [--promg-server stock|robotale]
    python benchmarks/ekg_build.py --df-c-only --sizes 100000 1000000 [--repeat 5]

``--whole-command`` times whole ``robotale ingest`` processes against PromG's whole build
instead (``benchmarks/whole_ingest.py``). Otherwise:

Starts a private Neo4j (a temporary robotale home on free ports; the jars come from the
usual cache) and, in the same run:

1. builds synthetic logs of the given sizes with three entity types (case, robot, msg_id) and
   an activity aggregation, and reports events/s for the whole build (events, entities, CORR,
   DF, COMM, Class, OBSERVED, DF_C, BEGINS). Targets on a 2-core machine: 100k events in
   under 10 s, 1M in under 90 s. Beside each, Neo4j's own write rate on the same machine in the
   same run: as many nodes (with as many properties as an event) and relationships written by
   trivial ``UNWIND ... CREATE`` batches (``cypher/ekg_bound_*``): nodes first, then every
   relationship between two stored nodes, with no index, constraint or computed value.
   A build that writes most of its edges in the transaction that creates their ends can
   beat it;
2. builds logs of the ``--baseline-sizes`` once with the thesis' own Cypher (section 7.1.2:
   one query creating every event, per-event MERGE of entities and CORR edges, DF edges by
   collecting each entity's events) and once with robotale, and prints robotale's speed as a
   ratio to the thesis' (target: at least 5x at 20k and at 100k). The thesis' queries get
   ``--thesis-limit`` seconds per size; a size they cannot finish in that time is reported
   as such, with a quadratic extrapolation from the largest size they finished, labelled as
   an extrapolation. The events, entities, CORR and DF edges of each finished thesis build
   are counted against robotale's and the differences printed (the thesis' DF crosses runs);
3. times the directly-follows counts by activity as an ingest computes them, from the event
   table (DF edges, classes, DF_C) against ``pm4py.discover_dfg`` on the same DataFrame with
   each robot's flow in each run as a case, interleaved, wall and CPU time, the two DFGs
   checked equal (target: at most 1.5x), and the Cypher aggregation a stored log gets for a
   key it was not ingested with;
4. ingests the smallest size as one log and as ten appends of a tenth of its runs each, and
   prints both times and their ratio;
5. builds the smallest size with one batch in flight and with two (parallel transactions,
   the default) and prints the ratio.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import importer_bound
import numpy as np
import pandas as pd

from robotale.eventlog import schema

ACTIVITIES = ["explore", "move", "cut_grass", "scan", "charge", "wait", "dock", "report"]
MESSAGES = ["weed_position", "tractor_position", "closest_tractor"]


def synthetic_log(events: int, seed: int = 7) -> pd.DataFrame:
    """A multi-robot log: 100 events per case, 10 robots, a third of events exchange messages.

    Every message is one send (``name!``) and two receives (``name?``) by other robots.
    """
    rng = np.random.default_rng(seed)
    triples = events // 9  # a third of the events are in send/receive/receive triples
    singles = events - 3 * triples
    kinds = np.concatenate([np.zeros(singles, int), np.ones(triples, int)])
    rng.shuffle(kinds)
    rows_activity, rows_robot, rows_msg = [], [], []
    robots = np.array([f"robot_{i}" for i in range(10)])
    for message, kind in enumerate(kinds):
        if kind == 0:
            rows_activity.append(ACTIVITIES[rng.integers(len(ACTIVITIES))])
            rows_robot.append(robots[rng.integers(10)])
            rows_msg.append(None)
        else:
            name = MESSAGES[rng.integers(len(MESSAGES))]
            sender, *receivers = rng.choice(10, size=3, replace=False)
            rows_activity += [f"{name}!", f"{name}?", f"{name}?"]
            rows_robot += [robots[sender], robots[receivers[0]], robots[receivers[1]]]
            rows_msg += [f"m{message}"] * 3
    size = len(rows_activity)
    gaps = rng.exponential(2.0, size)
    start = pd.Timestamp("2024-03-01T08:00:00+01:00")
    return pd.DataFrame(
        {
            schema.CASE: (np.arange(size) // 100).astype(str),
            schema.TIMESTAMP: start + pd.to_timedelta(np.cumsum(gaps), unit="s"),
            schema.ACTIVITY: rows_activity,
            schema.LIFECYCLE: "complete",
            schema.ROBOT: rows_robot,
            schema.MSG_ID: pd.array(rows_msg, dtype="string"),
            schema.X: rng.random(size) * 10,
            schema.Y: rng.random(size) * 10,
            schema.BATTERY: 100 - rng.random(size) * 50,
            schema.EVENT_ID: [f"e{i}" for i in range(size)],
        }
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--baseline-sizes", type=int, nargs="+", default=[20_000, 100_000])
    parser.add_argument(
        "--thesis-limit",
        type=float,
        default=600.0,
        help="seconds the thesis' queries get per size before they are stopped (600)",
    )
    parser.add_argument("--heap", default="3g", help="heap of the private Neo4j (3g)")
    parser.add_argument(
        "--repeat",
        type=int,
        default=3,
        help="runs per figure up to 100k events, the best counts (3)",
    )
    parser.add_argument(
        "--whole-command",
        action="store_true",
        help="time whole `robotale ingest` processes against PromG's whole build instead "
        "(benchmarks/whole_ingest.py)",
    )
    parser.add_argument(
        "--promg-venv",
        type=Path,
        help="with --whole-command: a virtual environment with PromG (none: robotale's side "
        "only; default: one is made)",
    )
    parser.add_argument(
        "--pages",
        default="background",
        choices=("background", "visit"),
        help="with --whole-command: when the ingests prepare the dashboard's pages; "
        "background (the default) awaits that process after each ingest, visit prepares none "
        "(the command's own time is the same: it never waits for them)",
    )
    parser.add_argument(
        "--build",
        default="auto",
        choices=("auto", "online", "bulk"),
        help="with --whole-command: the ingests' --build (auto, the default, as a user runs it)",
    )
    parser.add_argument(
        "--promg-server",
        default="stock",
        choices=("stock", "robotale"),
        help="with --whole-command: PromG's server as its users run it (stock: Neo4j's own "
        "launcher and stock neo4j.conf, the default) or started by robotale's code (robotale's "
        "JVM options); both with robotale's server's heap and page cache",
    )
    parser.add_argument(
        "--df-c-only",
        action="store_true",
        help="only part 3, at each of --sizes: directly-follows counts against pm4py",
    )
    args = parser.parse_args()
    if args.whole_command:
        from whole_ingest import main as whole_command

        return whole_command(
            args.sizes,
            max(args.repeat, 1),
            args.heap,
            args.promg_venv,
            args.pages,
            args.build,
            args.promg_server,
        )
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    if args.df_c_only:
        with private_neo4j(args.heap) as driver:
            for size in args.sizes:
                compare_df_c_with_pm4py(driver, size, args.repeat)
        print(f"load average after: {os.getloadavg()[0]:.1f}")
        return 0
    neo4j = private_neo4j(args.heap)
    with neo4j as driver:
        # Neo4j compiles each query once and its JIT warms up: measure a warm server.
        timed_build(driver, synthetic_log(10_000), "warmup", ["case", "robot", "msg_id"])
        for size in args.sizes:
            measure_build(driver, size, args.repeat if size <= 100_000 else 1)
        finished: tuple[int, float] | None = None
        spent = cpu_spent(neo4j.pid)
        for size in args.baseline_sizes:
            finished = compare_with_thesis(
                driver, size, args.repeat, args.thesis_limit, finished, spent
            )
        compare_df_c_with_pm4py(driver, min(args.sizes), args.repeat)
        compare_appends(driver, min(args.sizes), parts=10)
        compare_workers(driver, min(args.sizes))
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 0


class private_neo4j:
    """A Neo4j for this benchmark only, started in a temporary home and stopped at the end."""

    def __init__(self, heap: str) -> None:
        self.heap = heap

    def __enter__(self):
        from robotale.ekg.connection import Settings, connect
        from robotale.neo4j_server.server import LocalServer, ServerOptions, free_port

        self.home = tempfile.TemporaryDirectory(prefix="robotale-bench-")
        self.server = LocalServer(Path(self.home.name))
        options = ServerOptions(free_port(), free_port(), heap=self.heap, pagecache="2g")
        running = self.server.start(options)
        self.pid = running.pid
        password = self.server.password() or ""
        self.driver = connect(Settings(running.bolt_uri, "neo4j", password, True))
        os.environ.update(NEO4J_URI=running.bolt_uri, NEO4J_PASSWORD=password)
        return self.driver

    def __exit__(self, *exc: object) -> None:
        self.driver.close()
        self.server.stop()
        self.home.cleanup()


def timed_build(
    driver,
    log: pd.DataFrame,
    name: str,
    entities: list[str],
    aggregate: tuple[str, ...] = ("activity",),
    cpus: list[float] | None = None,
    spent: Callable[[], float] | None = None,
):
    """Build, time and delete one log; returns (seconds, summary). With ``spent`` (see
    :func:`cpu_spent`), the build's CPU seconds are added to ``cpus``."""
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log

    cpu = spent() if spent else 0.0
    started = time.perf_counter()
    summary = build_ekg(
        driver, log, name, entities=entities, aggregate=list(aggregate), progress=False
    )
    seconds = time.perf_counter() - started
    if spent is not None and cpus is not None:
        cpus.append(spent() - cpu)
    delete_log(driver, name)
    return seconds, summary


def cpu_spent(pid: int) -> Callable[[], float]:
    """CPU seconds so far of this process and of the Neo4j server ``pid``: a build's client
    and server together, as both sides of a comparison spend them."""
    from robotale.timings import process_seconds

    return lambda: time.process_time() + (process_seconds(pid) or 0.0)


def measure_build(driver, size: int, repeat: int) -> None:
    log = synthetic_log(size)
    runs = [
        timed_build(driver, log, f"bench{size}", ["case", "robot", "msg_id"]) for _ in range(repeat)
    ]
    seconds, summary = min(runs, key=lambda run: run[0])
    edges = summary.corr + sum(summary.df.values()) + summary.comm + len(log)  # + OBSERVED
    target = {100_000: "; target: under 10 s", 1_000_000: "; target: under 90 s"}.get(size, "")
    print(
        f"whole build of {len(log):>9,} events ({edges:,} CORR/DF/COMM/OBSERVED edges): "
        f"{seconds:6.1f} s, {len(log) / seconds:,.0f} events/s "
        f"(best of {repeat}{target})"
    )
    nodes = len(log) + sum(summary.entities.values())
    plain = min(plain_writes(driver, nodes, event_properties(log), edges) for _ in range(repeat))
    print(
        f"  Neo4j's own write rate, same run: {nodes:,} nodes with "
        f"{event_properties(log)} properties each and {edges:,} relationships by trivial "
        f"UNWIND ... CREATE batches: {plain:6.1f} s; the build takes {seconds / plain:.2f}x that"
    )
    importer_bound.print_bound(nodes, event_properties(log), edges, seconds)


def event_properties(log: pd.DataFrame) -> int:
    """The properties an event node gets on average: its non-null cells, log and order."""
    return round(log.notna().to_numpy().sum() / len(log)) + 2


def plain_writes(driver, nodes: int, properties: int, edges: int) -> float:
    """Seconds Neo4j takes to write ``nodes`` nodes of ``properties`` properties, then ``edges``
    relationships between them, in the build's batches, with nothing to compute or index:
    the plain write rate of that graph on this server."""
    from robotale.ekg.load import Loader
    from robotale.queries import cypher

    values = {f"p{k}": k for k in range(properties)}
    loader = Loader(driver, "bound")
    started = time.perf_counter()
    created = np.asarray(
        loader.run("ekg_bound_nodes", {"rows": [0] * nodes}, properties=values), dtype=object
    )
    at = np.arange(edges)
    loader.run(
        "ekg_bound_edges",
        {
            "sources": created[at % nodes].tolist(),
            "targets": created[(at * 7 + 1) % nodes].tolist(),
        },
    )
    seconds = time.perf_counter() - started
    with driver.session() as session:
        session.run(cypher("ekg_bound_cleanup")).consume()
    return seconds


def compare_with_thesis(
    driver,
    size: int,
    repeat: int,
    limit: float,
    finished: tuple[int, float] | None,
    spent: Callable[[], float] | None = None,
) -> tuple[int, float] | None:
    """Print robotale against the thesis' queries at ``size`` events; returns the largest
    (size, seconds) the thesis' queries finished, for extrapolating beyond it. With
    ``spent`` (:func:`cpu_spent`) the CPU time of the same work is printed beside."""
    log = synthetic_log(size)
    entities = ["case", "robot", "msg_id"]
    repeat = repeat if size <= 20_000 else 1
    ours, theirs, graphs = [], [], []
    our_cpus: list[float] = []
    their_cpus: list[float] = []
    for _ in range(repeat):  # in turns (A B A B), so a busy machine slows both alike
        same, summary = timed_build(
            driver, log, "bench_same", entities, aggregate=(), cpus=our_cpus, spent=spent
        )
        ours.append((same, timed_build(driver, log, "bench_whole", entities)[0]))
        theirs.append(thesis_build(driver, log, entities, limit, graphs, their_cpus, spent))
    differ = [d for graph in graphs for d in same_graph(built_counts(log, summary), graph)]
    same_work, whole = (min(times) for times in zip(*ours, strict=True))
    if None in theirs:
        if finished is None:
            print(f"thesis Cypher, {len(log):,} events: stopped after {limit:.0f} s")
            return finished
        done, seconds = finished
        thesis = seconds * (len(log) / done) ** 2
        note = (
            f"stopped after {limit:.0f} s; EXTRAPOLATED quadratically from its "
            f"{seconds:.1f} s at {done:,} events: ~{thesis:.0f} s"
        )
    else:
        thesis = min(t for t in theirs if t is not None)
        finished = (len(log), thesis)
        note = f"{thesis:.1f} s"
    print(
        f"thesis Cypher, {len(log):,} events (events, entities, CORR, DF): {note}; "
        f"robotale, same work (+COMM): {same_work:.1f} s = {thesis / same_work:.1f}x faster; "
        f"robotale, whole build (+Class, OBSERVED, DF_C, BEGINS): {whole:.1f} s = "
        f"{thesis / whole:.1f}x faster (target >= 5x; interleaved, best of {repeat} each; "
        f"the same entity types {', '.join(entities)} on both sides; load average "
        f"{os.getloadavg()[0]:.1f})"
    )
    said = "; ".join(dict.fromkeys(differ)) if differ else "the same"
    print(f"  events, entities, CORR and DF of the {len(graphs)} finished thesis builds: {said}")
    if our_cpus and their_cpus:
        mine, other = min(our_cpus), min(their_cpus)
        print(
            f"  CPU (this process and the Neo4j server, best of each): thesis Cypher "
            f"{other:.1f} s, robotale same work {mine:.1f} s = {other / mine:.1f}x"
        )
    return finished


SAME_WORK = ("events", "entities", "corr", "df")


def built_counts(log: pd.DataFrame, summary) -> dict[str, int]:
    """robotale's events, entities, CORR and DF edges, from its build's summary."""
    entities, df = sum(summary.entities.values()), sum(summary.df.values())
    return {"events": len(log), "entities": entities, "corr": summary.corr, "df": df}


def same_graph(ours: dict[str, int], theirs: dict[str, int]) -> list[str]:
    """Where robotale's graph and the thesis' differ in SAME_WORK's counts (empty: none)."""
    return [
        f"{what}: robotale {ours[what]:,}, thesis {theirs[what]:,}"
        for what in SAME_WORK
        if ours[what] != theirs[what]
    ]


def thesis_build(
    driver,
    log: pd.DataFrame,
    entity_types: list[str],
    limit: float,
    graphs: list | None = None,
    cpus: list[float] | None = None,
    spent: Callable[[], float] | None = None,
) -> float | None:
    """The thesis' queries (section 7.1.2) on an empty database; returns their seconds, or
    None when they took longer than ``limit`` (Neo4j stops them). A finished build's counts
    (``ekg_thesis_counts``) are added to ``graphs`` before it is removed, and with ``spent``
    (:func:`cpu_spent`) its CPU seconds to ``cpus``."""
    from neo4j import Query
    from neo4j.exceptions import Neo4jError

    from robotale.queries import cypher

    short = schema.to_csv_names(log)
    rows = short.astype(object).where(short.notna(), None)
    rows["time"] = log[schema.TIMESTAMP].map(lambda t: t.isoformat())
    records = rows.to_dict("records")
    cpu = spent() if spent else 0.0
    started = time.perf_counter()

    def run(name: str, **parameters) -> None:
        left = limit - (time.perf_counter() - started)
        driver.execute_query(Query(cypher(name), timeout=max(left, 0.001)), parameters)

    try:
        # LOAD CSV ... CREATE (e:Event {...}) per line: here the lines come as a parameter.
        run("ekg_thesis_events", rows=records, log="thesis")
        for entity_type in entity_types:
            run("ekg_thesis_corr", entitytype=entity_type)
            run("ekg_thesis_df", entitytype=entity_type)
        seconds: float | None = time.perf_counter() - started
        if spent is not None and cpus is not None:
            cpus.append(spent() - cpu)
    except Neo4jError as error:
        if "timeout" not in str(error).lower() and "terminated" not in str(error).lower():
            raise
        seconds = None
    if seconds is not None and graphs is not None:
        graphs.append(driver.execute_query(cypher("ekg_thesis_counts")).records[0].data())
    with driver.session() as session:
        session.run(cypher("ekg_thesis_cleanup")).consume()
    return seconds


def robotale_dfg(log: pd.DataFrame) -> dict[tuple[str, str], int]:
    """The directly-follows counts by activity of each robot's flow within each run, as an
    ingest computes them: from the log to DF_C (graph_tables: the checked event table, CORR,
    DF and the activity instances' DF; class_tables: classes, DF_C with counts, means and
    medians, entries). Every event of the synthetic log is a completion, so each is an
    activity instance and pm4py's DFG of the same DataFrame counts the same."""
    from robotale.ekg.tables import class_tables, graph_tables

    classes = class_tables(graph_tables(log, ["robot"]), ["activity"])
    names = classes.classes["id"].to_numpy()
    df_c = classes.df_c
    return {
        (str(names[a]), str(names[b])): int(n)
        for a, b, n in zip(df_c["source"], df_c["target"], df_c["count"], strict=True)
    }


def pm4py_dfg(log: pd.DataFrame) -> dict[tuple[str, str], int]:
    """pm4py's DFG of the same flows: each robot in each run is a case of its own (the
    entity robotale's DF follows), in the log's time order."""
    import pm4py

    flows = log.assign(_flow=log[schema.ROBOT].astype(str) + "|" + log[schema.CASE].astype(str))
    dfg, _, _ = pm4py.discover_dfg(flows, case_id_key="_flow")
    return {(str(a), str(b)): int(n) for (a, b), n in dfg.items()}


def same_dfg(ours: dict, theirs: dict) -> list[str]:
    """Where two DFGs differ (empty: the same edges with the same counts)."""
    return [
        f"{a} -> {b}: {ours.get((a, b), 0)} against {theirs.get((a, b), 0)}"
        for a, b in sorted(set(ours) | set(theirs))
        if ours.get((a, b), 0) != theirs.get((a, b), 0)
    ]


def timed(work) -> tuple[float, float, object]:
    """Wall and CPU seconds of ``work()`` in this process, and its result."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = work()
    return time.perf_counter() - wall, time.process_time() - cpu, result


def compare_df_c_with_pm4py(driver, size: int, repeat: int) -> None:
    """The directly-follows counts by activity as an ingest computes them (pandas, from the
    event table: DF edges, classes, DF_C) against ``pm4py.discover_dfg`` on the same
    DataFrame, interleaved (A B A B), the outputs checked equal; and the Cypher aggregation a
    stored log gets for a key it was not ingested with."""
    from robotale.ekg.aggregate import create_classes, create_df_c
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log

    # without message ids: pairing sends with receives (COMM) is not directly-follows work
    log = synthetic_log(size).drop(columns=[schema.MSG_ID])
    ours, theirs = [], []
    for _ in range(repeat):
        ours.append(timed(lambda: robotale_dfg(log)))
        theirs.append(timed(lambda: pm4py_dfg(log)))
    differences = same_dfg(ours[-1][2], theirs[-1][2])
    build_ekg(driver, log, "bench_df_c", entities=["robot"], aggregate=[], progress=False)
    in_neo4j = []
    for _ in range(repeat):  # create_classes replaces the classes of the run before
        started = time.perf_counter()
        create_df_c(driver, "bench_df_c", create_classes(driver, "bench_df_c", ["activity"]))
        in_neo4j.append(time.perf_counter() - started)
    delete_log(driver, "bench_df_c")
    (wall, cpu), (their_wall, their_cpu) = (
        (min(run[0] for run in runs), min(run[1] for run in runs)) for runs in (ours, theirs)
    )
    check = "same edges and counts" if not differences else f"DIFFERENT: {differences[:3]}"
    print(
        f"{len(log):,} events, each robot's flow per run: directly-follows counts from the "
        f"event table (DF edges, classes, DF_C with counts, means, medians) {wall:.2f} s wall "
        f"{cpu:.2f} s CPU; pm4py.discover_dfg {their_wall:.2f} s wall {their_cpu:.2f} s CPU; "
        f"ratio {wall / their_wall:.1f} wall, {cpu / their_cpu:.1f} CPU (target <= 1.5; "
        f"interleaved, best of {repeat}; {len(ours[-1][2])} edges: {check}); Class, "
        f"OBSERVED, DF_C in Neo4j for a stored log {min(in_neo4j):.2f} s = "
        f"{min(in_neo4j) / their_wall:.1f}x pm4py; load average {os.getloadavg()[0]:.1f}"
    )


def compare_appends(driver, size: int, parts: int) -> None:
    """One ingest of ``size`` events against ``parts`` appends of a share of its runs each."""
    from robotale.ekg.append import append_ekg
    from robotale.ekg.build import build_ekg
    from robotale.ekg.logs import delete_log

    log = synthetic_log(size)
    entities = ["case", "robot", "msg_id"]
    whole, _ = timed_build(driver, log, "bench_once", entities)
    cases = log[schema.CASE].astype(int)
    shares = [log[cases % parts == part] for part in range(parts)]
    started = time.perf_counter()
    build_ekg(driver, shares[0], "bench_appends", entities=entities, progress=False)
    times = [time.perf_counter() - started]
    for share in shares[1:]:
        appended = time.perf_counter()
        append_ekg(driver, share, "bench_appends")
        times.append(time.perf_counter() - appended)
    total = time.perf_counter() - started
    delete_log(driver, "bench_appends")
    print(
        f"{len(log):,} events: one ingest {whole:.1f} s; an ingest of {len(shares[0]):,} and "
        f"{parts - 1} appends of ~{len(shares[1]):,} events {total:.1f} s = {total / whole:.1f}x "
        f"(first {times[0]:.1f} s, appends {min(times[1:]):.1f}-{max(times[1:]):.1f} s)"
    )


def compare_workers(driver, size: int) -> None:
    """The whole build with one transaction at a time against two in flight."""
    from robotale.ekg import load

    log = synthetic_log(size)
    entities = ["case", "robot", "msg_id"]
    default = load.WORKERS
    seconds = {}
    try:
        for workers in (1, 2):
            load.WORKERS = workers
            seconds[workers] = timed_build(driver, log, f"bench_workers{workers}", entities)[0]
    finally:
        load.WORKERS = default
    print(
        f"whole build of {len(log):,} events, one transaction at a time {seconds[1]:.1f} s, "
        f"two in flight {seconds[2]:.1f} s: {seconds[1] / seconds[2]:.2f}x"
    )


if __name__ == "__main__":
    sys.exit(main())
