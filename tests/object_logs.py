"""Object-centric logs generated for the tests, and pm4py's view of one to compare against.

:func:`order_log` is an order-management log as pm4py holds it (an ``OCEL`` object): orders,
items and packages, events relating to several objects with qualifiers, object-to-object
relations, attributes of every kind and attribute changes over time. :func:`logistics_csv`
writes a logistics log in the OCED style of OCEAN's published datasets: one column per object
type (forklifts, trucks, vehicles, containers; a cell may list several) and ``DIR/<Type>.csv``
attribute tables. Both are seeded, so a failure repeats.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from pm4py.objects.ocel.obj import OCEL

EID, OID, TYPE, ACT, TIME, QUAL = (
    "ocel:eid",
    "ocel:oid",
    "ocel:type",
    "ocel:activity",
    "ocel:timestamp",
    "ocel:qualifier",
)


def order_log(orders: int = 12, seed: int = 7) -> OCEL:
    """Orders of 1-3 items each, packed into packages and delivered."""
    rng = np.random.default_rng(seed)
    start = pd.Timestamp("2024-03-01T08:00:00Z")
    events, relations, objects, o2o, changes = [], [], [], [], []
    items = 0
    clock = start

    def event(activity: str, related: list[tuple[str, str]], **attributes: object) -> None:
        nonlocal clock
        clock += pd.Timedelta(seconds=int(rng.integers(30, 4000)))
        eid = f"e{len(events) + 1}"
        events.append({EID: eid, ACT: activity, TIME: clock, **attributes})
        relations.extend({EID: eid, OID: oid, QUAL: qualifier} for oid, qualifier in related)

    for number in range(1, orders + 1):
        order = f"o{number}"
        objects.append({OID: order, TYPE: "order", "priority": int(rng.integers(1, 4))})
        mine = []
        for _ in range(int(rng.integers(1, 4))):
            items += 1
            item = f"i{items}"
            mine.append(item)
            weight = round(float(rng.uniform(0.2, 9.0)), 3)
            objects.append({OID: item, TYPE: "item", "weight": weight, "colour": "red"})
            o2o.append({OID: order, "ocel:oid_2": item, QUAL: "comprises"})
        event(
            "place order",
            [(order, "order"), *((i, "item") for i in mine)],
            price=round(float(rng.uniform(5, 500)), 2),
            clerk=str(rng.choice(["ann", "bob", "cy"])),
        )
        for item in mine:
            event(
                "pick item",
                [(item, "picked"), (order, "for")],
                clerk=str(rng.choice(["ann", "bob"])),
            )
        package = f"p{number}"
        objects.append({OID: package, TYPE: "package"})
        o2o.append({OID: package, "ocel:oid_2": order, QUAL: "ships"})
        event("pack", [(package, "package"), *((i, "content") for i in mine)], boxes=len(mine))
        if rng.random() < 0.5:
            changes.append(
                {OID: mine[0], TYPE: "item", TIME: clock, "ocel:field": "colour", "colour": "blue"}
            )
        event("deliver", [(package, "delivered"), (order, "closes")])
    events_table = pd.DataFrame(events)
    objects_table = pd.DataFrame(objects)
    relation_table = pd.DataFrame(relations).merge(events_table[[EID, ACT, TIME]], on=EID)
    relation_table = relation_table.merge(objects_table[[OID, TYPE]], on=OID)
    return OCEL(
        events_table,
        objects_table,
        relation_table,
        o2o=pd.DataFrame(o2o),
        object_changes=pd.DataFrame(changes),
    )


def pm4py_view(ocel: OCEL) -> dict[str, object]:
    """What pm4py read, as sets of plain values (times in UTC, numbers as floats)."""
    structural = {EID, ACT, TIME}
    events = {
        row[EID]: (row[ACT], _utc(row[TIME]), _attributes(row, structural))
        for row in ocel.events.to_dict("records")
    }
    objects = {
        row[OID]: (row[TYPE], _attributes(row, {OID, TYPE}))
        for row in ocel.objects.to_dict("records")
    }
    changes = ocel.object_changes
    return {
        "events": events,
        "objects": objects,
        "e2o": {(r[EID], r[OID], r[QUAL]) for r in ocel.relations.to_dict("records")},
        "o2o": {(r[OID], r["ocel:oid_2"], r[QUAL]) for r in ocel.o2o.to_dict("records")},
        "changes": {
            (r[OID], _utc(r[TIME]), r["ocel:field"], plain(r[r["ocel:field"]]))
            for r in changes.to_dict("records")
        },
    }


def _attributes(row: dict, structural: set[str]) -> dict[str, object]:
    skip = structural | {"@@cumcount"}
    return {k: plain(v) for k, v in row.items() if k not in skip and not missing(v)}


def missing(value: object) -> bool:
    return value is None or value is pd.NA or (isinstance(value, float) and np.isnan(value))


def plain(value: object) -> object:
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | float | np.integer | np.floating):
        return float(value)
    return value


def _utc(value: object) -> pd.Timestamp:
    stamp = pd.Timestamp(value)
    return stamp.tz_localize("UTC") if stamp.tzinfo is None else stamp.tz_convert("UTC")


def logistics_csv(folder: Path, containers: int = 40, seed: int = 3) -> tuple[Path, Path]:
    """An OCED-style logistics log: ``events.csv`` and ``objects/<Type>.csv`` for Forklift,
    Truck, Vehicle and Container. Returns the events file and the objects folder."""
    rng = np.random.default_rng(seed)
    forklifts = [f"fl{i}" for i in range(1, 4)]
    trucks = [f"tr{i}" for i in range(1, 6)]
    vehicles = [f"ve{i}" for i in range(1, 4)]
    clock = pd.Timestamp("2025-02-03T06:00:00+01:00")
    rows = []
    for number in range(1, containers + 1):
        container = f"cr{number}"
        steps = [
            (
                "Load Truck",
                {"Truck": str(rng.choice(trucks)), "Forklift": str(rng.choice(forklifts))},
            ),
            ("Drive to Terminal", {"Truck": None, "Vehicle": str(rng.choice(vehicles))}),
            ("Weigh", {}),
            ("Place in Stock", {"Forklift": str(rng.choice(forklifts))}),
        ]
        truck = steps[0][1]["Truck"]
        for activity, related in steps:
            clock += pd.Timedelta(seconds=int(rng.integers(60, 900)))
            cells = {"Forklift": None, "Truck": None, "Vehicle": None, "Container": container}
            cells.update({k: v for k, v in related.items() if v is not None})
            if activity == "Drive to Terminal":
                cells["Truck"] = truck
            rows.append({"activity": activity, "time": clock.isoformat(), **cells})
        if number % 10 == 0:  # a truck load of several containers: one cell lists them all
            clock += pd.Timedelta(seconds=30)
            batch = ",".join(f"cr{n}" for n in range(number - 9, number + 1))
            rows.append(
                {
                    "activity": "Depart",
                    "time": clock.isoformat(),
                    "Forklift": None,
                    "Truck": truck,
                    "Vehicle": None,
                    "Container": batch,
                }
            )
    events = pd.DataFrame(rows)
    events.insert(0, "event_id", [f"ev{i}" for i in range(1, len(events) + 1)])
    objects = folder / "objects"
    objects.mkdir(parents=True, exist_ok=True)
    events_file = folder / "events.csv"
    events.to_csv(events_file, index=False)
    pd.DataFrame({"id": forklifts, "capacity": [2.5, 3.0, 1.5]}).to_csv(
        objects / "Forklift.csv", index=False
    )
    pd.DataFrame(
        {"id": trucks, "plate": [f"K-{i}" for i in range(5)], "axles": [2, 3, 3, 2, 4]}
    ).to_csv(objects / "Truck.csv", index=False)
    pd.DataFrame({"id": vehicles, "kind": ["tug", "tug", "van"]}).to_csv(
        objects / "Vehicle.csv", index=False
    )
    weights = rng.uniform(1000, 30000, containers).round(1)
    pd.DataFrame({"id": [f"cr{n}" for n in range(1, containers + 1)], "weight": weights}).to_csv(
        objects / "Container.csv", index=False
    )
    return events_file, objects
