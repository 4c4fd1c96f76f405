"""Regenerate ``neo4j_jars.lock``, the pinned jar set of the local Neo4j server.

A maintainer's tool (it needs Maven): ``python -m robotale.ekg.neo4j_lock``. Maven resolves the
runtime closure of the Neo4j Community server, its HTTP module and Neo4j Browser; the lock
records each jar's Maven coordinates, sha1 and size, so users download exactly these files from
Maven Central without Maven (see :mod:`robotale.ekg.jars`).
"""

from __future__ import annotations

import hashlib
import subprocess
import sys
import tempfile
from pathlib import Path

from robotale.ekg.jars import BROWSER_VERSION, LOCK_FILE, NEO4J_VERSION, Jar

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


def resolve_with_maven() -> list[tuple[Jar, Path]]:
    """Every runtime jar Maven resolves for the server, with its file in the local repository."""
    with tempfile.TemporaryDirectory() as work:
        pom = Path(work) / "pom.xml"
        pom.write_text(_POM.format(neo4j=NEO4J_VERSION, browser=BROWSER_VERSION))
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


def write_lock(jars: list[Jar], lock: Path = LOCK_FILE) -> None:
    lines = [
        f"# Neo4j {NEO4J_VERSION} Community server with Neo4j Browser {BROWSER_VERSION}:",
        "# the runtime jars, fetched from Maven Central and checked against these sha1 sums.",
        "# Regenerate with `python -m robotale.ekg.neo4j_lock` (needs Maven).",
        *sorted(jar.lock_line() for jar in jars),
    ]
    lock.write_text("\n".join(lines) + "\n")


def main() -> int:
    jars = [jar for jar, _ in resolve_with_maven()]
    write_lock(jars)
    print(f"{LOCK_FILE}: {len(jars)} jars, {sum(j.size for j in jars) / 1e6:.0f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
