"""Regenerate the lock file of a Neo4j release, the pinned jar set of the local Neo4j server.

A maintainer's tool (it needs Maven): ``python -m robotale.neo4j_server.neo4j_lock [LINE]``
(a release line of :data:`~robotale.neo4j_server.jars.RELEASES`, e.g. ``2026.08``; default
5.26). Maven resolves the
runtime closure of the Neo4j Community server, its HTTP module and Neo4j Browser; the lock
records each jar's Maven coordinates, sha1 and size, so users download exactly these files from
Maven Central without Maven (see :mod:`robotale.neo4j_server.jars`).
"""

from __future__ import annotations

import hashlib
import subprocess
import sys
import tempfile
from pathlib import Path

from robotale.neo4j_server.jars import Jar, Release, release

_SCOPES = {"compile", "runtime", "provided", "system", "test"}
_POM = """<project xmlns="http://maven.apache.org/POM/4.0.0">
  <modelVersion>4.0.0</modelVersion>
  <groupId>robotale</groupId><artifactId>neo4j-server-lock</artifactId><version>1</version>
  <packaging>pom</packaging>
  <dependencies>
    <dependency><groupId>org.neo4j</groupId><artifactId>neo4j</artifactId>
      <version>{neo4j}</version></dependency>
    <dependency><groupId>org.neo4j.app</groupId><artifactId>neo4j-server</artifactId>
      <version>{neo4j}</version></dependency>
    <dependency><groupId>org.neo4j.client</groupId><artifactId>neo4j-browser</artifactId>
      <version>{browser}</version></dependency>
  </dependencies>
</project>
"""


def resolve_with_maven(chosen: Release) -> list[tuple[Jar, Path]]:
    """Every runtime jar Maven resolves for the server, with its file in the local repository."""
    with tempfile.TemporaryDirectory() as work:
        pom = Path(work) / "pom.xml"
        pom.write_text(_POM.format(neo4j=chosen.version, browser=chosen.browser))
        listing = Path(work) / "deps.txt"
        subprocess.run(
            [
                "mvn",
                "-q",
                "-f",
                str(pom),
                "dependency:list",
                "-DincludeScope=runtime",
                f"-DoutputFile={listing}",
                "-DoutputAbsoluteArtifactFilename=true",
            ],
            check=True,
        )
        return [
            _parse_listing_line(line)
            for line in listing.read_text().splitlines()
            if ":jar:" in line
        ]


def _parse_listing_line(line: str) -> tuple[Jar, Path]:
    # group:artifact:jar[:classifier]:version[:scope]:/path/to/file.jar
    coordinates, _, path = line.strip().partition(":/")
    group, artifact, _type, *rest = coordinates.split(":")
    if rest[-1] in _SCOPES:
        rest.pop()
    version, classifier = rest[-1], (rest[0] if len(rest) == 2 else "")
    file = Path("/" + path)
    digest = hashlib.sha1(file.read_bytes()).hexdigest()
    return Jar(group, artifact, version, classifier, digest, file.stat().st_size), file


def write_lock(jars: list[Jar], chosen: Release) -> None:
    lines = [
        f"# Neo4j {chosen.version} Community server with Neo4j Browser {chosen.browser}:",
        "# the runtime jars, fetched from Maven Central and checked against these sha1 sums.",
        f"# Regenerate with `python -m robotale.neo4j_server.neo4j_lock {chosen.line}`"
        " (needs Maven).",
        *sorted(jar.lock_line() for jar in jars),
    ]
    chosen.lock.write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    chosen = release(args[0] if args else None)
    jars = [jar for jar, _ in resolve_with_maven(chosen)]
    write_lock(jars, chosen)
    print(f"{chosen.lock}: {len(jars)} jars, {sum(j.size for j in jars) / 1e6:.0f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
