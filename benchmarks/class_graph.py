"""The class graph a cold dashboard page waits for: read from Neo4j against computed from the
log's columnar copy.

    python benchmarks/class_graph.py [--sizes 10000 100000] [--repeat 5]

Starts a private Neo4j (see ``ekg_build.py``), stores the thesis' runs repeated to each size
as the dashboard stores an upload (entities robot and msg_id, classes by activity and by
activity and robot), then times, in turns (A B A B ...), the class graph by activity and
robot with every entity type's flow as the Discover and Perspectives pages ask for it:

- A, the baseline: :func:`robotale.discovery.ekg.discover_ekg`, the stored Class nodes and
  their DF_C, COMM and BEGINS edges read with four Cypher queries (what a cold page did);
- B: the log's event table read from its columnar copy and the same graph computed from it
  (:func:`robotale.discovery.ekg_table.table_class_graph`, what a cold page does now).

Both answers are checked equal (:func:`differences`: every node and edge, in order; seconds
to nine significant digits, as Neo4j adds them up in another order). Printed: best of N wall
and CPU time of each (CPU: this process and the Neo4j server, read from ``/proc``: on a
shared machine the wall time also counts the others' work), the ratios, and the load
average.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path
from typing import Any

BENCHMARKS = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCHMARKS))

from aggregate import cpu_seconds  # noqa: E402
from dashboard import private_home, store, thesis_runs  # noqa: E402
from ekg_build import private_neo4j  # noqa: E402

KEY = ["activity", "robot"]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[10_000, 100_000])
    parser.add_argument("--repeat", type=int, default=5, help="turns of each side (best of)")
    parser.add_argument("--heap", default="2g", help="heap of the private Neo4j (2g)")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    failed = False
    neo4j = private_neo4j(args.heap)
    with private_home(), neo4j as driver:
        server = neo4j.server.running().pid
        for size in args.sizes:
            name, events = store(driver, f"bench_graph_{size}", thesis_runs(size))
            failed |= not measure(driver, name, events, args.repeat, server)
    print(f"load average after: {os.getloadavg()[0]:.1f}")
    return 1 if failed else 0


def measure(driver, name: str, events: int, repeat: int, server: int) -> bool:
    """A B A B ... ``repeat`` times; prints best wall and CPU (this process and the Neo4j
    process ``server``) of each; True when the two answers are the same."""
    from robotale.discovery.ekg import discover_ekg
    from robotale.discovery.ekg_table import table_class_graph
    from robotale.ekg.columnar import stored_table
    from robotale.ekg.logs import log_info

    types = list(log_info(driver, name)["entityTypes"])

    def neo4j() -> dict[str, Any]:
        return discover_ekg(name, KEY, types, driver=driver).to_dict()

    def table() -> dict[str, Any]:
        return table_class_graph(name, stored_table(driver, name), KEY, types).to_dict()

    times: dict[str, list[tuple[float, float]]] = {"neo4j": [], "table": []}
    answers: dict[str, dict[str, Any]] = {}
    for _ in range(repeat):
        for side, work in (("neo4j", neo4j), ("table", table)):
            cpu, wall = cpu_seconds(server), time.perf_counter()
            answers[side] = work()
            times[side].append((time.perf_counter() - wall, cpu_seconds(server) - cpu))
    found = differences(answers["table"], answers["neo4j"])
    a_wall, b_wall = (min(wall for wall, _ in times[side]) for side in ("neo4j", "table"))
    a_cpu, b_cpu = (min(cpu for _, cpu in times[side]) for side in ("neo4j", "table"))
    print(f"{events:>9,} events: Neo4j queries {a_wall:.3f} s wall, {a_cpu:.3f} s CPU; "
          f"columnar copy {b_wall:.3f} s wall, {b_cpu:.3f} s CPU; {a_wall / b_wall:.1f}x by "
          f"wall, {a_cpu / b_cpu:.1f}x by CPU (best of {repeat}, in turns); "
          f"{len(answers['table']['nodes'])} nodes, "
          f"{len(answers['table']['edges'])} edges; same answer: "
          f"{'yes' if not found else 'NO: ' + '; '.join(found[:3])} (load average "
          f"{os.getloadavg()[0]:.1f})")  # fmt: skip
    return not found


def differences(ours: dict[str, Any], theirs: dict[str, Any]) -> list[str]:
    """Where two class graphs (``ProcessGraph.to_dict()``) differ: their description, each
    node and edge in order, seconds to nine significant digits."""
    found = [] if ours["info"] == theirs["info"] else [f"info {ours['info']} != {theirs['info']}"]
    for part in ("nodes", "edges"):
        if len(ours[part]) != len(theirs[part]):
            found.append(f"{len(ours[part])} {part} against {len(theirs[part])}")
            continue
        for mine, other in zip(ours[part], theirs[part], strict=True):
            if _rounded(mine) != _rounded(other):
                found.append(f"{part[:-1]} {mine} != {other}")
    return found


def _rounded(value: Any) -> Any:
    if isinstance(value, float) and math.isfinite(value) and value != 0:
        return float(f"{value:.9g}")
    if isinstance(value, dict):
        return {key: _rounded(item) for key, item in value.items()}
    if isinstance(value, list):
        return [_rounded(item) for item in value]
    return value


if __name__ == "__main__":
    sys.exit(main())
