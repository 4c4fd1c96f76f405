"""A build cut into many small batches: the DF and COMM edges written with their events
(both ends in one batch) and those written after them (ends in two batches) together are
exactly the edges computed independently from the log in pandas."""

from __future__ import annotations

import uuid

import pytest

from robotale.ekg import build_ekg, load
from robotale.ekg.connection import database
from robotale.ekg.logs import delete_log
from robotale.ekg.tables import graph_tables
from robotale.eventlog import schema

# prime, so that batch boundaries fall at every distance from a message's send and receives
SMALL_BATCH = 101


@pytest.fixture(scope="module")
def built(neo4j_driver, thesis_log):
    name = f"test_batches_{uuid.uuid4().hex[:8]}"
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(load, "BATCH", SMALL_BATCH)
        build_ekg(neo4j_driver, thesis_log, name, entities=["robot", "msg_id"], progress=False)
    yield name
    delete_log(neo4j_driver, name)


def rows(driver, text: str, **params) -> set[tuple]:
    records, _, _ = driver.execute_query(text, params, database_=database())
    return {tuple(_hashable(v) for v in record.values()) for record in records}


def _hashable(value):
    return tuple(sorted(value)) if isinstance(value, list) else value


def test_the_build_was_cut_both_ways(thesis_log):
    tables = graph_tables(thesis_log, ["robot", "msg_id"])
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(load, "BATCH", SMALL_BATCH)
        for edges in (tables.df, tables.comm):
            within = load.within_batches(edges)
            assert within.any() and not within.all()


def test_df_edges_are_consecutive_events_of_each_entity(neo4j_driver, built, thesis_log):
    log = thesis_log.assign(order=range(len(thesis_log)))
    expected = set()
    for column, entity_type in ((schema.ROBOT, "robot"), (schema.MSG_ID, "msg_id")):
        chain = log.dropna(subset=[column]).sort_values(
            [column, schema.TIMESTAMP, "order"], kind="stable"
        )
        after = chain.groupby(column).shift(-1).dropna(subset=["order"])
        before = chain.loc[after.index]
        expected |= set(
            zip(
                before[schema.EVENT_ID],
                after[schema.EVENT_ID],
                [entity_type] * len(after),
                before[column],
                strict=True,
            )
        )
    found = rows(
        neo4j_driver,
        "MATCH (a:Event {log: $log})-[r:DF]->(b:Event) RETURN a.id, b.id, r.entityType, r.entityId",
        log=built,
    )
    assert len(expected) > 3000
    assert found == expected


def test_comm_edges_join_each_send_to_each_receive(neo4j_driver, built, thesis_log):
    messages = thesis_log.dropna(subset=[schema.MSG_ID])
    sends = messages[messages[schema.ACTIVITY].str.endswith("!")]
    receives = messages[messages[schema.ACTIVITY].str.endswith("?")]
    pairs = sends.merge(receives, on=schema.MSG_ID, suffixes=("_s", "_r"))
    expected = set(
        zip(
            pairs[f"{schema.EVENT_ID}_s"],
            pairs[f"{schema.EVENT_ID}_r"],
            pairs[schema.MSG_ID],
            strict=True,
        )
    )
    found = rows(
        neo4j_driver,
        "MATCH (a:Event {log: $log})-[r:COMM]->(b:Event) RETURN a.id, b.id, r.msgId",
        log=built,
    )
    assert len(expected) > 100
    assert found == expected


def test_every_event_is_stored_once_with_its_entities_and_class(neo4j_driver, built, thesis_log):
    found = rows(
        neo4j_driver,
        "MATCH (e:Event {log: $log}) "
        "OPTIONAL MATCH (e)-[:CORR]->(n:Entity {type: 'robot'}) "
        "OPTIONAL MATCH (e)-[:OBSERVED]->(c:Class) "
        "RETURN e.id, e.order, collect(DISTINCT n.id), collect(DISTINCT c.id)",
        log=built,
    )
    expected = {
        (event, order, (robot,), (activity,))
        for order, (event, robot, activity) in enumerate(
            zip(
                thesis_log[schema.EVENT_ID],
                thesis_log[schema.ROBOT],
                thesis_log[schema.ACTIVITY],
                strict=True,
            )
        )
    }
    assert found == expected
