"""Whether Neo4j's disk has room for a log, asked before anything of it is written.

The estimate counts what the build writes: one node per event (entities and classes are few
beside them), the relationships (CORR and DF per entity value of an event, OBSERVED per event
and class key) and the events' values; each multiplied by the bytes Neo4j 5 takes per item on
its disk (store files, indexes and transaction logs together: :data:`PER_EVENT`,
:data:`PER_RELATIONSHIP`, :data:`PER_VALUE_BYTE`, from the sizes of its records, each written
once to the store and once to the transaction log), and then by :data:`MARGIN`. It guards
against the certain failure and promises nothing: a log that needs more than estimated still
meets Neo4j's own full disk (:mod:`robotale.ekg.disk_full`).

The check runs when the server's data folder is on this machine (robotale's local server, or
a ``NEO4J_URI`` on this host); a server elsewhere keeps its disk to itself and is not checked.
"""

from __future__ import annotations

import shutil
from collections.abc import Sequence
from pathlib import Path
from urllib.parse import urlsplit

import pandas as pd
from neo4j import Driver
from neo4j.exceptions import Neo4jError

from robotale.ekg.connection import database, settings
from robotale.ekg.disk_full import size_text
from robotale.errors import InputError
from robotale.queries import cypher

#: bytes on Neo4j's disk per event node: its record (15 bytes) and property records (41
#: bytes per four values), its entries in the indexes on the log, id and activity, each
#: twice (store and transaction log)
PER_EVENT = 600
#: bytes per relationship: its record (34 bytes), its type's property record, twice
PER_RELATIONSHIP = 200
#: bytes per byte of the events' values as text: the string store's 128-byte blocks hold
#: 120 bytes each, and the transaction log holds the value again
PER_VALUE_BYTE = 2.5
#: the estimate's safety factor: Neo4j grows its files in steps and keeps old log files
MARGIN = 1.25
_LOCAL_HOSTS = {"localhost", "127.0.0.1", "::1"}


class NotEnoughSpace(InputError):
    """Neo4j's disk has less room than the log needs."""


def needed_bytes(events: pd.DataFrame, entities: Sequence[str], keys: int) -> int:
    """The estimated bytes Neo4j's disk takes for ``events`` built with these entity
    columns and ``keys`` class keys."""
    count = len(events)
    present = [column for column in entities if column in events.columns]
    correlations = int(sum(events[column].notna().sum() for column in present))
    relationships = 2 * correlations + keys * count  # CORR and DF, OBSERVED
    return int(
        MARGIN
        * (
            count * PER_EVENT
            + relationships * PER_RELATIONSHIP
            + _value_bytes(events) * PER_VALUE_BYTE
        )
    )


#: rows whose values are measured at most: a larger log's are scaled from every n-th row
SAMPLE = 20_000


def _value_bytes(events: pd.DataFrame) -> int:
    step = max(1, len(events) // SAMPLE)
    return step * _measured_bytes(events.iloc[::step])


def _measured_bytes(events: pd.DataFrame) -> int:
    total = 0
    for column in events.columns:
        values = events[column]
        if values.dtype == object or isinstance(values.dtype, pd.StringDtype):
            total += int(values.dropna().astype(str).str.len().sum())
        else:
            total += 8 * int(values.notna().sum())
    return total


def data_folder(driver: Driver) -> Path | None:
    """The server's data folder when it is on this machine, else None."""
    if urlsplit(settings().uri).hostname not in _LOCAL_HOSTS:
        return None
    try:
        records, _, _ = driver.execute_query(cypher("server_data_directory"), database_=database())
    except Neo4jError:  # a user who may not read the settings: nothing to check against
        return None
    folder = Path(str(records[0]["folder"])) if records else None
    return folder if folder is not None and folder.is_dir() else None


def check_space(
    driver: Driver, events: pd.DataFrame, name: str, entities: Sequence[str], keys: int
) -> None:
    """Raise :class:`NotEnoughSpace` when the disk of Neo4j's data folder has less free space
    than storing ``events`` as the log ``name`` needs (:func:`needed_bytes`)."""
    folder = data_folder(driver)
    if folder is None:
        return
    needed = needed_bytes(events, entities, keys)
    free = shutil.disk_usage(folder).free
    if needed > free:
        raise NotEnoughSpace(
            f"Neo4j's data folder {folder} has {size_text(free)} free and storing the log "
            f"{name!r} ({len(events):,} events) needs about {size_text(needed)}: free space "
            "there (or delete logs with `robotale logs delete`) and ingest again."
        )
