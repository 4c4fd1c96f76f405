"""PromG's Neo4j as a PromG user runs it: Neo4j's own launcher and its stock configuration.

robotale starts its own local server with java and options of its own (the parallel
collector, no transaction logs kept, ...). A PromG user installs Neo4j, drops APOC into
``plugins/`` and runs ``bin/neo4j start``, which starts Neo4j's launcher class
(``org.neo4j.server.startup.Neo4jCommand``) on the distribution's ``lib/``; the launcher reads
``conf/neo4j.conf`` and starts the server's JVM with that file's ``server.jvm.additional``
options (G1, ``AlwaysPreTouch`` ...). :class:`stock_neo4j` lays out such an installation in a
folder of the benchmark's (the jars robotale keeps for the same release as its ``lib/``, the
pinned APOC jars as its ``plugins/``, see :func:`unshadowed`), writes the stock ``neo4j.conf``
with only what the benchmark must change appended (:func:`stock_conf`), sets the password as
``neo4j-admin dbms set-initial-password`` does and runs the launcher's ``start`` and ``stop``
as ``bin/neo4j`` runs them (the Neo4j tarball itself, with its shell scripts, is not on Maven
Central, where robotale fetches its jars from).
"""

from __future__ import annotations

import os
import secrets
import subprocess
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

#: The active lines of ``conf/neo4j.conf`` as Neo4j Community 5.26 ships it (every other line
#: of that file is a comment). A user who runs PromG starts from this file.
STOCK_LINES = (
    "server.directories.import=import",
    "server.bolt.enabled=true",
    "server.http.enabled=true",
    "server.https.enabled=false",
    "db.tx_log.rotation.retention_policy=2 days 2G",
    "server.jvm.additional=-XX:+UseG1GC",
    "server.jvm.additional=-XX:-OmitStackTraceInFastThrow",
    "server.jvm.additional=-XX:+AlwaysPreTouch",
    "server.jvm.additional=-XX:+UnlockExperimentalVMOptions",
    "server.jvm.additional=-XX:+TrustFinalNonStaticFields",
    "server.jvm.additional=-XX:+DisableExplicitGC",
    "server.jvm.additional=-Djdk.nio.maxCachedBufferSize=1024",
    "server.jvm.additional=-Dio.netty.tryReflectionSetAccessible=true",
    "server.jvm.additional=-Djdk.tls.ephemeralDHKeySize=2048",
    "server.jvm.additional=-Djdk.tls.rejectClientInitiatedRenegotiation=true",
    "server.jvm.additional=-XX:FlightRecorderOptions=stackdepth=256",
    "server.jvm.additional=-XX:+UnlockDiagnosticVMOptions",
    "server.jvm.additional=-XX:+DebugNonSafepoints",
    "server.jvm.additional=--add-opens=java.base/java.nio=ALL-UNNAMED",
    "server.jvm.additional=--add-opens=java.base/java.io=ALL-UNNAMED",
    "server.jvm.additional=--add-opens=java.base/sun.nio.ch=ALL-UNNAMED",
    "server.jvm.additional=--enable-native-access=ALL-UNNAMED",
    "server.jvm.additional=-Dlog4j2.disable.jmx=true",
    "server.jvm.additional=-Dlog4j.layout.jsonTemplate.maxStringLength=32768",
    "server.windows_service_name=neo4j",
)
#: the launcher's class (what ``bin/neo4j`` runs) and the admin tool's (``bin/neo4j-admin``)
LAUNCHER = "org.neo4j.server.startup.Neo4jCommand"
ADMIN = "org.neo4j.server.startup.Neo4jAdminCommand"
#: what APOC's installation asks of ``apoc.conf`` for PromG's ``apoc.load.csv``
APOC_CONF = "apoc.import.file.enabled=true\n"


def stock_conf(bolt_port: int, http_port: int, heap: str, pagecache: str) -> str:
    """The stock ``neo4j.conf`` with what the benchmark must change appended (a later line
    of a setting wins in Neo4j's reading of the file): the ports (beside other servers), the
    heap and page cache (the same as robotale's server, so both have the same memory) and
    APOC's procedures unrestricted (as APOC's installation asks; PromG calls them)."""
    changed = {
        "server.default_listen_address": "127.0.0.1",
        "server.bolt.listen_address": f"127.0.0.1:{bolt_port}",
        "server.bolt.advertised_address": f"127.0.0.1:{bolt_port}",
        "server.http.listen_address": f"127.0.0.1:{http_port}",
        "server.http.advertised_address": f"127.0.0.1:{http_port}",
        "server.memory.heap.initial_size": heap,
        "server.memory.heap.max_size": heap,
        "server.memory.pagecache.size": pagecache,
        "dbms.security.procedures.unrestricted": "apoc.*",
    }
    lines = ["# Neo4j 5.26's stock neo4j.conf (its active lines)", *STOCK_LINES]
    lines.append("# changed by the benchmark: ports, memory (as robotale's server), APOC")
    lines += [f"{key}={value}" for key, value in changed.items()]
    return "\n".join(lines) + "\n"


def lay_out(home: Path, lib: Path, plugins: list[Path], conf: str) -> None:
    """An installation of Neo4j in ``home``: ``lib`` (the release's jars) linked as its
    ``lib/``, ``plugins`` linked into its ``plugins/``, ``conf`` as ``conf/neo4j.conf`` beside
    APOC's ``conf/apoc.conf``, and empty ``data/``, ``logs/``, ``import/`` and ``run/``."""
    home.mkdir(parents=True, exist_ok=True)
    (home / "lib").symlink_to(lib, target_is_directory=True)
    for folder in ("plugins", "conf", "data", "logs", "import", "run"):
        (home / folder).mkdir()
    for jar in plugins:
        (home / "plugins" / jar.name).symlink_to(jar)
    (home / "conf" / "neo4j.conf").write_text(conf)
    (home / "conf" / "apoc.conf").write_text(APOC_CONF)


def unshadowed(jars: list[Path], lib: Path, folder: Path) -> list[Path]:
    """``jars`` (plugins) with the classes ``lib``'s jars also have left out: copies in
    ``folder`` where a jar has any, else the jar itself.

    Neo4j's launcher puts ``plugins/`` before ``lib/`` on the server's class path, so the old
    commons-lang3 and commons-text that the pinned APOC 5.26.0 core jar bundles would shadow
    the server's newer ones, and the server stops at APOC's configuration (``NoSuchMethodError``
    in ``ObjectUtils.getIfNull``). A user's APOC matches their Neo4j's ``lib/``; left out,
    the classes resolve as on robotale's server (``lib/`` first), where both pairings run the
    same APOC code."""
    in_lib = {
        name
        for jar in sorted(lib.glob("*.jar"))
        for name in zipfile.ZipFile(jar).namelist()
        if name.endswith(".class") and not name.endswith("module-info.class")
    }
    folder.mkdir(parents=True, exist_ok=True)
    kept = []
    for jar in jars:
        with zipfile.ZipFile(jar) as source:
            names = source.namelist()
            if in_lib.isdisjoint(names):
                kept.append(jar)
                continue
            copy = folder / jar.name
            with zipfile.ZipFile(copy, "w", zipfile.ZIP_DEFLATED) as target:
                for name in names:
                    if name not in in_lib:
                        target.writestr(source.getinfo(name), source.read(name))
            kept.append(copy)
    return kept


@dataclass(frozen=True)
class Running:
    """The started server as ``whole_ingest`` and ``peers`` read it (as robotale's
    ``RunningServer``): the server JVM's pid and the Bolt address."""

    pid: int
    bolt_port: int
    http_port: int

    @property
    def bolt_uri(self) -> str:
        return f"bolt://127.0.0.1:{self.bolt_port}"


class StockServer:
    """A Neo4j installation in ``home`` run by Neo4j's launcher; the methods the benchmark's
    servers share (``running``, ``password``, ``home``, ``stop``)."""

    def __init__(self, home: Path, java: str, bolt_port: int, http_port: int) -> None:
        self.home = self.root = home
        self.java, self.ports = java, (bolt_port, http_port)
        self._password: str | None = None

    def _tool(self, main: str, *arguments: str) -> subprocess.CompletedProcess[str]:
        """``bin/neo4j`` or ``bin/neo4j-admin`` with ``arguments``: the launcher's class on
        ``lib/``, its home and configuration from the environment, as the scripts set them."""
        environment = os.environ | {
            "NEO4J_HOME": str(self.home),
            "NEO4J_CONF": str(self.home / "conf"),
            "JAVA_HOME": str(Path(self.java).resolve().parents[1]),
        }
        command = [self.java, "-cp", f"{self.home / 'lib'}/*", f"-Dbasedir={self.home}"]
        command += ["-Dfile.encoding=UTF-8", main, *arguments]
        return subprocess.run(
            command, env=environment, cwd=self.home, capture_output=True, text=True, check=False
        )

    def start(self, timeout: float = 300) -> Running:
        from robotale.neo4j_server.server import USER, bolt_answers

        self._password = secrets.token_urlsafe(18)
        done = self._tool(ADMIN, "dbms", "set-initial-password", "--", self._password)
        if done.returncode != 0:
            raise RuntimeError(f"neo4j-admin set-initial-password failed: {done.stderr[-500:]}")
        started = self._tool(LAUNCHER, "start")
        if started.returncode != 0:
            said = started.stdout[-500:] + started.stderr[-500:]
            raise RuntimeError(f"neo4j start failed: {said}")
        running = self.running()
        deadline = time.monotonic() + timeout
        while running is None or not bolt_answers(running.bolt_uri, (USER, self._password)):
            if time.monotonic() > deadline:
                raise RuntimeError(f"the stock Neo4j did not answer within {timeout:.0f} s")
            time.sleep(0.5)
            running = self.running()
        return running

    def running(self) -> Running | None:
        pid_file = self.home / "run" / "neo4j.pid"
        if not pid_file.is_file():
            return None
        pid = int(pid_file.read_text().split()[0])
        return Running(pid, *self.ports) if Path(f"/proc/{pid}").exists() else None

    def password(self) -> str | None:
        return self._password

    def stop(self) -> None:
        self._tool(LAUNCHER, "stop")

    def command_line(self) -> list[str]:
        """The server JVM's command line (what the launcher started), for the report."""
        running = self.running()
        if running is None:
            return []
        raw = Path(f"/proc/{running.pid}/cmdline").read_bytes()
        return [part.decode() for part in raw.split(b"\0") if part]


class stock_neo4j:
    """PromG's server as its users run it, for the benchmark's ``with``: the driver and the
    :class:`StockServer`; the same heap and page cache as robotale's private server."""

    def __init__(self, work: Path, heap: str, pagecache: str = "1g") -> None:
        self.work, self.heap, self.pagecache = work, heap, pagecache

    def __enter__(self):
        from robotale.ekg.connection import Settings, connect
        from robotale.neo4j_server.jars import apoc_with_file_access, ensure_jars
        from robotale.neo4j_server.server import free_ports, java_executable

        bolt, http = free_ports(2)
        home = self.work / "neo4j-stock"
        conf = stock_conf(bolt, http, self.heap, self.pagecache)
        lib = ensure_jars()
        plugins = unshadowed(apoc_with_file_access(), lib, self.work / "plugin-jars")
        lay_out(home, lib, plugins, conf)
        self.server = StockServer(home, java_executable(), bolt, http)
        running = self.server.start()
        self.driver = connect(Settings(running.bolt_uri, "neo4j", self.server.password(), True))
        return self.driver, self.server

    def __exit__(self, *exc: object) -> None:
        self.driver.close()
        self.server.stop()


def describe_pairing(kind: str, heap: str, pagecache: str = "1g") -> str:
    """Which servers the two sides ran on, in one line of the benchmark's output."""
    ours = (
        f"robotale on its own local server (robotale's launch: parallel collector; heap {heap}, "
        f"page cache {pagecache}, no plugins)"
    )
    if kind == "stock":
        theirs = (
            "PromG on Neo4j as its users run it (Neo4j's launcher `neo4j start`, Neo4j 5.26's "
            f"stock neo4j.conf: G1, AlwaysPreTouch ...; changed only: ports, data folder, "
            f"password, APOC in plugins/ and unrestricted, heap {heap} and page cache "
            f"{pagecache} as robotale's: equal memory)"
        )
    else:
        theirs = (
            "PromG on a server started by robotale's own launch code (robotale's JVM options, "
            f"the parallel collector; heap {heap}, page cache {pagecache}, APOC)"
        )
    return f"pairing --promg-server {kind}: {ours}; {theirs}"
