"""OCEAN's specifications on logs shaped like its published datasets (a logistics log and an
order-management log, generated here), ingested with robotale's CSV ingest (one --entities
column per object type): the node counts of every step (OCEAN's verification table) and
every aggregate's count and attributes equal a pandas computation written out step by step."""

from __future__ import annotations

import pandas as pd
import pytest
from ocean_shaped import (
    LOGISTICS_SPEC,
    ORDER_MANAGEMENT_SPEC,
    ObjectLog,
    logistics,
    order_management,
)

from robotale.cli import main
from robotale.ekg.connection import database
from robotale.ekg.spec import parse_spec
from robotale.ekg.steps import run_spec

CUTOFF = pd.Timestamp("2024-03-01T00:00:00Z")


def ingest(tmp_path, capsys, driver, log: ObjectLog, name: str) -> None:
    path = tmp_path / "events.csv"
    log.events.to_csv(path, index=False)
    code = main(["ingest", str(path), "--log", name, "--entities", ",".join(log.types)])
    assert code == 0, capsys.readouterr().err
    for kind, table in log.objects.items():
        rows = table.to_dict("records")
        driver.execute_query(
            "UNWIND $rows AS row MATCH (n:Entity {log: $log, type: $type, id: row.id}) "
            "SET n += row",
            rows=rows,
            log=name,
            type=kind,
            database_=database(),
        )


def stored(driver, name: str, step: int) -> dict[str, dict]:
    records, _, _ = driver.execute_query(
        "MATCH (a:Aggregate {log: $log, step: $step}) RETURN properties(a) AS a",
        log=name,
        step=step,
        database_=database(),
    )
    found = {}
    for record in records:
        a = dict(record["a"])
        found[a["name"]] = {
            k: v.to_native() if hasattr(v, "to_native") else v
            for k, v in a.items()
            if k not in ("log", "step", "id", "name", "origin", "key", "type")
        }
    return found


def same(found: dict[str, dict], expected: dict[str, dict]) -> None:
    assert set(found) == set(expected)
    for name, values in expected.items():
        for key, value in values.items():
            if isinstance(value, float):
                assert found[name][key] == pytest.approx(value, rel=1e-9), (name, key)
            else:
                assert found[name][key] == value, (name, key)


def multiset(values) -> list[str]:
    counts = pd.Series(list(values)).astype(str).value_counts()
    return [f"{v}:{c}" for v, c in sorted(counts.items())]


def verification(results) -> list[tuple[int, int, int, int]]:
    return [
        (r.initial_events, r.final_events, r.initial_entities, r.final_entities) for r in results
    ]


def test_logistics_spec(tmp_path, capsys, neo4j_driver, log_name):
    log = logistics(3000)
    ingest(tmp_path, capsys, neo4j_driver, log, log_name)
    results = run_spec(neo4j_driver, log_name, parse_spec(LOGISTICS_SPEC))
    events = log.events.assign(time=pd.to_datetime(log.events["time"], utc=True))
    containers, orders = log.objects["Container"], log.objects["Customer_Order"]

    # step 1: containers by Status
    expected = {}
    for status, part in containers.groupby("Status"):
        expected[status] = {
            "count": len(part),
            "id_multiset": multiset(part["id"]),
            "Weight_avg": float(part["Weight"].mean()),
            "Amount_of_Handling_Units_min": int(part["Amount_of_Handling_Units"].min()),
            "Amount_of_Handling_Units_max": int(part["Amount_of_Handling_Units"].max()),
        }
    same(stored(neo4j_driver, log_name, 1), expected)

    # steps 2 and 3: the orders of 1000 goods or more, then the others, by Type
    big = orders[orders["Amount_of_Goods"] >= 1000]
    small = orders[orders["Amount_of_Goods"] < 1000]
    same(
        stored(neo4j_driver, log_name, 2),
        {t: {"count": len(p), "Amount_of_Goods_sum": int(p["Amount_of_Goods"].sum())}
         for t, p in big.groupby("Type")},
    )  # fmt: skip
    same(
        stored(neo4j_driver, log_name, 3),
        {t: {"count": len(p), "Amount_of_Goods_min": int(p["Amount_of_Goods"].min()),
             "Amount_of_Goods_max": int(p["Amount_of_Goods"].max())}
         for t, p in small.groupby("Type")},
    )  # fmt: skip

    # step 4: events up to the cutoff by activity and the aggregate(s) of their orders
    aggregate_of = {i: f"2:{t}" for i, t in zip(big["id"], big["Type"], strict=True)}
    aggregate_of |= {i: f"3:{t}" for i, t in zip(small["id"], small["Type"], strict=True)}

    def order_key(cell) -> str:
        if not isinstance(cell, str):
            return "unknown"
        return ",".join(sorted({aggregate_of[o] for o in cell.split(",")}))

    early = events[events["time"] <= CUTOFF]
    keys = early["activity"] + "|" + early["Customer_Order"].map(order_key)
    same(
        stored(neo4j_driver, log_name, 4),
        {k: {"count": len(p), "timestamp_min": p["time"].min().to_pydatetime(),
             "timestamp_max": p["time"].max().to_pydatetime()}
         for k, p in early.groupby(keys)},
    )  # fmt: skip

    # step 5: the later events by activity
    late = events[events["time"] > CUTOFF]
    same(
        stored(neo4j_driver, log_name, 5),
        {a: {"count": len(p), "timestamp_min": p["time"].min().to_pydatetime()}
         for a, p in late.groupby("activity")},
    )  # fmt: skip

    n, entities = len(events), sum(len(t) for t in log.objects.values())
    after1 = entities - len(containers)
    assert verification(results) == [
        (n, n, entities, after1),
        (n, n, after1, after1 - len(big)),
        (n, n, after1 - len(big), after1 - len(orders)),
        (n, n - len(early), after1 - len(orders), after1 - len(orders)),
        (n - len(early), 0, after1 - len(orders), after1 - len(orders)),
    ]


def test_order_management_spec(tmp_path, capsys, neo4j_driver, log_name):
    log = order_management(2000)
    ingest(tmp_path, capsys, neo4j_driver, log, log_name)
    results = run_spec(neo4j_driver, log_name, parse_spec(ORDER_MANAGEMENT_SPEC))
    customers, orders = log.objects["customers"], log.objects["orders"]
    same(
        stored(neo4j_driver, log_name, 1),
        {s: {"count": len(p), "id_multiset": multiset(p["id"])}
         for s, p in customers.groupby("segment")},
    )  # fmt: skip
    big = orders[orders["price"] >= 1000]
    small = orders[orders["price"] < 1000]
    same(
        stored(neo4j_driver, log_name, 2),
        {"orders": {"count": len(big), "price_avg": float(big["price"].mean())}},
    )
    same(
        stored(neo4j_driver, log_name, 3),
        {c: {"count": len(p), "price_avg": float(p["price"].mean())}
         for c, p in small.groupby("channel")},
    )  # fmt: skip
    same(
        stored(neo4j_driver, log_name, 4),
        {a: {"count": len(p)} for a, p in log.events.groupby("activity")},
    )
    n, entities = len(log.events), sum(len(t) for t in log.objects.values())
    after1 = entities - len(customers)
    assert verification(results) == [
        (n, n, entities, after1),
        (n, n, after1, after1 - len(big)),
        (n, n, after1 - len(big), after1 - len(orders)),
        (n, 0, after1 - len(orders), after1 - len(orders)),
    ]
    # every event's CORR edges to orders are lifted: the event aggregates' CORR counts to the
    # order aggregates add up to the CORR edges of the orders
    records, _, _ = neo4j_driver.execute_query(
        "MATCH (:Aggregate {log: $log, step: 4})-[r:CORR]->(o:Aggregate {log: $log}) "
        "WHERE o.step IN [2, 3] RETURN sum(r.count) AS n",
        log=log_name,
        database_=database(),
    )
    corr = log.events["orders"].dropna().str.split(",").str.len().sum()
    assert records[0]["n"] == corr
