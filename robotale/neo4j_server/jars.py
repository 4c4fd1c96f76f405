"""The Neo4j server's jars: pinned per release in a lock file, fetched from Maven Central.

:data:`RELEASES` are the Neo4j releases robotale runs: 5.26 LTS (the default, pinned in
``neo4j_jars.lock``) and the newest release Maven Central serves (its own lock file).
:func:`ensure_jars` makes ``cache_dir()/neo4j-<version>/lib`` hold exactly the locked jars.
Each jar is downloaded with urllib, checked against its sha1 and moved into place atomically;
a file lock lets several processes (parallel test runs, two terminals) provision at once. Once
everything is in place a marker file records it, so later starts never touch the network.
"""

from __future__ import annotations

import fcntl
import hashlib
import os
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import IO

from tqdm import tqdm

from robotale.config import cache_dir
from robotale.errors import ServerError
from robotale.files import atomic_file

LOCK_FILE = Path(__file__).with_name("neo4j_jars.lock")
#: plugins (APOC) pinned for tests and benchmarks; a user's own plugins need no pin
PLUGIN_LOCK_FILE = Path(__file__).with_name("plugin_jars.lock")
#: Maven Central, or a mirror of it (``ROBOTALE_MAVEN_REPO``).
DEFAULT_REPOSITORY = "https://repo1.maven.org/maven2"
_MARKER = ".complete"
_ATTEMPTS = 3


@dataclass(frozen=True)
class Release:
    """One Neo4j release robotale can run: its jars' lock file and the Java it needs."""

    version: str
    browser: str
    #: the Java feature versions it runs on, lowest and highest
    java: tuple[int, int]
    lock: Path
    #: the class whose main method runs the server
    entry_point: str = "org.neo4j.server.CommunityEntryPoint"

    @property
    def line(self) -> str:
        """The release line ``--version`` names it by: ``5.26``, ``2026.08``."""
        return ".".join(self.version.split(".")[:2])


#: the releases ``robotale neo4j start --version`` offers, by line; the first is the default
RELEASES = {
    release.line: release
    for release in (
        Release("5.26.30", "5.24.0", (17, 21), LOCK_FILE),
        Release(
            "2026.08.1",
            "5.24.0",
            (21, 25),
            Path(__file__).with_name("neo4j_2026_jars.lock"),
            "org.neo4j.server.Neo4jCommunity",
        ),
    )
}
DEFAULT_RELEASE = next(iter(RELEASES.values()))
NEO4J_VERSION = DEFAULT_RELEASE.version
BROWSER_VERSION = DEFAULT_RELEASE.browser
#: the environment variable that chooses the release where no ``--version`` is given
VERSION_ENV = "ROBOTALE_NEO4J_VERSION"


def release(name: str | None = None) -> Release:
    """The release ``name`` names (a line such as ``2026.08`` or a full version); None: the
    one :data:`VERSION_ENV` names, else the default."""
    name = (name or os.environ.get(VERSION_ENV) or DEFAULT_RELEASE.line).strip()
    for candidate in RELEASES.values():
        if name in (candidate.line, candidate.version):
            return candidate
    offered = ", ".join(f"{r.line} ({r.version})" for r in RELEASES.values())
    raise ServerError(f"robotale runs no Neo4j {name!r}; it runs {offered}.")


@dataclass(frozen=True)
class Jar:
    group: str
    artifact: str
    version: str
    classifier: str
    sha1: str
    size: int

    @property
    def filename(self) -> str:
        suffix = f"-{self.classifier}" if self.classifier else ""
        return f"{self.artifact}-{self.version}{suffix}.jar"

    def url(self, repository: str) -> str:
        group_path = self.group.replace(".", "/")
        return f"{repository}/{group_path}/{self.artifact}/{self.version}/{self.filename}"

    def lock_line(self) -> str:
        coordinates = f"{self.group}:{self.artifact}:{self.version}"
        if self.classifier:
            coordinates += f":{self.classifier}"
        return f"{coordinates} {self.sha1} {self.size}"


def read_lock(lock: Path = LOCK_FILE) -> list[Jar]:
    """The jars a lock file pins (``group:artifact:version[:classifier] sha1 size`` lines)."""
    jars = []
    for line in lock.read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        coordinates, sha1, size = line.split()
        group, artifact, version, *classifier = coordinates.split(":")
        jars.append(Jar(group, artifact, version, "".join(classifier), sha1, int(size)))
    return jars


def server_dir(version: str = NEO4J_VERSION) -> Path:
    """Where a Neo4j version's jars live, shared by every robotale home."""
    return cache_dir() / f"neo4j-{version}"


def ensure_jars(
    lib: Path | None = None,
    repository: str | None = None,
    lock: Path | None = None,
    release: Release = DEFAULT_RELEASE,
) -> Path:
    """Download whatever jar of ``lock`` (default: ``release``'s) is missing from ``lib``
    (default: ``release``'s folder of :func:`server_dir`); returns ``lib``.

    Raises :class:`ServerError` naming the jar when a download fails or its sha1 differs.
    """
    lock = lock or release.lock
    lib = lib or server_dir(release.version) / "lib"
    jars = read_lock(lock)
    marker = lib / _MARKER
    fingerprint = hashlib.sha1(lock.read_bytes()).hexdigest()
    if _marker_matches(marker, fingerprint):
        return lib
    lib.mkdir(parents=True, exist_ok=True)
    with _file_lock(lib.parent / f"{lib.name}.lock"):
        if _marker_matches(marker, fingerprint):  # another process finished meanwhile
            return lib
        missing = [jar for jar in jars if not _is_in_place(lib / jar.filename, jar)]
        if missing:
            what = f"Neo4j {release.version} jars"
            _download_all(missing, lib, repository or _repository(), what)
        _remove_strays(lib, {jar.filename for jar in jars})
        marker.write_text(fingerprint)
    return lib


def plugin_jar(artifact: str, repository: str | None = None) -> Path:
    """The cached jar of the pinned plugin ``artifact`` (e.g. ``apoc-core``), downloaded and
    sha1-checked the first time; ``cache_dir()/neo4j-plugins`` keeps it for every later call."""
    pinned = {jar.artifact: jar for jar in read_lock(PLUGIN_LOCK_FILE)}
    if artifact not in pinned:
        raise ServerError(
            f"No plugin {artifact!r} is pinned in {PLUGIN_LOCK_FILE.name}; "
            f"pinned: {', '.join(sorted(pinned))}."
        )
    return ensure_jar(pinned[artifact], cache_dir() / "neo4j-plugins", repository)


def apoc_with_file_access(repository: str | None = None) -> list[Path]:
    """Every jar ``plugin_jars.lock`` pins: APOC core and extended with what their file
    procedures (``apoc.load.csv``) need on this server, for one plugins folder."""
    return [plugin_jar(jar.artifact, repository) for jar in read_lock(PLUGIN_LOCK_FILE)]


def ensure_jar(jar: Jar, folder: Path, repository: str | None = None) -> Path:
    """``folder/<jar's file name>``, downloaded unless a copy with the pinned sha1 is there."""
    target = folder / jar.filename
    if _is_in_place(target, jar):
        return target
    folder.mkdir(parents=True, exist_ok=True)
    with _file_lock(folder / f".{jar.filename}.lock"):
        if not _is_in_place(target, jar):  # another process may have finished meanwhile
            _download_all([jar], folder, repository or _repository(), jar.artifact)
    return target


def _repository() -> str:
    return os.environ.get("ROBOTALE_MAVEN_REPO", DEFAULT_REPOSITORY).rstrip("/")


def _marker_matches(marker: Path, fingerprint: str) -> bool:
    return marker.is_file() and marker.read_text() == fingerprint


def _is_in_place(path: Path, jar: Jar) -> bool:
    return path.is_file() and path.stat().st_size == jar.size and _sha1(path) == jar.sha1


def _sha1(path: Path) -> str:
    digest = hashlib.sha1()
    with path.open("rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@contextmanager
def _file_lock(path: Path) -> Iterator[None]:
    with path.open("a") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _download_all(jars: list[Jar], lib: Path, repository: str, what: str) -> None:
    total = sum(jar.size for jar in jars)
    with (
        tqdm(
            total=total,
            unit="B",
            unit_scale=True,
            file=sys.stderr,
            desc=what,
        ) as progress,
        ThreadPoolExecutor(max_workers=8) as pool,
    ):
        list(pool.map(lambda jar: _download(jar, lib, repository, progress), jars))


def _download(jar: Jar, lib: Path, repository: str, progress: tqdm) -> None:
    url = jar.url(repository)
    for attempt in range(1, _ATTEMPTS + 1):
        try:
            # a jar whose checksum is wrong, or whose download broke off, never reaches lib
            with atomic_file(lib / jar.filename, "wb") as out:
                digest = _fetch(url, out, progress)
                if digest != jar.sha1:
                    raise ServerError(
                        f"The Neo4j jar {url} has sha1 {digest}, not the pinned {jar.sha1}; "
                        "check ROBOTALE_MAVEN_REPO or your network proxy."
                    )
            return
        except (urllib.error.URLError, OSError) as error:
            if attempt == _ATTEMPTS:
                raise ServerError(
                    f"Could not download the Neo4j jar {url} ({error}); "
                    "check the network or set ROBOTALE_MAVEN_REPO to a Maven Central mirror."
                ) from error
            time.sleep(attempt)


def _fetch(url: str, out: IO[bytes], progress: tqdm) -> str:
    digest = hashlib.sha1()
    with urllib.request.urlopen(url, timeout=60) as response:
        for block in iter(lambda: response.read(1 << 16), b""):
            digest.update(block)
            out.write(block)
            progress.update(len(block))
    return digest.hexdigest()


def _remove_strays(lib: Path, wanted: set[str]) -> None:
    # Jars of another lock (an older pin) must not end up on the class path.
    for path in lib.glob("*.jar"):
        if path.name not in wanted:
            path.unlink()
