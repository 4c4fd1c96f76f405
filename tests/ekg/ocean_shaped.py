"""Object-centric logs shaped like OCEAN's published datasets, generated with a seed, and the
aggregation specifications OCEAN runs on them.

- a logistics log: containers, customer orders, forklifts, trucks and vehicles (each event
  names one or more objects of some types; a cell may list several), with a container's
  Status, Weight and Amount_of_Handling_Units, an order's Type and Amount_of_Goods;
- an order-management log: orders, items, customers, employees and packages, with an
  order's price and type and a customer's segment.

Each generator returns the events (a CSV robotale ingests with one ``--entities`` column per
object type) and one attribute table per object type (``id`` and the attributes of the
objects the events name), which the tests set on the Entity nodes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

START = pd.Timestamp("2024-01-01T00:00:00Z")


@dataclass(frozen=True)
class ObjectLog:
    events: pd.DataFrame  # time, activity, event_id and one column per object type
    objects: dict[str, pd.DataFrame]  # type -> id and attributes
    types: list[str]


def _objects(rng: np.random.Generator, prefix: str, count: int) -> np.ndarray:
    return np.array([f"{prefix}{i}" for i in range(count)], dtype=object)


def _cells(rng: np.random.Generator, pool: np.ndarray, n: int, share: float, most: int) -> list:
    """One cell per event: empty for about 1 - ``share`` of them, else 1 .. ``most`` distinct
    objects of ``pool`` joined by commas."""
    sizes = rng.integers(1, most + 1, n)
    first = rng.integers(0, len(pool), n)
    stride = rng.integers(1, max(len(pool) // most, 1) + 1, n)  # keeps the objects distinct
    cells = pd.Series(pool[first], dtype=object)
    for extra in range(1, most):
        more = sizes > extra
        others = pd.Series(pool[(first + extra * stride) % len(pool)], dtype=object)
        cells[more] = cells[more] + "," + others[more]
    cells[rng.random(n) >= share] = None
    return cells.tolist()


def _frame(rng: np.random.Generator, n: int, activities: list[str], span_days: int) -> dict:
    seconds = np.sort(rng.integers(0, span_days * 86400, n))
    return {
        "time": (START + pd.to_timedelta(seconds, unit="s")).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "activity": rng.choice(activities, n),
        "event_id": [f"ev{i}" for i in range(n)],
    }


def _referenced(events: pd.DataFrame, kind: str) -> set[str]:
    cells = events[kind].dropna().str.split(",")
    return {name for names in cells for name in names}


LOGISTICS_ACTIVITIES = ["Register Customer Order", "Create Transport Document",
                        "Book Vehicles", "Order Empty Containers", "Pick Up Empty Container",
                        "Load Truck", "Drive to Terminal", "Weigh", "Place in Stock",
                        "Bring to Loading Bay", "Load to Vehicle", "Depart"]  # fmt: skip
LOGISTICS_SHARES = {"Container": 0.8, "Customer_Order": 0.5, "Forklift": 0.3, "Truck": 0.3,
                    "Vehicle": 0.2}  # fmt: skip


@dataclass(frozen=True)
class _Draws:
    """The logistics log as integers (no text per event): what :func:`logistics` builds at
    once and :func:`write_logistics` writes a slice at a time, drawn in the same order."""

    seconds: np.ndarray  # since START, sorted
    activities: np.ndarray  # index into LOGISTICS_ACTIVITIES
    pools: dict[str, np.ndarray]  # type -> object names
    first: dict[str, np.ndarray]  # type -> index into its pool per event, -1: no object
    second: dict[str, np.ndarray]  # type -> a second object's index, -1: none


def _logistics_draws(rng: np.random.Generator, n: int) -> _Draws:
    pools = {
        "Container": _objects(rng, "cr", max(n // 6, 4)),
        "Customer_Order": _objects(rng, "co", max(n // 15, 4)),
        "Forklift": _objects(rng, "fl", 6),
        "Truck": _objects(rng, "tr", 12),
        "Vehicle": _objects(rng, "vh", max(n // 60, 3)),
    }
    seconds = np.sort(rng.integers(0, 120 * 86400, n))
    # rng.choice over a list draws these same integers
    activities = rng.integers(0, len(LOGISTICS_ACTIVITIES), n).astype(np.int8)
    first, second = {}, {}
    for kind, pool in pools.items():
        # as _cells draws them: up to two distinct objects, none for 1 - share of the events
        most = 2 if kind == "Container" else 1
        sizes = rng.integers(1, most + 1, n)
        one = rng.integers(0, len(pool), n)
        stride = rng.integers(1, max(len(pool) // most, 1) + 1, n)
        absent = rng.random(n) >= LOGISTICS_SHARES[kind]
        first[kind] = np.where(absent, -1, one).astype(np.int32)
        other = np.where(sizes > 1, (one + stride) % len(pool), -1)
        second[kind] = np.where(absent, -1, other).astype(np.int32)
        del sizes, one, stride, absent, other
    return _Draws(seconds, activities, pools, first, second)


def _logistics_events(draws: _Draws, start: int, stop: int) -> pd.DataFrame:
    """Events ``start`` .. ``stop`` - 1 as text, the columns a CSV of the log has."""
    columns = {
        "time": (START + pd.to_timedelta(draws.seconds[start:stop], unit="s")).strftime(
            "%Y-%m-%dT%H:%M:%SZ"
        ),
        "activity": np.array(LOGISTICS_ACTIVITIES, dtype=object)[draws.activities[start:stop]],
        "event_id": [f"ev{i}" for i in range(start, stop)],
    }
    for kind, pool in draws.pools.items():
        one, other = draws.first[kind][start:stop], draws.second[kind][start:stop]
        cells = pd.Series(pool[np.maximum(one, 0)], dtype=object)
        two = other >= 0
        cells[two] = cells[two] + "," + pd.Series(pool[other[two]], dtype=object).to_numpy()
        cells[one < 0] = None
        columns[kind] = cells.tolist()
    return pd.DataFrame(columns)


def _logistics_objects(rng: np.random.Generator, draws: _Draws) -> dict[str, pd.DataFrame]:
    """One table per type: the objects some event names, sorted by id, and their attributes
    (drawn after the events, as :func:`logistics` always did)."""
    objects = {}
    for kind, pool in draws.pools.items():
        named = np.concatenate([draws.first[kind], draws.second[kind]])
        used = np.unique(named[named >= 0])
        objects[kind] = pd.DataFrame({"id": sorted(pool[used].tolist())})
    containers = objects["Container"]
    containers["Status"] = rng.choice(["empty", "loaded", "in stock"], len(containers))
    containers["Weight"] = np.round(rng.uniform(1000, 30000, len(containers)), 1)
    containers["Amount_of_Handling_Units"] = rng.integers(1, 40, len(containers))
    orders = objects["Customer_Order"]
    orders["Type"] = rng.choice(["standard", "express"], len(orders))
    orders["Amount_of_Goods"] = rng.integers(100, 3000, len(orders))
    vehicles = objects["Vehicle"]
    vehicles["Capacity"] = rng.integers(10, 60, len(vehicles))
    return objects


def logistics(n: int, seed: int = 3) -> ObjectLog:
    rng = np.random.default_rng(seed)
    draws = _logistics_draws(rng, n)
    events = _logistics_events(draws, 0, n)
    return ObjectLog(events, _logistics_objects(rng, draws), list(draws.pools))


def write_logistics(n: int, folder: Path, seed: int = 3, chunk: int = 200_000) -> list[str]:
    """:func:`logistics` written to ``folder`` a slice of ``chunk`` events at a time (the same
    log, byte for byte, without holding its text): ``events.csv`` and ``objects/<Type>.csv``
    (as ``robotale ingest --objects`` reads them). Returns the object types."""
    rng = np.random.default_rng(seed)
    draws = _logistics_draws(rng, n)
    events = folder / "events.csv"
    for start in range(0, n, chunk):
        part = _logistics_events(draws, start, min(start + chunk, n))
        part.to_csv(events, index=False, header=start == 0, mode="w" if start == 0 else "a")
    (folder / "objects").mkdir(exist_ok=True)
    for kind, table in _logistics_objects(rng, draws).items():
        table.to_csv(folder / "objects" / f"{kind}.csv", index=False)
    return list(draws.pools)


def order_management(n: int, seed: int = 5) -> ObjectLog:
    rng = np.random.default_rng(seed)
    activities = ["place order", "confirm order", "pick item", "pay order", "item out of stock",
                  "reorder item", "create package", "send package", "package delivered",
                  "payment reminder"]  # fmt: skip
    pools = {
        "orders": _objects(rng, "o", max(n // 8, 4)),
        "items": _objects(rng, "i", max(n // 3, 4)),
        "customers": _objects(rng, "c", max(n // 40, 4)),
        "employees": _objects(rng, "em", 8),
        "packages": _objects(rng, "p", max(n // 20, 3)),
    }
    shares = {"orders": 0.9, "items": 0.6, "customers": 0.4, "employees": 0.5, "packages": 0.2}
    columns = _frame(rng, n, activities, 60)
    for kind, pool in pools.items():
        columns[kind] = _cells(rng, pool, n, shares[kind], 3 if kind == "items" else 1)
    events = pd.DataFrame(columns)
    objects = {kind: pd.DataFrame({"id": sorted(_referenced(events, kind))}) for kind in pools}
    orders = objects["orders"]
    orders["price"] = np.round(rng.uniform(10, 2500, len(orders)), 2)
    orders["channel"] = rng.choice(["web", "shop", "phone"], len(orders))
    customers = objects["customers"]
    customers["segment"] = rng.choice(["private", "business"], len(customers))
    items = objects["items"]
    items["weight"] = np.round(rng.uniform(0.1, 20, len(items)), 3)
    return ObjectLog(events, objects, list(pools))


LOGISTICS_SPEC = {
    "steps": [
        {"aggr_type": "ENTITIES", "ent_type": "Container", "group_by": ["Status"],
         "attr_aggrs": [{"name": "id", "function": "MULTISET"},
                        {"name": "Weight", "function": "AVG"},
                        {"name": "Amount_of_Handling_Units", "function": "MINMAX"}]},
        {"aggr_type": "ENTITIES", "ent_type": "Customer_Order", "group_by": ["Type"],
         "where": "Amount_of_Goods >= 1000",
         "attr_aggrs": [{"name": "Amount_of_Goods", "function": "SUM"}]},
        {"aggr_type": "ENTITIES", "ent_type": "Customer_Order", "group_by": ["Type"],
         "where": "Amount_of_Goods < 1000",
         "attr_aggrs": [{"name": "Amount_of_Goods", "function": "MIN"},
                        {"name": "Amount_of_Goods", "function": "MAX"}]},
        {"aggr_type": "EVENTS", "group_by": ["activity", "Customer_Order"],
         "where": 'timestamp <= datetime("2024-03-01T00:00:00")',
         "attr_aggrs": [{"name": "timestamp", "function": "MINMAX"}]},
        {"aggr_type": "EVENTS", "group_by": ["activity"],
         "where": 'timestamp > datetime("2024-03-01T00:00:00")',
         "attr_aggrs": [{"name": "timestamp", "function": "MIN"}]},
    ]
}  # fmt: skip

ORDER_MANAGEMENT_SPEC = {
    "steps": [
        {"aggr_type": "ENTITIES", "ent_type": "customers", "group_by": ["segment"],
         "attr_aggrs": [{"name": "id", "function": "MULTISET"}]},
        {"aggr_type": "ENTITIES", "ent_type": "orders", "group_by": ["type"],
         "where": "price >= 1000", "attr_aggrs": [{"name": "price", "function": "AVG"}]},
        {"aggr_type": "ENTITIES", "ent_type": "orders", "group_by": ["channel"],
         "where": "price < 1000", "attr_aggrs": [{"name": "price", "function": "AVG"}]},
        {"aggr_type": "EVENTS", "group_by": ["activity"]},
    ]
}  # fmt: skip
