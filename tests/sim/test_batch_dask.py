"""Batches on a Dask cluster: a LocalCluster with worker processes on loopback stands in for
machines sharing a folder. The cluster's runs must be the local pool's, byte for byte, and a
run that kills its worker must be reported while the other workers finish the batch."""

from __future__ import annotations

import json
import logging
import threading
from pathlib import Path

import dask
import pandas as pd
import pytest
from patience import patience
from simbags import manifest
from test_batch import east, rover_world

from robotale.cli import main
from robotale.errors import InputError
from robotale.eventlog.prepare import prepare, prepare_dataset
from robotale.eventlog.readers import read_log
from robotale.eventlog.writers import write_csv
from robotale.sim.batch import SUMMARY, simulate_batch
from robotale.sim.plans import adjust, plans

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def cluster():
    """Two single-threaded worker processes. A worker holds one run at a time (saturation
    1.0), so a worker's death is pinned on that run; its run is retried once elsewhere."""
    settings = {
        "distributed.scheduler.worker-saturation": 1.0,
        "distributed.scheduler.allowed-failures": 1,
    }
    with (
        dask.config.set(settings),
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=":0",
        ) as local,
    ):
        yield "dask://" + local.scheduler_address.removeprefix("tcp://")


def files(folder: Path) -> dict[str, bytes]:
    """Every bag file under ``folder`` by its path inside it (manifests apart: see below)."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and p.suffix != ".json"
    }


def manifests(folder: Path) -> dict[str, dict]:
    """The runs' manifests without the wall-clock time each took, the one thing that varies."""
    found = {p.parent.name: json.loads(p.read_text()) for p in folder.glob("run_*/*.json")}
    return {case: {k: v for k, v in m.items() if k != "wall_time"} for case, m in found.items()}


def test_a_dask_batch_writes_the_local_batchs_bags_and_log(tmp_path, short_agri, cluster):
    world = adjust(short_agri, time_limit=40)
    batch = plans(world, "agri", runs=3, seed=7)
    local = simulate_batch(batch, tmp_path / "local", executor="local:2")
    remote = simulate_batch(batch, tmp_path / "dask", executor=cluster)
    assert files(tmp_path / "local") == files(tmp_path / "dask")
    assert any(name.endswith(".db3") for name in files(tmp_path / "local"))
    assert manifests(tmp_path / "local") == manifests(tmp_path / "dask")
    assert len(manifests(tmp_path / "local")) == 3
    assert remote["executor"] == cluster and remote["workers"] == 2
    assert remote["cases"] == local["cases"]
    here = prepare(tmp_path / "local")
    parallel = prepare(tmp_path / "dask", executor=cluster)
    pd.testing.assert_frame_equal(here, parallel)
    assert sorted(here["case:concept:name"].unique()) == ["run_0001", "run_0002", "run_0003"]
    # each worker writes its run's part of the dataset; it reads back as the CSV
    write_csv(here, tmp_path / "agri.csv")
    written = prepare_dataset(tmp_path / "dask", tmp_path / "agri.parquet", executor=cluster)
    assert [p["rows"] for p in written["parts"]] == here.groupby(
        "case:concept:name"
    ).size().tolist()
    pd.testing.assert_frame_equal(
        read_log(tmp_path / "agri.csv"), read_log(tmp_path / "agri.parquet")
    )


def test_the_commands_take_a_dask_executor(tmp_path, short_agri, cluster, capsys):
    out = tmp_path / "agri"
    args = ["simulate", "agri", "--runs", "2", "--tractors", "1", "--weeds", "1"]
    args += ["--time-limit", "30", "--out", str(out), "--quiet", "--executor", cluster]
    assert main(args) == 0
    assert f"2 workers on {cluster}" in capsys.readouterr().out
    csv = tmp_path / "agri.csv"
    assert main(["prepare", str(out), "--out", str(csv), "--executor", cluster]) == 0
    assert main(["prepare", str(out), "--out", str(tmp_path / "here.csv")]) == 0
    assert csv.read_bytes() == (tmp_path / "here.csv").read_bytes()
    written = pd.read_csv(csv)
    assert written["case"].nunique() == 2


def test_a_run_that_kills_its_dask_worker_is_reported_and_the_others_finish(tmp_path, cluster):
    # where each rover starts, from the same seeds in a harmless world
    calm = rover_world(tmp_path / "calm", "pass")
    simulate_batch(plans(calm, "rover", runs=4, seed=5), tmp_path / "calm_runs", workers=0)
    starts = {
        f"run_{i:04d}": manifest(tmp_path / "calm_runs" / f"run_{i:04d}") for i in range(1, 5)
    }
    world = rover_world(tmp_path / "model", "import os; os._exit(3)")
    out = tmp_path / "runs"
    summary = simulate_batch(plans(world, "rover", runs=4, seed=5), out, executor=cluster)
    runs = {case: manifest(out / case) for case in starts}
    died = {case for case, run in starts.items() if east(run)}
    assert died and len(died) < 4  # the seed starts some rovers east of their base
    for case, run in runs.items():
        if case in died:
            assert run["outcome"]["status"] == "crashed"
            assert "worker process running it died" in run["outcome"]["reason"]
            assert not (out / case / "metadata.yaml").exists()
        else:
            assert run["outcome"]["status"] == "ended"
            assert (out / case / "metadata.yaml").is_file()
    assert summary["outcomes"] == {"crashed": len(died), "ended": 4 - len(died)}
    assert json.loads((out / SUMMARY).read_text())["outcomes"] == summary["outcomes"]
    assert not list(out.glob(".*"))


@pytest.mark.parametrize("text", ["dask:/x", "local:two", "spark://h:1"])
def test_an_unknown_executor_is_refused_in_one_sentence(tmp_path, text):
    world = rover_world(tmp_path / "model", "pass")
    with pytest.raises(InputError, match=r"^--executor .*: use local, local:N .*dask://HOST:PORT"):
        simulate_batch(plans(world, "rover", runs=1, seed=1), tmp_path / "runs", executor=text)
    assert not (tmp_path / "runs").exists()


def test_a_scheduler_that_does_not_answer_is_named(tmp_path):
    world = rover_world(tmp_path / "model", "pass")
    with pytest.raises(InputError, match=r"dask://127\.0\.0\.1:9: no Dask scheduler answers"):
        simulate_batch(
            plans(world, "rover", runs=2, seed=1), tmp_path / "runs", executor="dask://127.0.0.1:9"
        )


@pytest.fixture(scope="module")
def ftp(tmp_path_factory):
    """An FTP server on loopback (pyftpdlib), serving a folder of this machine: a
    destination the workers reach only through fsspec's ftp:// filesystem."""
    from pyftpdlib.authorizers import DummyAuthorizer
    from pyftpdlib.handlers import FTPHandler
    from pyftpdlib.servers import ThreadedFTPServer

    logging.getLogger("pyftpdlib").setLevel(logging.WARNING)
    home = tmp_path_factory.mktemp("ftp")
    users = DummyAuthorizer()
    users.add_user("robot", "secret", str(home), perm="elradfmwMT")
    users.add_user("reader", "secret", str(home), perm="elr")  # may list and read, not write
    handler = type("Handler", (FTPHandler,), {"authorizer": users})
    server = ThreadedFTPServer(("127.0.0.1", 0), handler)
    serving = threading.Thread(target=server.serve_forever, kwargs={"timeout": 0.2}, daemon=True)
    serving.start()
    port = server.socket.getsockname()[1]
    yield f"ftp://robot:secret@127.0.0.1:{port}", home
    server.close_all()
    serving.join(timeout=5)


def test_runs_and_a_dataset_written_to_an_ftp_url_are_the_local_ones(
    tmp_path, short_agri, cluster, ftp
):
    url, home = ftp
    # a test before may have killed workers: their nannies bring them back
    with distributed.Client(cluster.replace("dask://", "tcp://")) as client:
        client.wait_for_workers(2, timeout=patience(120))
    world = adjust(short_agri, time_limit=30)
    batch = plans(world, "agri", runs=2, seed=3)
    local = tmp_path / "local"
    simulate_batch(batch, f"file://{local}", executor="local:2")
    summary = simulate_batch(batch, f"{url}/runs/agri", executor=cluster)
    uploaded = home / "runs" / "agri"
    assert files(uploaded) == files(local) and len(files(local)) > 2
    assert manifests(uploaded) == manifests(local)
    assert json.loads((uploaded / SUMMARY).read_text())["cases"] == summary["cases"]
    assert not list(uploaded.glob(".*"))
    again = simulate_batch(batch, f"{url}/runs/agri", executor=cluster, overwrite=True)
    assert again["outcomes"] == summary["outcomes"]
    with pytest.raises(InputError, match=r"runs/agri already holds recorded runs \(run_0001"):
        simulate_batch(batch, f"{url}/runs/agri", executor=cluster)
    write_csv(prepare(local), tmp_path / "agri.csv")
    assert (
        main(["prepare", str(uploaded), "--out", f"{url}/agri.parquet", "--executor", cluster]) == 0
    )
    pd.testing.assert_frame_equal(read_log(tmp_path / "agri.csv"), read_log(home / "agri.parquet"))
    assert main(["prepare", str(uploaded), "--out", f"{url}/agri.csv"]) == 0
    assert (home / "agri.csv").read_bytes() == (tmp_path / "agri.csv").read_bytes()


def test_a_destination_that_refuses_writes_is_one_sentence(tmp_path, short_agri, ftp):
    url, home = ftp
    reader = url.replace("robot:secret", "reader:secret")
    batch = plans(adjust(short_agri, time_limit=30), "agri", runs=1, seed=3)
    before = sorted(home.rglob("*"))
    with pytest.raises(InputError) as refused:
        simulate_batch(batch, f"{reader}/refused/agri", executor="local:1")
    message = str(refused.value)
    assert message.startswith(f"{reader}/refused/agri could not be written: ")
    assert "\n" not in message and "550" in message  # the FTP server's own refusal
    assert sorted(home.rglob("*")) == before
