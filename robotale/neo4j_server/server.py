"""The local Neo4j server: start, stop and status.

Neo4j Community runs from the jars of :mod:`robotale.neo4j_server.jars` through its real server
entry point (Bolt, HTTP and Neo4j Browser at ``/browser/``), bound to 127.0.0.1 only. Its home is
``$ROBOTALE_HOME/neo4j``: ``conf/neo4j.conf``, ``data/``, ``logs/``, ``server.json`` (pid and
ports of the running server), ``ports.json`` (the last server's pid and ports and whether it was
stopped: it outlives a crash, so robotale keeps talking about the right port) and ``password``
(mode 0600; user ``neo4j``). The password is
``NEO4J_PASSWORD`` when that is set at the first start, otherwise a generated one.

Plugin jars (``--plugins`` or ``<robotale home>/plugins``) and the user's settings
(``<robotale home>/neo4j.conf``) join in as :mod:`robotale.neo4j_server.server_config` describes.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import time
import urllib.request
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path

from neo4j import Driver, GraphDatabase
from neo4j.exceptions import AuthError, ServiceUnavailable

from robotale.config import robotale_home
from robotale.errors import ServerError
from robotale.files import write_file
from robotale.neo4j_server.jars import (
    DEFAULT_RELEASE,
    RELEASES,
    VERSION_ENV,
    Release,
    ensure_jars,
    release,
)
from robotale.neo4j_server.java import find_java
from robotale.neo4j_server.port_holder import port_holder
from robotale.neo4j_server.server_config import (
    ALLOWED_FUNCTIONS,
    APOC_CONF_NAME,
    OVERLAY_NAME,
    PLUGINS_NAME,
    Overlay,
    check_plugins,
    compose,
    read_overlay,
    render,
)
from robotale.queries import statements

HOST = "127.0.0.1"
USER = "neo4j"
DEFAULT_BOLT_PORT = 7687
DEFAULT_HTTP_PORT = 7474
# How long `start` waits for the ports of a server that crashed or was just stopped.
PORT_WAIT = 60.0
#: the classes that run a server, one per release (a running server is known by its own)
ENTRY_POINTS = frozenset(release.entry_point for release in RELEASES.values())
#: Neo4j's command-line entry point (what the ``neo4j-admin`` script starts)
ADMIN_TOOL = "org.neo4j.cli.AdminTool"
# A JVM that runs a short admin command (setting the password) is done before the optimising
# compiler and the parallel collector pay off: without them it starts and ends in half the time.
_SHORT_TOOL_OPTIONS = ("-XX:TieredStopAtLevel=1", "-XX:+UseSerialGC", "-Xshare:auto")
# The garbage collector: the parallel one rather than G1 (Neo4j's launcher's choice). An
# ingest's transaction state dies young, and G1's concurrent marking and remembered sets cost
# the server 1.5-2.5 s of CPU per 100,000 events where the parallel collector's cost 0.3 s
# (docs/benchmarks.md); its longer pauses on a full heap matter less to a local server than
# the CPU on two cores. A ``server.jvm.additional`` line of the overlay that chooses a
# collector (``-XX:+UseG1GC``) replaces this one: the JVM refuses two.
_COLLECTOR = "-XX:+UseParallelGC"
_CHOOSES_COLLECTOR = re.compile(r"-XX:\+Use\w*GC")
# The JVM options of Neo4j's own launcher (we start java directly, so we pass them ourselves).
_JVM_OPTIONS = (
    "-XX:-OmitStackTraceInFastThrow",
    "-XX:+UnlockExperimentalVMOptions",
    "-XX:+TrustFinalNonStaticFields",
    "-XX:+DisableExplicitGC",
    "-Djdk.nio.maxCachedBufferSize=1024",
    "-Dio.netty.tryReflectionSetAccessible=true",
    "-Djdk.tls.ephemeralDHKeySize=2048",
    "-Djdk.tls.rejectClientInitiatedRenegotiation=true",
    "--add-opens=java.base/java.nio=ALL-UNNAMED",
    "--add-opens=java.base/java.io=ALL-UNNAMED",
    "--add-opens=java.base/sun.nio.ch=ALL-UNNAMED",
    "-Dlog4j2.disable.jmx=true",
    "-Dfile.encoding=UTF-8",
)


@dataclass(frozen=True)
class ServerOptions:
    """How to run the server; every field has a flag and an environment variable."""

    bolt_port: int = DEFAULT_BOLT_PORT
    http_port: int = DEFAULT_HTTP_PORT
    heap: str = "1g"
    pagecache: str = "512m"
    #: the folder of plugin jars; None: the robotale home's ``plugins/`` when it exists
    plugins: Path | None = None
    #: the Neo4j release: a line of :data:`robotale.neo4j_server.jars.RELEASES` or a full version
    version: str = DEFAULT_RELEASE.line

    @classmethod
    def from_env(cls) -> ServerOptions:
        env = os.environ
        plugins = env.get("ROBOTALE_NEO4J_PLUGINS")
        return cls(
            bolt_port=int(env.get("ROBOTALE_NEO4J_BOLT_PORT", DEFAULT_BOLT_PORT)),
            http_port=int(env.get("ROBOTALE_NEO4J_HTTP_PORT", DEFAULT_HTTP_PORT)),
            heap=env.get("ROBOTALE_NEO4J_HEAP", cls.heap),
            pagecache=env.get("ROBOTALE_NEO4J_PAGECACHE", cls.pagecache),
            plugins=Path(plugins).expanduser() if plugins else None,
            version=env.get(VERSION_ENV) or cls.version,
        )


@dataclass(frozen=True)
class RunningServer:
    """What ``server.json`` records about a started server."""

    pid: int
    bolt_port: int
    http_port: int

    @property
    def bolt_uri(self) -> str:
        return f"bolt://{HOST}:{self.bolt_port}"

    @property
    def browser_url(self) -> str:
        return f"http://{HOST}:{self.http_port}/browser/"


class PortInUse(ServerError):
    """The port the server should listen on is taken."""


# What `neo4j status` can tell about the local server.
RUNNING, STOPPED, CRASHED, OTHER = "running", "stopped", "crashed", "something else answers"


@dataclass(frozen=True)
class ServerCondition:
    """The local server's condition and its last known pid and ports (None: never started)."""

    condition: str
    record: RunningServer | None


class LocalServer:
    """The Neo4j server whose home is ``<robotale home>/neo4j``."""

    def __init__(self, home: Path | None = None) -> None:
        self.root = home or robotale_home()
        self.home = self.root / "neo4j"
        self.overlay_file = self.root / OVERLAY_NAME
        self.state_file = self.home / "server.json"
        self.ports_file = self.home / "ports.json"
        #: the options of the last start: a restart (around an offline import) keeps them
        self.options_file = self.home / "options.json"
        self.password_file = self.home / "password"
        #: the Neo4j version that created ``data/``: another one is not started on it
        self.version_file = self.home / "version"
        self.log_file = self.home / "logs" / "neo4j.log"
        self.console_file = self.home / "logs" / "console.log"

    # -- queries -------------------------------------------------------------------------

    def running(self) -> RunningServer | None:
        """The recorded server if its process is alive (a stale record is removed)."""
        if not self.state_file.is_file():
            return None
        state = RunningServer(**json.loads(self.state_file.read_text()))
        if _is_our_process(state.pid, self.home):
            return state
        self.state_file.unlink(missing_ok=True)
        return None

    def last_record(self) -> tuple[RunningServer | None, bool]:
        """The last started server's pid and ports, and whether it was stopped by us."""
        if not self.ports_file.is_file():
            return None, True
        record = json.loads(self.ports_file.read_text())
        stopped = bool(record.pop("stopped", False))
        return RunningServer(**record), stopped

    def condition(self) -> ServerCondition:
        """Running, stopped, crashed (its process died without `stop`), or stopped while
        something else answers on its Bolt port."""
        if (running := self.running()) is not None:
            return ServerCondition(RUNNING, running)
        record, stopped = self.last_record()
        port = record.bolt_port if record else ServerOptions.from_env().bolt_port
        if _port_answers(port):
            return ServerCondition(OTHER, record)
        return ServerCondition(STOPPED if stopped else CRASHED, record)

    def recorded_options(self) -> ServerOptions:
        """:meth:`ServerOptions.from_env`, with the last server's ports where the environment
        names none: a restart after a crash comes back where the logs' users look for it."""
        options = ServerOptions.from_env()
        record, _ = self.last_record()
        if record is None:
            return options
        env = os.environ
        return dataclasses.replace(
            options,
            bolt_port=options.bolt_port if "ROBOTALE_NEO4J_BOLT_PORT" in env else record.bolt_port,
            http_port=options.http_port if "ROBOTALE_NEO4J_HTTP_PORT" in env else record.http_port,
        )

    def running_options(self) -> ServerOptions:
        """The options the last start used (:meth:`recorded_options` when none are kept)."""
        if not self.options_file.is_file():
            return self.recorded_options()
        kept = json.loads(self.options_file.read_text())
        plugins = kept.pop("plugins", None)
        return ServerOptions(**kept, plugins=Path(plugins) if plugins else None)

    def password(self) -> str | None:
        return self.password_file.read_text().strip() if self.password_file.is_file() else None

    # -- the Cypher console's user -------------------------------------------------------

    @property
    def console_password_file(self) -> Path:
        return self.home / "console-password"

    def console_password(self) -> str | None:
        path = self.console_password_file
        return path.read_text().strip() if path.is_file() else None

    def console_credentials(self) -> tuple[str, str]:
        """User and password of the console's own user, created on the running server the
        first time (the file keeping its password is the record that it exists)."""
        password = self.console_password()
        if password is not None:
            return CONSOLE_USER, password
        running = self.running()
        if running is None:
            raise ServerError(
                "The local Neo4j is not running: start it with `robotale neo4j start`."
            )
        password = secrets.token_urlsafe(18)
        auth = (USER, self.password() or "")
        with GraphDatabase.driver(running.bolt_uri, auth=auth) as admin:
            create_console_user(admin, CONSOLE_USER, password)
        _write_private(self.console_password_file, password)
        return CONSOLE_USER, password

    # -- start / stop --------------------------------------------------------------------

    def start(
        self,
        options: ServerOptions | None = None,
        timeout: float = 180,
        progress: Callable[[str], None] = lambda line: None,
        bolt_only: bool = False,
    ) -> RunningServer:
        """Start the server in the background and wait until Bolt answers.

        ``bolt_only``: return once Bolt answers, while the web server (Browser, HTTP) may still
        be starting (Neo4j opens Bolt after its databases are up and HTTP after Bolt, which
        takes seconds more): for a caller that only queries.

        Returns the already running server if there is one. Ports the last server of this home
        held (it crashed, or was stopped a moment ago) are waited for, with ``progress`` lines;
        any other port in use is refused at once.
        """
        if (state := self.running()) is not None:
            return state
        options = options or self.recorded_options()
        record, _ = self.last_record()
        ours = {record.bolt_port, record.http_port} if record else set()
        for port, flag in ((options.bolt_port, "bolt"), (options.http_port, "http")):
            if port in ours:
                _wait_until_free(port, flag, PORT_WAIT, progress)
            _require_free(port, flag)
        plugins = self.plugins_folder(options)
        if plugins is not None:
            check_plugins(plugins)
        overlay = read_overlay(self.overlay_file, progress)
        chosen = release(options.version)
        self._require_data_of(chosen)
        java = java_executable(chosen)
        lib = ensure_jars(release=chosen)
        self._write_config(options, overlay)
        self._ensure_password(java, lib)
        # Plugins' extensions (APOC's configuration, for one) are found through the class
        # path, not the plugins folder. The server's jars come first: plugins bundle older
        # copies of libraries the server needs (APOC's commons-lang3 breaks its settings).
        classpath = f"{lib}/*:{plugins}/*" if plugins else f"{lib}/*"
        process = self._launch(java, classpath, options, chosen, overlay.jvm_options)
        state = RunningServer(process.pid, options.bolt_port, options.http_port)
        write_file(self.state_file, json.dumps(asdict(state)))
        kept = asdict(options) | {"plugins": str(options.plugins) if options.plugins else None}
        write_file(self.options_file, json.dumps(kept))
        self._record(state, stopped=False)
        try:
            self._wait_until_answering(process, state, timeout, bolt_only)
        except BaseException:
            _terminate(process.pid, grace=30)
            self.state_file.unlink(missing_ok=True)
            self._record(state, stopped=True)  # it did not start: no crash to report later
            raise
        return state

    def stop(self, grace: float = 60) -> RunningServer | None:
        """End the server cleanly (SIGTERM, then SIGKILL after ``grace`` seconds).

        Returns what was running, or None when nothing was.
        """
        state = self.running()
        record, _ = self.last_record()
        if state is None and record is not None and _is_our_process(record.pid, self.home):
            state = record  # its server.json was lost, yet it still runs
        if state is not None:
            _terminate(state.pid, grace)
        self.state_file.unlink(missing_ok=True)
        if record is not None:
            self._record(record, stopped=True)
        return state

    def _record(self, state: RunningServer, stopped: bool) -> None:
        write_file(self.ports_file, json.dumps(asdict(state) | {"stopped": stopped}))

    # -- helpers -------------------------------------------------------------------------

    def plugins_folder(self, options: ServerOptions) -> Path | None:
        """The plugins folder the server loads: ``--plugins``, else the home's ``plugins/``."""
        if options.plugins is not None:
            return options.plugins.resolve()
        default = self.root / PLUGINS_NAME
        return default.resolve() if default.is_dir() else None

    def _write_config(self, options: ServerOptions, overlay: Overlay | None = None) -> None:
        conf = self.home / "conf"
        conf.mkdir(parents=True, exist_ok=True)
        (self.home / "logs").mkdir(exist_ok=True)
        plugins = self.plugins_folder(options)
        owned = {
            "server.default_listen_address": HOST,
            "server.default_advertised_address": HOST,
            "server.bolt.listen_address": f"{HOST}:{options.bolt_port}",
            "server.bolt.advertised_address": f"{HOST}:{options.bolt_port}",
            "server.http.listen_address": f"{HOST}:{options.http_port}",
            "server.http.advertised_address": f"{HOST}:{options.http_port}",
            "server.bolt.enabled": "true",
            "server.http.enabled": "true",
            "server.memory.pagecache.size": options.pagecache,
            "dbms.security.auth_enabled": "true",
            "server.directories.data": "data",
            "server.directories.logs": "logs",
            "server.directories.import": "import",
            "server.directories.plugins": str(plugins) if plugins else "plugins",
        }
        defaults = {
            "server.https.enabled": "false",
            "dbms.usage_report.enabled": "false",
            # Transaction logs are for backups and clusters; a local analysis server needs none.
            "db.tx_log.rotation.retention_policy": "keep_none",
            # Bolt waits 5 s twice on shutdown for clients of a server that is already closed
            # (the databases stop and checkpoint first); a local server need not.
            "internal.server.bolt.connection_shutdown_wait_time": "1s",
            "internal.server.bolt.thread_pool_shutdown_wait_time": "1s",
            **security_settings(options.heap),
        }
        settings = compose(owned, defaults, overlay or Overlay({}, ()))
        (conf / "neo4j.conf").write_text(render(settings, self.overlay_file))
        self._copy_apoc_conf(conf)

    def _copy_apoc_conf(self, conf: Path) -> None:
        source, target = self.root / APOC_CONF_NAME, conf / APOC_CONF_NAME
        if source.is_file():
            shutil.copyfile(source, target)
        else:  # one removed from the home must not linger
            target.unlink(missing_ok=True)

    def data_version(self) -> str | None:
        """The Neo4j version that wrote this home's data (None: not recorded)."""
        return self.version_file.read_text().strip() if self.version_file.is_file() else None

    def _require_data_of(self, chosen: Release) -> None:
        """Refuse to start ``chosen`` on data another Neo4j version wrote (an older release
        cannot read a newer store, and a newer one would upgrade it for good); record the
        version of a home without data."""
        data = self.home / "data"
        written_by = self.data_version()
        if not data.is_dir() or not any(data.iterdir()):
            self.home.mkdir(parents=True, exist_ok=True)
            write_file(self.version_file, chosen.version)
            return
        written_by = written_by or DEFAULT_RELEASE.version  # homes from before the choice
        if written_by != chosen.version:
            raise ServerError(
                f"The Neo4j data in {data} was written by Neo4j {written_by}, not "
                f"{chosen.version}: start it with --version {written_by}, or move that folder "
                f"away to start Neo4j {chosen.version} with an empty database."
            )

    def _ensure_password(self, java: str, lib: Path) -> None:
        auth_store = self.home / "data" / "dbms" / "auth.ini"
        password = self.password()
        if password is not None and auth_store.is_file():
            return
        if auth_store.is_file():
            raise ServerError(
                f"The Neo4j password file {self.password_file} is missing but the database "
                f"already has one; restore the file or delete {self.home / 'data'} to start over."
            )
        if password is None:
            password = os.environ.get("NEO4J_PASSWORD") or secrets.token_urlsafe(18)
            _write_private(self.password_file, password)
        # A new database has no console user yet: the next console request creates it.
        self.console_password_file.unlink(missing_ok=True)
        env = {**os.environ, "NEO4J_HOME": str(self.home), "NEO4J_CONF": str(self.home / "conf")}
        result = subprocess.run(
            # "--": a password may begin with "-" (token_urlsafe's do, now and then).
            [
                java,
                *_SHORT_TOOL_OPTIONS,
                "-cp",
                f"{lib}/*",
                ADMIN_TOOL,
                "dbms",
                "set-initial-password",
                "--",
                password,
            ],
            env=env,
            capture_output=True,
            text=True,
            check=False,
        )
        if result.returncode != 0:
            raise ServerError(f"Could not set the Neo4j password: {result.stderr.strip()}")

    def _launch(
        self,
        java: str,
        classpath: str,
        options: ServerOptions,
        chosen: Release,
        jvm_options: tuple[str, ...] = (),
    ) -> subprocess.Popen[bytes]:
        command = [
            java,
            f"-Xms{options.heap}",
            f"-Xmx{options.heap}",
            *collector(jvm_options),
            *_JVM_OPTIONS,
            *jvm_options,
            "-cp",
            classpath,
            chosen.entry_point,
            f"--home-dir={self.home}",
            f"--config-dir={self.home / 'conf'}",
        ]
        with self.console_file.open("ab") as console:
            # A new session: the server outlives the command that started it and ignores
            # the Ctrl-C meant for that command.
            return subprocess.Popen(
                command,
                cwd=self.home,
                stdin=subprocess.DEVNULL,
                stdout=console,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def _wait_until_answering(
        self,
        process: subprocess.Popen[bytes],
        state: RunningServer,
        timeout: float,
        bolt_only: bool = False,
    ) -> None:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if process.poll() is not None:
                self._fail(f"Neo4j exited with status {process.returncode} while starting", state)
            # HTTP comes up last: once it answers, Bolt, Browser and the databases are ready.
            http = bolt_only or _http_answers(state)
            if http and bolt_answers(state.bolt_uri, (USER, self.password() or "")):
                return
            time.sleep(0.5)
        self._fail(f"Neo4j did not answer on {state.bolt_uri} within {timeout:.0f} s", state)

    def _fail(self, what: str, state: RunningServer) -> None:
        tail = _last_lines(self.log_file, 15) or _last_lines(self.console_file, 15)
        if "Address already in use" in tail:
            # Taken between our check and Neo4j's bind: say by whom, if we can still see it.
            ports = (("bolt", state.bolt_port), ("http", state.http_port))
            taken = [
                f"{flag} port {port} ({_held_by(port)})"
                for flag, port in ports
                if not _is_free(port)
            ]
            held = ", ".join(taken) or f"see {self.log_file}"
            raise PortInUse(f"{what}: a port it needs is in use: {held}.")
        raise ServerError(f"{what}; the last lines of {self.log_file}:\n{tail}")


def bolt_answers(uri: str, auth: tuple[str, str]) -> bool:
    """True when a Bolt server answers at ``uri`` (even if it refuses these credentials)."""
    driver = GraphDatabase.driver(uri, auth=auth, connection_timeout=2)
    try:
        driver.verify_connectivity()
        return True
    except AuthError:
        return True
    except (ServiceUnavailable, OSError):
        return False
    finally:
        driver.close()


def _http_answers(state: RunningServer) -> bool:
    try:
        with urllib.request.urlopen(f"http://{HOST}:{state.http_port}/", timeout=2) as response:
            return bool(response.status == 200)
    except OSError:
        return False


def java_executable(chosen: Release = DEFAULT_RELEASE) -> str:
    """The Java that runs the release ``chosen`` (see :mod:`robotale.neo4j_server.java`)."""
    lowest, highest = chosen.java
    return str(find_java(lowest, highest, f"Neo4j {chosen.version}").executable)


def _is_free(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        # As Neo4j binds: connections of a server that just ended (TIME_WAIT) do not count.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((HOST, port))
        except OSError:
            return False
    return True


def _port_answers(port: int) -> bool:
    """Whether anything accepts connections on ``port`` of 127.0.0.1."""
    try:
        with socket.create_connection((HOST, port), timeout=2):
            return True
    except OSError:
        return False


def _wait_until_free(port: int, what: str, timeout: float, progress: Callable[[str], None]) -> None:
    """Wait for a port the last server of this home held; something answering there is not
    that server (it is not running), so that is refused at once."""
    deadline = time.monotonic() + timeout
    while not _is_free(port):
        if _port_answers(port):
            raise PortInUse(
                f"The last local Neo4j's {what} port {port} on {HOST} is held by "
                f"{port_holder(port) or 'something else'}, which answers there; stop it, choose "
                f"another port with --{what}-port, or set NEO4J_URI to use that server."
            )
        left = deadline - time.monotonic()
        if left <= 0:
            raise PortInUse(
                f"The {what} port {port} on {HOST} of the last local Neo4j was still not free "
                f"after {timeout:.0f} s ({_held_by(port)}); choose another port with "
                f"--{what}-port."
            )
        progress(f"Waiting for the {what} port {port} to be free ({left:.0f} s left) ...")
        time.sleep(1)


def _require_free(port: int, what: str) -> None:
    if not _is_free(port):
        raise PortInUse(
            f"The Neo4j {what} port {port} on {HOST} is in use ({_held_by(port)}); choose "
            f"another with --{what}-port (or ROBOTALE_NEO4J_{what.upper()}_PORT), or set "
            "NEO4J_URI to use the server that is listening there."
        )


def _held_by(port: int) -> str:
    holder = port_holder(port)
    return f"held by {holder}" if holder else "its holder is unknown: try `ss -ltnp`"


def collector(jvm_options: tuple[str, ...]) -> tuple[str, ...]:
    """robotale's choice of garbage collector, unless ``jvm_options`` (the overlay's) choose
    one themselves."""
    if any(_CHOOSES_COLLECTOR.fullmatch(option) for option in jvm_options):
        return ()
    return (_COLLECTOR,)


def free_port() -> int:
    """A TCP port on 127.0.0.1 that nobody listens on right now."""
    return free_ports(1)[0]


def free_ports(count: int) -> list[int]:
    """``count`` different TCP ports on 127.0.0.1 that nobody listens on right now: each probe
    stays bound until all are chosen, since two probes one after the other can be given the
    same port (Bolt and HTTP on one port: Neo4j then fails to start)."""
    with contextlib.ExitStack() as stack:
        probes = [stack.enter_context(socket.socket(socket.AF_INET, socket.SOCK_STREAM))
                  for _ in range(count)]  # fmt: skip
        for probe in probes:
            probe.bind((HOST, 0))
        return [int(probe.getsockname()[1]) for probe in probes]


def _write_private(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(descriptor, "w") as stream:
        stream.write(text + "\n")


def _is_our_process(pid: int, home: Path) -> bool:
    # A pid can be reused after a crash: only a Neo4j with this home counts.
    _reap(pid)
    try:
        cmdline = Path(f"/proc/{pid}/cmdline").read_bytes().split(b"\0")
    except OSError:
        return False
    ours = any(entry.encode() in cmdline for entry in ENTRY_POINTS)
    return f"--home-dir={home}".encode() in cmdline and ours


def _reap(pid: int) -> bool:
    """Collect ``pid`` if it is a finished child of ours; True once it is gone."""
    try:
        done, _ = os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:  # not our child: ask the kernel instead
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        try:
            stat = Path(f"/proc/{pid}/stat").read_text()
        except OSError:
            return True
        return stat.rsplit(")", 1)[-1].split()[0] == "Z"
    return done == pid


def _terminate(pid: int, grace: float) -> None:
    try:
        os.kill(pid, signal.SIGTERM)
    except ProcessLookupError:
        return
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline:
        if _reap(pid):
            return
        time.sleep(0.2)
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        return
    while not _reap(pid):
        time.sleep(0.1)


def _last_lines(path: Path, count: int) -> str:
    if not path.is_file():
        return ""
    return "\n".join(path.read_text(errors="replace").splitlines()[-count:])


# -- the Cypher console's user and the limits of one query -------------------------------

#: the user the dashboard's Cypher console logs in as on the local server
CONSOLE_USER = "robotale_console"
#: the share of the heap one transaction may hold: a runaway query fails, the server lives on
_TRANSACTION_SHARE = 0.5
_SIZE = re.compile(r"(\d+)([kmg]?)", re.IGNORECASE)
_UNITS = {"": 1, "k": 1024, "m": 1024**2, "g": 1024**3}


def security_settings(heap: str) -> dict[str, str]:
    """The settings that keep one query from reading the server's files or its whole heap."""
    settings = {
        # LOAD CSV may not read files (the console also refuses the clause before sending it).
        "dbms.security.allow_csv_import_from_file_urls": "false",
        "server.directories.import": "import",
        # No plugin's procedures or functions load unless the overlay names them: the
        # console's queries then cannot reach them whatever their spelling.
        "dbms.security.procedures.allowlist": ",".join(sorted(ALLOWED_FUNCTIONS)),
    }
    limit = _share_of(heap, _TRANSACTION_SHARE)
    if limit is not None:
        settings["db.memory.transaction.max"] = limit
    return settings


def _share_of(size: str, share: float) -> str | None:
    """``share`` of a JVM size such as ``1g``, in megabytes (None when it is no size)."""
    match = _SIZE.fullmatch(size.strip())
    if match is None:
        return None
    total = int(match.group(1)) * _UNITS[match.group(2).lower()]
    return f"{max(1, int(total * share) // 1024**2)}m"


def create_console_user(admin: Driver, user: str, password: str) -> None:
    """Create (or reset the password of) the console's user, connected as an administrator."""
    for statement in statements("console_user"):
        admin.execute_query(statement, user=user, password=password, database_="system")
