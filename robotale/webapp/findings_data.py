"""The findings of stored logs as the Findings page shows them, computed once per version of a
log and kept in the app's cache; storing a log prepares them, so the first page after it is
ready at once."""

from __future__ import annotations

from typing import Any

from neo4j import Driver

from robotale.discovery.graph import json_ready
from robotale.enhancement.findings import find
from robotale.webapp.logdata import Cache, LogData, log_info


def stored_findings(driver: Driver, logs: LogData, cache: Cache, name: str) -> dict[str, Any]:
    """The answers for the stored log ``name`` and its runs (case, start, duration)."""
    version = str(log_info(driver, name).get("created"))

    def compute() -> dict[str, Any]:
        result = find(logs.frame(driver, name))
        runs = result.runs.reindex(columns=["case", "start", "duration"])
        return json_ready({**result.to_dict(), "runs": runs.to_dict(orient="records")})

    return cache.get((name, version), compute)
