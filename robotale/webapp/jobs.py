"""Long work the dashboard does in the background (reading an upload, building an EKG).

One worker thread runs the jobs in turn, so two ingests never compete for Neo4j; the page
polls ``/api/jobs/<id>`` for the job's stage and progress. Jobs live in memory: the dashboard
is one process.
"""

from __future__ import annotations

import secrets
import threading
import time
import traceback
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import asdict, dataclass, field
from typing import Any

from robotale.errors import RobotaleError

#: finished jobs are forgotten after this many seconds
KEEP = 3600


@dataclass
class Job:
    id: str
    title: str
    stage: str = "waiting"
    done: int = 0
    total: int = 0
    finished: bool = False
    error: str | None = None
    #: what the work returned, for the page to show (and link to)
    result: dict[str, Any] = field(default_factory=dict)
    ended_at: float = 0.0

    def step(self, stage: str, done: int = 0, total: int = 0) -> None:
        self.stage, self.done, self.total = stage, done, total

    def to_dict(self) -> dict[str, Any]:
        data = asdict(self)
        data.pop("ended_at")
        return data


class Jobs:
    def __init__(self) -> None:
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="robotale-job")
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()

    def submit(self, title: str, work: Callable[[Job], dict[str, Any]]) -> Job:
        """Run ``work(job)`` in the background; it reports progress through ``job.step``."""
        job = Job(secrets.token_hex(8), title)
        with self._lock:
            self._forget_old()
            self._jobs[job.id] = job
        self._pool.submit(_run, job, work)
        return job

    def get(self, job_id: str) -> Job | None:
        with self._lock:
            return self._jobs.get(job_id)

    def _forget_old(self) -> None:
        limit = time.time() - KEEP
        for job_id in [j.id for j in self._jobs.values() if j.finished and j.ended_at < limit]:
            del self._jobs[job_id]


def _run(job: Job, work: Callable[[Job], dict[str, Any]]) -> None:
    try:
        job.result = work(job) or {}
        job.stage = "done"
    except RobotaleError as error:
        job.error = str(error)
    except Exception as error:  # the page must learn that the job ended, whatever happened
        traceback.print_exc()
        job.error = f"The job failed unexpectedly ({type(error).__name__}: {error})."
    finally:
        job.finished = True
        job.ended_at = time.time()
