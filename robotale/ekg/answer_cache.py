"""The console's kept answers: an identical read-only query, with identical parameters and
limits, on a database that has not changed since, is answered from memory.

Neo4j decides what *unchanged* means: the bookmark a read transaction commits with names the
last transaction committed to its database, so two bookmarks are equal exactly when nothing
was committed in between, by robotale (ingest, append, delete, aggregate, monitor) or by
anyone else. Every lookup commits a read transaction of ``RETURN 1`` for the current bookmark
(a round trip that costs Neo4j no work); an answer is kept only when the database's bookmark
was the same before and after it was computed, so one that may have seen a write half way is
not kept.

The key is the database, the exact text, the parameters (as sorted JSON) and the row and byte
limits; a cache belongs to one server and user (:class:`robotale.ekg.readonly.Connections`),
so no answer passes between databases, servers or users. At most :data:`ENTRIES` answers and
:data:`BYTES` bytes of their JSON, the least recently used forgotten first; an answer larger
than an eighth of that is not kept. Queries whose plan calls a function whose value changes
by itself (``rand()``, ``datetime()`` without arguments...) are never kept.

Identical requests arriving together are computed once: the others wait for the first (at
most its time limit) and take its answer.
"""

from __future__ import annotations

import json
import re
import threading
from collections import OrderedDict
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

import neo4j

from robotale.ekg.plan_check import operators
from robotale.queries import cypher

#: answers kept at most, per server and user
ENTRIES = 256
#: bytes of JSON kept at most, per server and user
BYTES = 16 * 1024 * 1024
#: text and parameters longer than this are not keys (they are asked of Neo4j every time)
KEY_BYTES = 64 * 1024

#: functions whose value is not decided by the graph: chance and the clock. A temporal
#: constructor reads the clock when given no value or only a time zone (also as a parameter),
#: so every call of one counts, except the conversions from epoch numbers
_VOLATILE = re.compile(
    r"\b(?:rand|randomUUID|timestamp)\s*\("
    r"|\b(?:date|datetime|time|localtime|localdatetime)"
    r"(?:\.(?!fromepoch(?:millis)?\b)\w+)?\s*\(",
    re.IGNORECASE,
)

Key = tuple[str, str, str, int, int]


def volatile(plan: Mapping[str, Any]) -> bool:
    """Whether ``plan`` (``EXPLAIN``'s, with Neo4j's own spelling of every expression) calls a
    function whose value changes without the graph changing."""
    return any(_VOLATILE.search(details) for _, details in operators(plan))


def mark(session: neo4j.Session) -> str:
    """The bookmark naming the last transaction committed to the session's database."""
    with session.begin_transaction(timeout=10) as tx:
        tx.run(cypher("console_mark")).consume()
        tx.commit()
    return "|".join(sorted(session.last_bookmarks().raw_values))


class AnswerCache:
    """Answers by (database, text, parameters, limits), each valid for one bookmark."""

    def __init__(self, entries: int = ENTRIES, size: int = BYTES) -> None:
        self.entries = entries
        self.size = size
        self._kept: OrderedDict[Key, tuple[str, str]] = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self._flights: dict[Key, tuple[threading.Lock, list[int]]] = {}

    def key(
        self, database: str, text: str, parameters: Mapping[str, Any], rows: int, size: int
    ) -> Key | None:
        try:
            values = json.dumps(parameters, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError):  # not plain JSON: ask Neo4j every time
            return None
        if len(values) + len(text) > KEY_BYTES:
            return None
        return (database, text, values, rows, size)

    def get(self, key: Key, at: str) -> list[dict[str, Any]] | None:
        """The answer kept for ``key`` when it was computed at bookmark ``at``."""
        with self._lock:
            found = self._kept.get(key)
            if found is None:
                return None
            if found[0] != at:  # the database changed since: never right again
                self._forget(key)
                return None
            self._kept.move_to_end(key)
            answer = found[1]
        kept: list[dict[str, Any]] = json.loads(answer)
        return kept

    def put(self, key: Key, at: str, answer: list[dict[str, Any]]) -> None:
        text = json.dumps(answer, allow_nan=False)
        if len(text) > self.size // 8:
            return
        with self._lock:
            if key in self._kept:
                self._forget(key)
            self._kept[key] = (at, text)
            self._bytes += len(text)
            while len(self._kept) > self.entries or self._bytes > self.size:
                self._forget(next(iter(self._kept)))

    def _forget(self, key: Key) -> None:
        _, text = self._kept.pop(key)
        self._bytes -= len(text)

    def __len__(self) -> int:
        return len(self._kept)

    @property
    def bytes(self) -> int:
        return self._bytes

    @contextmanager
    def alone(self, key: Key, wait: float) -> Iterator[None]:
        """Held by one request of ``key`` at a time (the others wait up to ``wait`` seconds,
        then go ahead anyway): a question twenty clients ask at once is computed once."""
        with self._lock:
            lock, users = self._flights.setdefault(key, (threading.Lock(), [0]))
            users[0] += 1
        held = lock.acquire(timeout=wait)
        try:
            yield
        finally:
            if held:
                lock.release()
            with self._lock:
                users[0] -= 1
                if not users[0]:
                    del self._flights[key]
