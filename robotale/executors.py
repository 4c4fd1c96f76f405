"""Where a batch's runs go: a process pool on this machine or a Dask distributed cluster.

``--executor`` takes ``local`` (one process per CPU), ``local:N`` (N processes) or
``dask://HOST:PORT`` (the scheduler of a cluster started with ``dask scheduler`` and
``dask worker``; see docs/scale.md). Both give a :class:`concurrent.futures.Executor`, so
``simulate`` and ``prepare`` submit runs the same way whichever executor runs them.
"""

from __future__ import annotations

import multiprocessing
import os
import re
from collections.abc import Iterable, Iterator
from concurrent.futures import Executor, Future, wait
from concurrent.futures import ProcessPoolExecutor as _Pool
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass

from robotale.errors import InputError

LOCAL, DASK = "local", "dask"
_DASK = re.compile(r"dask://(?P<host>[^:/\s]+):(?P<port>\d+)/?")
_LOCAL = re.compile(r"local(?::(?P<workers>\d+))?")
CONNECT_TIMEOUT = "10s"


@dataclass(frozen=True)
class ExecutorSpec:
    """An ``--executor`` value, parsed: ``kind`` is :data:`LOCAL` or :data:`DASK`."""

    kind: str
    workers: int | None = None  # local: processes (None: one per CPU)
    address: str | None = None  # dask: the scheduler's tcp:// address

    @property
    def remote(self) -> bool:
        return self.kind == DASK

    def describe(self) -> str:
        if not self.remote or self.address is None:
            return LOCAL
        return f"dask://{self.address.removeprefix('tcp://')}"


def parse_executor(text: str | None, workers: int | None = None) -> ExecutorSpec:
    """The executor ``text`` names (``None``: the local pool of ``workers`` processes)."""
    if text is None:
        return ExecutorSpec(LOCAL, workers)
    if local := _LOCAL.fullmatch(text.strip()):
        count = local["workers"]
        return ExecutorSpec(LOCAL, int(count) if count is not None else workers)
    if dask := _DASK.fullmatch(text.strip()):
        return ExecutorSpec(DASK, address=f"tcp://{dask['host']}:{dask['port']}")
    raise InputError(
        f"--executor {text!r}: use local, local:N (N worker processes) or dask://HOST:PORT "
        "(a Dask scheduler)"
    )


@contextmanager
def open_executor(spec: ExecutorSpec, tasks: int) -> Iterator[tuple[Executor, int]]:
    """An executor for ``tasks`` tasks and how many workers it has; shut down on exit."""
    if spec.remote:
        with _dask_executor(spec) as opened:
            yield opened
        return
    workers = max(1, min(spec.workers or os.cpu_count() or 1, tasks))
    # spawn: a fresh interpreter per worker, so pybullet and the engines start clean
    pool = _Pool(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
    try:
        yield pool, workers
    except BaseException:
        pool.shutdown(wait=False, cancel_futures=True)  # an interrupt does not wait for runs
        raise
    pool.shutdown(wait=True)


@contextmanager
def _dask_executor(spec: ExecutorSpec) -> Iterator[tuple[Executor, int]]:
    try:  # Dask is an optional extra (robotale[dask]) and 2.7 s to import: dask:// only
        from distributed import Client
    except ImportError:
        raise InputError(
            f"--executor {spec.describe()} needs Dask's distributed package: "
            "pip install 'robotale[dask]'"
        ) from None
    try:
        client = Client(spec.address, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError):
        raise InputError(
            f"--executor {spec.describe()}: no Dask scheduler answers there; start one with "
            "`dask scheduler` and workers with `dask worker` (see docs/scale.md)"
        ) from None
    try:
        workers = len(client.scheduler_info(n_workers=-1)["workers"])
        if workers == 0:
            raise InputError(
                f"--executor {spec.describe()}: the scheduler has no workers; start some with "
                f"`dask worker {spec.address}`"
            )
        yield client.get_executor(pure=False), workers
    finally:
        client.close()


def stop_all(futures: Iterable[Future[object]], error: BaseException) -> None:
    """After ``error`` stopped a caller collecting ``futures``: those not started are
    cancelled and, unless the user interrupted, those running are waited for, so nothing a
    worker writes lands after the caller has removed what the failed work left behind."""
    pending = [future for future in futures if not future.cancel()]
    if isinstance(error, Exception):
        wait(pending)


def worker_lost(error: BaseException) -> bool:
    """Whether ``error`` says the worker process running a task died (rather than the task
    raising): a broken local pool, or a task Dask gave up on after it killed its workers."""
    if isinstance(error, BrokenProcessPool):
        return True
    try:  # loaded already when a Dask cluster ran the task; absent without the extra
        from distributed import KilledWorker
    except ImportError:
        return False
    return isinstance(error, KilledWorker)
