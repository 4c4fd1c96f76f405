"""Fixtures shared by every part's tests.

Each part keeps its own fixtures in ``tests/<part>/conftest.py``; only what several parts use
lives here.

Every test runs with ``ROBOTALE_HOME`` set to a temporary directory of the session (the
download cache stays the user's), so nothing is written into the user's robotale home.

Neo4j (always a real server, never a mock):

- ``neo4j_server`` (session): the :class:`robotale.ekg.connection.Settings` of the server the
  tests use. With ``NEO4J_URI`` set (plus ``NEO4J_USER``/``NEO4J_PASSWORD``) that server;
  otherwise a local Neo4j started for this session in a temporary robotale home on free ports
  (the jars come from the user's cache, so only the very first run downloads them) and
  stopped at the end: the release ``ROBOTALE_TEST_NEO4J_VERSION`` names (``2026.08``; default
  the LTS release ``robotale neo4j start`` runs), so the suite runs on each release robotale
  offers. While it runs, ``NEO4J_URI``, ``NEO4J_USER`` and ``NEO4J_PASSWORD`` point
  at it, so code under test and ``robotale`` subprocesses use it without further setup.
- ``neo4j_driver`` (session): a connected ``neo4j.Driver`` for that server.
- ``log_name``: a log name no other test uses; whatever was stored under it is deleted after
  the test. Tests share one database, so give every log you write such a name.
- ``graph_counts``: a function returning ``{"node:Event": n, "relationship:DF": m, ...}`` for
  the whole database; compare two calls to assert that a failed operation changed nothing.
"""

from __future__ import annotations

import os
import re
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

import pytest

if TYPE_CHECKING:
    from neo4j import Driver

    from robotale.ekg.connection import Settings

REPO = Path(__file__).resolve().parent.parent

# The fuzz tests: `make test` replays a fixed sequence of examples, so a run cannot fail by
# chance; `make fuzz` (ROBOTALE_FUZZ_EXAMPLES set) explores new ones.
try:
    from hypothesis import settings as _hypothesis

    _hypothesis.register_profile("fixed", derandomize=True)
    _hypothesis.register_profile("explore", derandomize=False)
    _hypothesis.load_profile("explore" if os.environ.get("ROBOTALE_FUZZ_EXAMPLES") else "fixed")
except ImportError:  # hypothesis is a development dependency
    pass
EXAMPLES = REPO / "examples"


@pytest.fixture(scope="session", autouse=True)
def robotale_home(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A robotale home of this session's own, so no test writes into the user's (uploads,
    models, demo runs); the download cache stays the user's, so the Neo4j jars are reused.
    Ingests prepare the dashboard's pages before they return."""
    from robotale.config import cache_dir

    environment = pytest.MonkeyPatch()
    environment.setenv("ROBOTALE_CACHE", str(cache_dir()))
    home = tmp_path_factory.mktemp("home")
    environment.setenv("ROBOTALE_HOME", str(home))
    # an ingest prepares the dashboard's pages before it returns, so no process outlives the
    # test that started it (tests/results/test_background.py tests the background)
    environment.setenv("ROBOTALE_PAGES", "now")
    try:
        yield home
    finally:
        environment.undo()


@pytest.fixture(scope="session")
def thesis_csv() -> Path:
    """The event log the thesis' authors recorded from their running scenario (five of its runs)."""
    return EXAMPLES / "thesis" / "robotic_data.csv"


@pytest.fixture(scope="session")
def fame_models() -> Path:
    """The thesis authors' own FAME models (fame-modeler/ and fame-ros/)."""
    return EXAMPLES / "thesis" / "fame-models"


@pytest.fixture(scope="session")
def neo4j_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Settings]:
    """The Neo4j server of this test session (see the module docstring)."""
    from robotale.ekg.connection import settings

    if os.environ.get("NEO4J_URI"):
        yield settings()
        return
    from robotale.neo4j_server.server import LocalServer, PortInUse, ServerOptions, free_ports

    server = LocalServer(tmp_path_factory.mktemp("robotale-home"))
    version = os.environ.get("ROBOTALE_TEST_NEO4J_VERSION") or ServerOptions.version
    for attempt in range(3):  # a free port can be taken by someone else before Neo4j binds it
        options = ServerOptions(*free_ports(2), heap="1g", pagecache="256m", version=version)
        try:
            running = server.start(options)
            break
        except PortInUse:
            if attempt == 2:
                raise
    environment = pytest.MonkeyPatch()
    environment.setenv("NEO4J_URI", running.bolt_uri)
    environment.setenv("NEO4J_USER", "neo4j")
    environment.setenv("NEO4J_PASSWORD", server.password() or "")
    try:
        yield settings()
    finally:
        environment.undo()
        server.stop()


@pytest.fixture(scope="session")
def neo4j_driver(neo4j_server: Settings) -> Iterator[Driver]:
    """A driver connected to the session's Neo4j server."""
    from robotale.ekg.connection import connect

    driver = connect(neo4j_server)
    yield driver
    driver.close()


@pytest.fixture
def log_name(request: pytest.FixtureRequest, neo4j_driver: Driver) -> Iterator[str]:
    """A fresh log name for this test; its data is deleted afterwards."""
    from robotale.ekg.logs import delete_log

    test = re.sub(r"\W+", "_", request.node.name)[:40]
    name = f"test_{test}_{uuid.uuid4().hex[:8]}"
    yield name
    delete_log(neo4j_driver, name)


@pytest.fixture
def graph_counts(neo4j_driver: Driver) -> Callable[[], dict[str, int]]:
    """Counts of nodes per label and relationships per type in the whole database."""
    from robotale.ekg.logs import graph_counts

    return lambda: graph_counts(neo4j_driver)


@pytest.fixture
def small_disk(tmp_path: Path) -> Iterator[Callable[[str], Path]]:
    """Mounts a filesystem of the given size (``small_disk("1m")``) and returns its folder:
    a real full disk for the tests of what a command does when it runs out of space. Needs
    root (``mount -t tmpfs``); the test is skipped where it cannot mount."""
    import subprocess

    mounted: list[Path] = []

    def mount(size: str) -> Path:
        folder = tmp_path / f"disk{len(mounted)}"
        folder.mkdir()
        done = subprocess.run(
            ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(folder)],
            capture_output=True,
            text=True,
            check=False,
        )
        if done.returncode != 0:
            pytest.skip(f"cannot mount a small filesystem here ({done.stderr.strip()})")
        mounted.append(folder)
        return folder

    yield mount
    for folder in mounted:
        subprocess.run(["umount", "-l", str(folder)], check=False)


_exit_status = 0


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    global _exit_status
    _exit_status = int(exitstatus)


def pytest_unconfigure(config: pytest.Config) -> None:
    """Cyclone DDS' binding can crash while the interpreter finalises DDS entities that tests
    left to the garbage collector (a segmentation fault after the last test): once pytest has
    reported, leave without finalising, with pytest's own exit status."""
    import sys

    if "cyclonedds" in sys.modules:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_exit_status)
