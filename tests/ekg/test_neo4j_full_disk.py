"""A disk too small for a log under robotale's local Neo4j: a real small filesystem (tmpfs)
as the server's data directory, and a log larger than it. The free-space check refuses the
log before anything is written; past the check, the disk fills while the log is written and
the unfinished log is named with the command that removes it."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from robotale.cli import main
from robotale.commands import ingest
from robotale.neo4j_server.server import LocalServer, PortInUse, ServerOptions, free_ports

pytestmark = pytest.mark.slow


def _larger_than_the_disk(path, events: int) -> None:
    numbers = np.arange(events)
    pd.DataFrame(
        {
            "case": [f"run_{n // 1000:04d}" for n in numbers],
            "activity": [f"step_{n % 37}" for n in numbers],
            "timestamp": pd.Timestamp("2024-01-01", tz="UTC") + pd.to_timedelta(numbers, "s"),
            "robot": [f"robot_{n % 5}" for n in numbers],
            # a long value per event: the property store grows past the disk quickly, with
            # few events for robotale to prepare twice
            "note": [f"note {n:08d} " * 120 for n in numbers],
        }
    ).to_csv(path, index=False)


def test_a_full_disk_under_neo4j_is_one_sentence_naming_it(
    tmp_path, small_disk, monkeypatch, capsys
):
    home = tmp_path / "home"
    (home / "neo4j").mkdir(parents=True)
    disk = small_disk("48m")
    (home / "neo4j" / "data").symlink_to(disk)
    # Neo4j preallocates its transaction logs (256 MB each) unless told not to
    (home / "neo4j.conf").write_text("db.tx_log.preallocate=false\ndb.tx_log.rotation.size=1M\n")
    for name in ("NEO4J_URI", "NEO4J_USER", "NEO4J_PASSWORD"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("ROBOTALE_HOME", str(home))
    server = LocalServer(home)
    _start(server)
    try:
        log = tmp_path / "big.csv"
        _larger_than_the_disk(log, 20_000)
        assert log.stat().st_size > 48 * 1024**2 / 3

        # the check before the write: one sentence, and nothing of the log in Neo4j
        free = shutil.disk_usage(disk).free
        assert main(["ingest", str(log), "--log", "big"]) == 1
        refused = capsys.readouterr().err.strip().splitlines()[-1]
        assert refused.startswith("robotale: Neo4j's data folder "), refused
        assert "'big' (20,000 events) needs about " in refused
        data = refused.split("Neo4j's data folder ", 1)[1].split(" has ", 1)[0]
        assert Path(data).resolve() == disk.resolve()
        said_free = float(refused.split(" has ", 1)[1].split(" MB free", 1)[0])
        assert abs(said_free - free / 1024**2) < 4  # Neo4j writes a little meanwhile
        assert main(["logs", "list"]) == 0
        assert "big" not in capsys.readouterr().out

        # Past the check (the fault it guards against is what is tested now, so the check is
        # replaced, at the one place the command calls it): Neo4j's own full disk.
        monkeypatch.setattr(ingest, "check_space", lambda *args, **kwargs: None)
        assert main(["ingest", str(log), "--log", "big"]) == 1
        error = capsys.readouterr().err.strip().splitlines()[-1]
        said = [line for line in _debug_log(server) if "space" in line.lower()][:5]
        assert error.startswith("robotale: Neo4j's disk is full: it could not "), (error, said)
        assert f"on the disk of {disk} (" in error
        assert "the log 'big' was not" in error
        assert "robotale logs delete big" in error or "nothing of it was kept" in error
    finally:
        server.stop()


def _start(server: LocalServer) -> None:
    for attempt in range(3):  # a free port can be taken before Neo4j binds it
        try:
            server.start(ServerOptions(*free_ports(2), heap="512m", pagecache="64m"))
            return
        except PortInUse:
            if attempt == 2:
                raise


def _debug_log(server: LocalServer) -> list[str]:
    return server.log_file.with_name("debug.log").read_text(errors="replace").splitlines()
