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
import subprocess
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path


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
    from robotale.neo4j_server.importer import (
        ImportFiles,
        admin_command,
        admin_environment,
        parse_report,
    )
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
        files = ImportFiles([("Event", node_file)], [("E", edge_file)])
        command = admin_command(java, f"{lib}/*", "neo4j", files)
        environment = admin_environment(home)
        before = os.times()
        started = time.perf_counter()
        result = subprocess.run(command, env=environment, cwd=home, capture_output=True, text=True)
        wall = time.perf_counter() - started
        after = os.times()
    if result.returncode != 0:
        raise SystemExit(f"neo4j-admin database import failed: {result.stderr.strip()[:800]}")
    cpu = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    done = parse_report(result.stdout)
    if done is None:
        raise SystemExit(f"the importer's report was not understood: {result.stdout[-300:]}")
    wanted = (nodes, edges, nodes * properties)
    imported = (done.nodes, done.relationships, done.properties)
    if imported != wanted:
        raise SystemExit(f"the importer imported {imported}, not {wanted}")
    return Import(wall, cpu, done.seconds, imported)


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
