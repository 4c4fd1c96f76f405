"""Neo4j's offline bulk importer (``neo4j-admin database import full``) on a graph of a given
shape: the physical bound of a build on this machine.

The importer writes a new database's store files directly, with no transaction, query or
index; a build that ends in the same numbers of nodes, properties and relationships cannot
write them faster. It runs on the jars of the release robotale's local server uses, into a
temporary home of its own, so a running server is never touched.
"""

from __future__ import annotations

import csv
import os
import re
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

# Neo4j's command-line entry point (what the ``neo4j-admin`` script starts).
ADMIN_TOOL = "org.neo4j.cli.AdminTool"


def write_graph(folder: Path, nodes: int, properties: int, edges: int) -> tuple[Path, Path]:
    """The importer's input: ``nodes`` nodes of ``properties`` integer properties, then
    ``edges`` relationships between them spread as the transactional bound spreads them."""
    node_file, edge_file = folder / "nodes.csv", folder / "edges.csv"
    with node_file.open("w", newline="") as out:
        writer = csv.writer(out)
        # the id is stored as a property too: it is the first of the node's properties
        writer.writerow(["id:ID", *(f"p{k}:int" for k in range(properties - 1))])
        values = list(range(properties - 1))
        writer.writerows([node, *values] for node in range(nodes))
    with edge_file.open("w", newline="") as out:
        writer = csv.writer(out)
        writer.writerow([":START_ID", ":END_ID", ":TYPE"])
        writer.writerows((at % nodes, (at * 7 + 1) % nodes, "E") for at in range(edges))
    return node_file, edge_file


@dataclass
class Import:
    wall: float  # the process, start to exit (the JVM's start included)
    cpu: float
    own: float  # the importer's own "IMPORT DONE in" time
    imported: tuple[int, int, int]  # nodes, relationships, properties it reports


def importer_seconds(nodes: int, properties: int, edges: int) -> Import:
    """The importer building that graph (input files written beforehand, outside the timer);
    stops the benchmark when it imported anything else."""
    from robotale.neo4j_server.jars import ensure_jars
    from robotale.neo4j_server.server import DEFAULT_RELEASE, java_executable

    java, lib = java_executable(DEFAULT_RELEASE), ensure_jars(release=DEFAULT_RELEASE)
    with tempfile.TemporaryDirectory(prefix="robotale-import-") as folder:
        home = Path(folder)
        (home / "conf").mkdir()
        (home / "conf" / "neo4j.conf").write_text(
            f"server.directories.data={home / 'data'}\nserver.directories.logs={home / 'logs'}\n"
        )
        node_file, edge_file = write_graph(home, nodes, properties, edges)
        command = [java, "-cp", f"{lib}/*", ADMIN_TOOL, "database", "import", "full", "neo4j"]
        command += [f"--nodes=Event={node_file}", f"--relationships={edge_file}"]
        environment = os.environ | {"NEO4J_HOME": str(home), "NEO4J_CONF": str(home / "conf")}
        before = os.times()
        started = time.perf_counter()
        result = subprocess.run(command, env=environment, capture_output=True, text=True)
        wall = time.perf_counter() - started
        after = os.times()
    if result.returncode != 0:
        raise SystemExit(f"neo4j-admin database import failed: {result.stderr.strip()[:800]}")
    cpu = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    done = parse_report(result.stdout)
    wanted = (nodes, edges, nodes * properties)
    if done.imported != wanted:
        raise SystemExit(f"the importer imported {done.imported}, not {wanted}")
    return Import(wall, cpu, done.own, done.imported)


def parse_report(stdout: str) -> Import:
    """The importer's own time and counts from its closing report."""
    took = re.search(r"IMPORT DONE in ((?:\d+h )?(?:\d+m )?(?:\d+s )?\d+ms)", stdout)
    counts = [
        re.search(rf"(\d+) {what}\b", stdout) for what in ("nodes", "relationships", "properties")
    ]
    if took is None or None in counts:
        raise SystemExit(f"the importer's report was not understood: {stdout[-300:]}")
    units = {"h": 3600.0, "m": 60.0, "s": 1.0, "ms": 0.001}
    own = sum(
        float(number) * units[unit] for number, unit in re.findall(r"(\d+)(h|ms|m|s)", took[1])
    )
    imported = tuple(int(match[1]) for match in counts if match is not None)
    return Import(0.0, 0.0, own, (imported[0], imported[1], imported[2]))


def print_bound(nodes: int, properties: int, edges: int, build: float) -> None:
    """One line: the importer on a graph of the build's shape, and the build as a multiple."""
    done = importer_seconds(nodes, properties, edges)
    print(
        f"  physical bound, neo4j-admin database import full on {nodes:,} nodes of "
        f"{properties} properties and {edges:,} relationships (counts checked): "
        f"{done.own:.1f} s by its own report ({done.wall:.1f} s wall with the JVM's start, "
        f"{done.cpu:.1f} s CPU); the build takes {build / done.own:.2f}x that"
    )


def shape(counts: dict[str, int]) -> tuple[int, int]:
    """(nodes, relationships) of a graph from ``peers.counts``: events, entities and
    classes (each node carries one of these labels), every relationship type."""
    nodes = sum(counts.get(f"node:{label}", 0) for label in ("Event", "Entity", "Class"))
    edges = sum(count for key, count in counts.items() if key.startswith("relationship:"))
    return nodes, edges


if __name__ == "__main__":
    import sys

    size = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    print_bound(size, 8, size * 3, float("nan"))
