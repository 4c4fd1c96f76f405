"""Limits of the console that hold whatever the query: the JSON it accepts, the workers'
memory, and a query that Neo4j does not stop at its timeout (the watchdog's), through the
real app and the session's real Neo4j."""

from __future__ import annotations

import dataclasses
import json
import logging
import re
import time

import pytest

from robotale.webapp import create_app
from robotale.webapp.json_body import MAX_BYTES, MAX_DEPTH, depth

#: a tight loop: Neo4j's transaction timeout does not interrupt it
LOOP = "RETURN reduce(s = 0, i IN range(1, $n) | s + i) AS s"


def post(client, body: str):
    return client.post(
        "/api/cypher",
        data=body,
        content_type="application/json",
        headers={"X-CSRFToken": client.csrf},
    )


def refusal(response) -> str:
    assert response.status_code == 400, response.get_data(as_text=True)[:300]
    message = response.json["error"]
    assert "\n" not in message
    return message


@pytest.mark.parametrize("levels", [5000, 900, MAX_DEPTH + 1])
def test_deep_json_is_one_sentence(client, levels):
    nested = "[" * levels + "]" * levels
    body = '{"query": "RETURN $p AS p", "parameters": {"p": ' + nested + "}}"
    assert depth(body) == levels + 2  # the body's object, "parameters" and the lists
    message = refusal(post(client, body))
    assert message == (
        f"The request's JSON nests {levels + 2} levels deep; send at most {MAX_DEPTH} levels "
        "of arrays and objects."
    )


def test_json_within_the_limits_still_runs(client):
    levels = MAX_DEPTH - 2
    value: list = []
    for _ in range(levels - 1):
        value = [value]
    body = json.dumps({"query": "RETURN $p AS p", "parameters": {"p": value}})
    assert depth(body) == MAX_DEPTH
    response = post(client, body)
    assert response.status_code == 200, response.get_data(as_text=True)[:300]
    assert response.json["results"][0]["rows"] == [[value]]


def test_brackets_inside_strings_do_not_count(client):
    text = "[" * 5000
    body = json.dumps({"query": "RETURN size($p) AS n", "parameters": {"p": text}})
    response = post(client, body)
    assert response.status_code == 200, response.get_data(as_text=True)[:300]
    assert response.json["results"][0]["rows"] == [[len(text)]]


def test_a_body_larger_than_the_limit_is_refused_before_reading(client):
    body = json.dumps({"query": "RETURN $p AS p", "parameters": {"p": "x" * MAX_BYTES}})
    message = refusal(post(client, body))
    assert message == (
        f"The request body is larger than {MAX_BYTES:,} bytes ({len(body):,} bytes); "
        "send a smaller one."
    )


def test_a_body_that_is_no_json_names_where(client):
    message = refusal(post(client, '{"query": "RETURN 1",}'))
    assert message.startswith('Send {"query": "...", "parameters": {...}} as JSON (the body')
    assert "line 1, column" in message


def test_a_worker_that_ran_out_of_memory_is_replaced(client):
    message = refusal(post(client, json.dumps({"query": "RETURN range(1, 20000000) AS n"})))
    assert "does not fit" in message or "did not finish" in message, message
    response = post(client, json.dumps({"query": "UNWIND range(1, 3) AS i RETURN sum(i) AS s"}))
    assert response.json["results"][0]["rows"] == [[6]]


def _seconds_per_step(driver) -> float:
    """How long Neo4j takes per step of :data:`LOOP` on this machine now (best of three)."""
    steps, best = 2_000_000, float("inf")
    for _ in range(3):
        started = time.monotonic()
        driver.execute_query(LOOP, n=steps)
        best = min(best, time.monotonic() - started)
    return best / steps


def test_a_query_neo4j_does_not_stop_is_ended_by_the_watchdog(neo4j_driver, web_settings, caplog):
    timeout, grace = 1.0, 4.0
    settings = dataclasses.replace(web_settings, console_timeout=timeout, console_grace=grace)
    app = create_app(settings)
    client = app.test_client()
    page = client.get("/cypher").get_data(as_text=True)
    client.csrf = re.search(r'name="csrf-token" content="([^"]+)"', page).group(1)
    # long enough to outlive timeout and grace several times over on this machine, short
    # enough not to burn the server's CPU for long when Neo4j cannot stop it
    steps = int(20 / _seconds_per_step(neo4j_driver))
    body = json.dumps({"query": LOOP, "parameters": {"n": steps}})
    with caplog.at_level(logging.WARNING, logger="robotale.webapp.console_watchdog"):
        message = refusal(post(client, body))
    ids = re.findall(r"neo4j-transaction-\d+", message)
    assert ids, message
    assert message.startswith("The query ran past the console's 1 s")
    # What the sentence says is what Neo4j shows right after.
    records, _, _ = neo4j_driver.execute_query(
        "SHOW TRANSACTIONS YIELD transactionId WHERE transactionId IN $ids RETURN transactionId",
        ids=ids,
    )
    still = [record["transactionId"] for record in records]
    if "still runs on the server" in message:
        assert still == ids  # so the user was answered before the query ended
        assert any(ids[0] in record.getMessage() for record in caplog.records)
    else:
        assert "robotale terminated it" in message and still == []
    _wait_until_gone(neo4j_driver, ids)
    response = post(client, json.dumps({"query": "RETURN 1 AS one"}))
    assert response.json["results"][0]["rows"] == [[1]]
    app.extensions["robotale"].console.close()


def _wait_until_gone(driver, ids: list[str]) -> None:
    # The loop ends on its own; the next tests should not share the server's CPU with it.
    deadline = time.monotonic() + 600
    while time.monotonic() < deadline:
        records, _, _ = driver.execute_query(
            "SHOW TRANSACTIONS YIELD transactionId WHERE transactionId IN $ids "
            "RETURN transactionId",
            ids=ids,
        )
        if not records:
            return
        time.sleep(1)
