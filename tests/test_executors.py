"""Stopping a pool's work after one run failed: what a running worker writes lands before
the caller cleans up, unless the user interrupted."""

import multiprocessing
import subprocess
from concurrent.futures import FIRST_EXCEPTION, ProcessPoolExecutor, wait

import pytest

from robotale.executors import stop_all


def _started(tmp_path, touched):
    """A pool of two: one task failing at once, one writing ``touched`` after a second, and
    eight waiting for a free worker."""
    pool = ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn"))
    slow = ["sh", "-c", f"sleep 1 && touch {touched}"]
    futures = [pool.submit(subprocess.run, slow, check=True)]
    futures.append(pool.submit(subprocess.run, ["false"], check=True))
    futures += [pool.submit(subprocess.run, slow, check=True) for _ in range(8)]
    done, _ = wait(futures, return_when=FIRST_EXCEPTION)
    assert futures[1] in done
    return pool, futures


def test_a_failure_cancels_what_waits_and_waits_for_what_runs(tmp_path):
    touched = tmp_path / "written"
    pool, futures = _started(tmp_path, touched)
    stop_all(futures, subprocess.CalledProcessError(1, "false"))
    assert touched.exists()  # the running task finished before stop_all returned
    assert all(future.done() for future in futures)  # nothing of the pool still runs
    assert futures[-1].cancelled()  # the pool hands a few tasks ahead to its workers
    pool.shutdown(wait=True)


def test_an_interrupt_does_not_wait_for_what_runs(tmp_path):
    touched = tmp_path / "written"
    pool, futures = _started(tmp_path, touched)
    stop_all(futures, KeyboardInterrupt())
    assert not touched.exists()
    assert futures[-1].cancelled()
    pool.shutdown(wait=True)
    assert touched.exists()


@pytest.mark.parametrize("error", [ValueError("x"), KeyboardInterrupt()])
def test_stopping_finished_work_returns_at_once(error):
    with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
        futures = [pool.submit(abs, -1)]
        wait(futures)
        stop_all(futures, error)
        assert futures[0].result() == 1
