"""What the console does about a query that ran past its time: Neo4j sets the transaction's
timeout, but a query in a tight loop (``reduce`` over a long ``range``, a regular expression
that backtracks) does not look at it and keeps running. The watchdog finds the request's
transactions by their metadata (``SHOW TRANSACTIONS``), terminates them, looks again, and says
in one sentence what became of them; one that still runs is also logged for whoever runs the
dashboard.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass

from neo4j import Driver
from neo4j.exceptions import DriverError, Neo4jError

from robotale.queries import cypher

log = logging.getLogger(__name__)
#: seconds the watchdog waits for terminated transactions to be gone
SETTLE = 5.0


@dataclass(frozen=True)
class Outcome:
    #: the request's transactions found on the server when the time was up
    found: tuple[str, ...]
    #: those still there after they were terminated
    still_running: tuple[str, ...]
    #: why they could not be looked at or terminated ("" when they could)
    failure: str = ""


def stop(driver: Driver, request: str, settle: float = SETTLE) -> Outcome:
    """Terminate the transactions of console request ``request`` and wait up to ``settle``
    seconds for them to end."""
    try:
        found = _running(driver, request)
        if found:
            driver.execute_query(cypher("console_terminate"), ids=list(found))
        still = found
        deadline = time.monotonic() + settle
        while still and time.monotonic() < deadline:
            time.sleep(0.5)
            still = _running(driver, request)
    except (Neo4jError, DriverError) as error:
        return Outcome((), (), str(getattr(error, "message", None) or error).splitlines()[0])
    outcome = Outcome(found, still)
    if still:
        log.warning("console query %s still runs after TERMINATE TRANSACTIONS: %s", request, still)
    return outcome


def _running(driver: Driver, request: str) -> tuple[str, ...]:
    records, _, _ = driver.execute_query(cypher("console_transactions"), request=request)
    return tuple(str(record["transactionId"]) for record in records)


def sentence(outcome: Outcome, seconds: float) -> str:
    """What the user reads about a query that did not answer within ``seconds``."""
    narrow = "narrow it (a LIMIT, a WHERE on the log)"
    if outcome.failure:
        return (
            f"The query did not finish within {seconds:.0f} s, and robotale could not look "
            f"for it on the server to end it ({outcome.failure}); {narrow}."
        )
    if not outcome.found:
        return f"The query did not finish within {seconds:.0f} s: {narrow}."
    ids = ", ".join(outcome.found)
    if outcome.still_running:
        return (
            f"The query ran past the console's {seconds:.0f} s, and Neo4j stopped it neither "
            f"then nor when robotale terminated it ({ids}): it still runs on the server and "
            "uses its CPU until it ends or Neo4j restarts (robotale neo4j stop, then start)."
        )
    return (
        f"The query ran past the console's {seconds:.0f} s without Neo4j stopping it, so "
        f"robotale terminated it ({ids}); {narrow}."
    )
