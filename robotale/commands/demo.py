"""``robotale demo``: the whole mission end to end on the local defaults.

Neo4j up (the local server unless ``NEO4J_URI`` names one), the agri mission simulated
(``ROBOTALE_DEMO_RUNS`` runs, 20 unless told), its bags prepared into an event log and
ingested as the log ``agri``, the thesis' own log ingested as ``thesis``, the BPMN models that
drove them attached for the Model page, and the dashboard served until Ctrl-C.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from robotale.config import robotale_home
from robotale.ekg.connection import connect
from robotale.ekg.keys import DEFAULT_ENTITIES, built_keys
from robotale.errors import InputError
from robotale.eventlog.preparing import prepare_reporting
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv
from robotale.neo4j_server.server import LocalServer, ServerOptions
from robotale.results.storing import store
from robotale.sim import scenarios
from robotale.sim.batch import print_summary, simulate_batch
from robotale.sim.plans import check, plans, resolve_world
from robotale.webapp.model_store import attach_model
from robotale.webapp.serve import Dashboard, discover_path, serve_until_interrupted
from robotale.webapp.settings import DEFAULT_PORT

DEFAULT_RUNS = 20
AGRI_LOG = "agri"
THESIS_LOG_NAME = "thesis"
THESIS_DIR = Path("examples") / "thesis"
THESIS_LOG = THESIS_DIR / "robotic_data.csv"
THESIS_MODEL = THESIS_DIR / "fame-models" / "fame-ros" / "agri.bpmn"
ENTITIES = list(DEFAULT_ENTITIES)


@dataclass(frozen=True)
class DemoOptions:
    runs: int
    seed: int
    folder: Path
    port: int
    serve: bool

    @classmethod
    def given(
        cls, runs: int | None, seed: int | None, out: Path | None, port: int | None, serve: bool
    ) -> DemoOptions:
        runs = runs if runs is not None else _runs_from_env()
        if runs < 1:
            raise InputError(f"--runs is {runs}: the demo needs at least one run.")
        folder = out or robotale_home() / "demo"
        return cls(runs, 1 if seed is None else seed, folder, port or DEFAULT_PORT, serve)


def _runs_from_env() -> int:
    value = os.environ.get("ROBOTALE_DEMO_RUNS", "").strip()
    if not value:
        return DEFAULT_RUNS
    if not value.isdigit():
        raise InputError(f"ROBOTALE_DEMO_RUNS is {value!r}: give a whole number of runs.")
    return int(value)


def demo_command(
    *,
    runs: int | None = None,
    seed: int | None = None,
    out: Path | None = None,
    port: int | None = None,
    serve: bool = True,
) -> int:
    """The whole mission end to end; ``serve`` keeps the dashboard up until Ctrl-C."""
    options = DemoOptions.given(runs, seed, out, port, serve)
    thesis = source_file(THESIS_LOG)
    # Bind the dashboard's port first: a port in use should stop the demo before the work.
    dashboard = _dashboard(options.port) if options.serve else None
    _step("Neo4j")
    _neo4j_up()
    _step(f"Simulating {options.runs} run(s) of the agri mission")
    bags = _simulate(options)
    _step("Preparing the recordings into an event log")
    log = _prepare(bags, options.folder / "agri.csv")
    _step("Building the event knowledge graphs")
    _ingest(log, AGRI_LOG, bags)
    _ingest(read_log(thesis), THESIS_LOG_NAME, thesis)
    _attach_models()
    _explain()
    if dashboard is not None:
        _serve(dashboard)
    return 0


def source_file(relative: Path) -> Path:
    """A file of robotale's source checkout (or below the current directory)."""
    for root in (Path(__file__).resolve().parents[2], Path.cwd()):
        if (root / relative).is_file():
            return root / relative
    raise InputError(f"{relative} was not found; run the demo from robotale's source tree.")


def _step(title: str) -> None:
    print(f"\n== {title}", flush=True)


def _neo4j_up() -> None:
    if os.environ.get("NEO4J_URI"):
        connect().close()  # a server that is down should stop the demo before the simulation
        print(f"Using the Neo4j at {os.environ['NEO4J_URI']} (NEO4J_URI)")
        return
    server = LocalServer()
    running = server.start(ServerOptions.from_env())
    print(f"Neo4j is running at {running.bolt_uri}; Neo4j Browser: {running.browser_url}")
    print(f"  user neo4j, password in {server.password_file}")


def _simulate(options: DemoOptions) -> Path:
    world, scenario = resolve_world("agri")
    check(world)
    batch = plans(world, scenario, runs=options.runs, seed=options.seed)
    target = options.folder / "runs"
    summary = simulate_batch(batch, target, overwrite=True, progress=True)
    print_summary(summary, target, sys.stdout)
    return target


def _prepare(bags: Path, csv: Path) -> pd.DataFrame:
    log = prepare_reporting(bags)
    write_csv(log, csv)
    print(f"{len(log):,} events from {log['case:concept:name'].nunique()} run(s) in {csv}")
    return log


def _ingest(log: pd.DataFrame, name: str, source: Path) -> None:
    store(log, name, source, entities=ENTITIES, aggregate=built_keys(ENTITIES))


def _attach_models() -> None:
    attach_model(AGRI_LOG, scenarios.model_file("agri"))
    attach_model(THESIS_LOG_NAME, source_file(THESIS_MODEL))


def _explain() -> None:
    print(
        "\nIn Neo4j Browser, the drone's and tractors' process across robots:\n"
        f"  MATCH (c:Class {{log: '{AGRI_LOG}', type: 'activity+robot'}})-[r:DF_C]->(d) "
        "RETURN c, r, d\n"
        "Both logs: `robotale logs list`; the prepared CSV works with `robotale discover`."
    )


def _dashboard(port: int) -> Dashboard:
    return Dashboard(port=port)


def _serve(dashboard: Dashboard) -> None:
    print("\nThe dashboard is up; open the address below.", flush=True)
    serve_until_interrupted(dashboard, discover_path(AGRI_LOG))
    print("Dashboard stopped; the logs stay in Neo4j (`robotale serve` shows them again).")
