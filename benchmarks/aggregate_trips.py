"""Every round trip of one aggregation run at a size, with the server's time for each.

    python benchmarks/aggregate_trips.py [--size 35000] [--runs 2] [--ab]

Starts a private Neo4j as ``benchmarks/aggregate.py`` does, ingests the OCEAN-shaped
logistics log and runs its specification ``--runs`` times (undone between runs; the first
run warms the plan cache). For each query sent it prints the cypher file it comes from,
the rows sent (the longest list parameter), whether rows came back, the server's
``result_available_after`` and ``result_consumed_after`` (ms) and the client's wait from
sending to the summary; a commit is a round trip of its own and is printed as one.

With ``--ab`` the runs alternate between robotale as it is (B) and its round-trip structure
before the reads' commits were dropped, a small step's lifted edges were written one batch
per worker and the entity steps' reads were started beside the columnar copy's (A, restored
by replacing those functions; ``--before`` names which of them), each run's output checked
equal to the first's; each run's wall time, its process's and Neo4j's CPU time and the load
are printed, and the best of each.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from importlib.resources import files
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from aggregate import Limits, cpu_seconds, generate, ingest, output, private_server  # noqa: E402
from neo4j._sync.work import result as neo4j_result  # noqa: E402
from neo4j._sync.work import transaction as neo4j_transaction  # noqa: E402

from robotale.ekg import lift, steps  # noqa: E402
from robotale.ekg.connection import connect, database  # noqa: E402
from robotale.ekg.load import BATCH  # noqa: E402
from robotale.ekg.spec import parse_spec  # noqa: E402
from robotale.ekg.steps import run_spec, undo  # noqa: E402
from robotale.queries import statements  # noqa: E402

sys.path.insert(0, str(HERE.parent / "tests" / "ekg"))
from ocean_shaped import LOGISTICS_SPEC  # noqa: E402

TRIPS: list[list[object]] = []
_LOCK = threading.Lock()


def query_names() -> dict[str, str]:
    """The first non-comment line of each cypher file -> its name."""
    folder = files("robotale.cypher")
    found: dict[str, str] = {}
    for entry in sorted(folder.iterdir(), key=lambda e: e.name):
        if entry.name.endswith(".cypher"):
            for statement in statements(entry.name[: -len(".cypher")]):
                found[statement.strip()] = entry.name[: -len(".cypher")]
    return found


def name_of(text: str, names: dict[str, str]) -> str:
    from robotale.queries import split_statements

    parts = split_statements(text, comments=False)
    found = names.get(parts[0].strip()) if parts else None
    if found:
        return found
    for statement, name in names.items():  # a step's where put in: the text before it
        if parts and statement[:100] == parts[0].strip()[:100]:
            return name
    return text.strip().splitlines()[0][:50]


def rows_sent(parameters: object) -> int:
    if not isinstance(parameters, dict):
        return 0
    lengths = [len(v) for v in parameters.values() if isinstance(v, list)]
    for v in parameters.values():
        if isinstance(v, dict):
            lengths += [len(x) for x in v.values() if isinstance(x, list)]
    return max(lengths, default=0)


def instrument(names: dict[str, str]) -> None:
    original_run = neo4j_result.Result._run
    original_warn = neo4j_result.Result._handle_warnings
    original_commit = neo4j_transaction.TransactionBase._commit

    def run(self, query, parameters, *rest):  # type: ignore[no-untyped-def]
        self._trip = [name_of(str(query), names), rows_sent(parameters), time.perf_counter()]
        return original_run(self, query, parameters, *rest)

    def warn(self) -> None:  # type: ignore[no-untyped-def]
        trip = getattr(self, "_trip", None)
        if trip is not None:
            meta = self._metadata
            with _LOCK:
                TRIPS.append(
                    [
                        *trip[:2],
                        self._had_record,
                        meta.get("t_first"),
                        meta.get("t_last"),
                        (time.perf_counter() - trip[2]) * 1000,
                    ]
                )
        return original_warn(self)

    def commit(self):  # type: ignore[no-untyped-def]
        began = time.perf_counter()
        try:
            return original_commit(self)
        finally:
            with _LOCK:
                TRIPS.append(["COMMIT", 0, False, None, None, (time.perf_counter() - began) * 1000])

    neo4j_result.Result._run = run
    neo4j_result.Result._handle_warnings = warn
    neo4j_transaction.TransactionBase._commit = commit


def read_with_commit(driver, query, parameters):  # type: ignore[no-untyped-def]
    """A read as before: a managed transaction (its query, then its commit)."""
    records, _, _ = driver.execute_query(query, parameters, database_=database())
    return records


NOW = (steps.read_autocommit, lift.read_autocommit, steps._lift_batch, steps._start_entity_reads)
BEFORE = (read_with_commit, read_with_commit, lambda edges: BATCH, lambda *_: {})
#: which of BEFORE's functions ``--before`` names
PARTS = {"reads": (0, 1), "lift": (2,), "prefetch": (3,)}


def before(parts: list[str]) -> tuple:  # type: ignore[type-arg]
    """NOW with the functions of ``parts`` as they were."""
    chosen = {i for part in parts for i in PARTS[part]}
    return tuple(BEFORE[i] if i in chosen else NOW[i] for i in range(len(NOW)))


def use(functions) -> None:  # type: ignore[no-untyped-def]
    (steps.read_autocommit, lift.read_autocommit, steps._lift_batch, steps._start_entity_reads) = (
        functions
    )


def print_trips() -> None:
    print(f"  {'query':32} {'sent':>6} {'rows':>5} {'avail':>6} {'cons':>6} {'wait':>7}")
    for q, sent, had, first, last, wait in TRIPS:
        print(
            f"  {q:32} {sent:6} {'yes' if had else '':>5} "
            f"{first if first is not None else '':>6} "
            f"{last if last is not None else '':>6} {wait:7.1f}"
        )
    print(f"  total client wait {sum(t[5] for t in TRIPS) / 1000:.2f} s")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=35_000)
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--ab", action="store_true", help="alternate before (A) and now (B)")
    parser.add_argument(
        "--before",
        default="reads,lift,prefetch",
        help="what A puts back, of reads, lift, prefetch (all)",
    )
    args = parser.parse_args()
    sys.stdout.reconfigure(line_buffering=True)  # type: ignore[union-attr]
    with private_server("3g", "2g") as server:
        name = f"logistics_{args.size}"
        types = generate(server.work, args.size)
        if not ingest(server, args.size, name, types, Limits(3600, 1024**3)):
            return 1
        instrument(query_names())
        driver = connect(server.settings())
        try:
            first = None
            best: dict[str, list[float]] = {}
            for turn in range(args.runs * (2 if args.ab else 1)):
                side = ("A" if turn % 2 == 0 else "B") if args.ab else "B"
                use(before(args.before.split(",")) if side == "A" else NOW)
                TRIPS.clear()
                began, cpu = time.perf_counter(), cpu_seconds(server.pid())
                own = sum(os.times()[:2])
                run_spec(driver, name, parse_spec(LOGISTICS_SPEC))
                wall, cpu = time.perf_counter() - began, cpu_seconds(server.pid()) - cpu
                own = sum(os.times()[:2]) - own
                trips = len(TRIPS)
                best.setdefault(side, []).append(wall)
                print(
                    f"\nrun {turn + 1} ({side}): {wall:.2f} s, CPU {cpu:.2f} s (this process "
                    f"{own:.2f} s), load {os.getloadavg()[0]:.1f}; {trips} round trips"
                )
                if not args.ab or turn < 2:
                    print_trips()
                found = output(driver, name)
                first = first or found
                if found != first:
                    raise SystemExit("the output differs from the first run's")
                print(f"  output: {len(found[0])} aggregates, {found[1]:,} lifted edges, equal")
                TRIPS.clear()
                undo(driver, name, 1)
            for side, walls in sorted(best.items()):
                print(
                    f"best of {side}: {min(walls):.2f} s ({', '.join(f'{w:.2f}' for w in walls)})"
                )
        finally:
            driver.close()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
