"""Twenty requests at once against the real console: each answers with the rows Neo4j gives
the same query asked directly (the workers answer several requests each, on threads)."""

from __future__ import annotations

import json
import re
from concurrent.futures import ThreadPoolExecutor

from robotale.webapp import console

CLIENTS = 20

#: queries whose rows depend on the parameters each client sends
OWN = [
    "UNWIND range(1, $n) AS i RETURN i, i * $n AS product ORDER BY i",
    "MATCH (e:Event {log: $log}) WHERE e.step <= $n RETURN e.activity AS activity, "
    "count(*) AS events ORDER BY activity",
    "MATCH (a:Event {log: $log})-[:DF]->(b:Event) WHERE a.step % $n = 0 "
    "RETURN a.id AS source, b.id AS target ORDER BY source",
]


def _graph(driver, log: str) -> None:
    driver.execute_query(
        "UNWIND range(1, 60) AS step "
        "CREATE (:Event {log: $log, id: 'e' + step, step: step, activity: 'a' + (step % 5), "
        "robot: 'r' + (step % 2), case: 'c' + (step % 3), "
        "timestamp: datetime('2024-01-01T00:00:00Z') + duration({seconds: step})}) "
        "WITH 1 AS done LIMIT 1 "
        "MATCH (a:Event {log: $log}), (b:Event {log: $log}) WHERE b.step = a.step + 1 "
        "CREATE (a)-[:DF {entityType: 'robot'}]->(b)",
        log=log,
    )


def _asked(log: str) -> list[tuple[str, dict]]:
    values = {"log": log, "robot": "r0", "other": "r1", "case": "c0"}
    questions = [
        (example.text, {name: values.get(name) for name in example.parameters})
        for example in console.examples()
    ]
    for client in range(CLIENTS):
        questions.append((OWN[client % len(OWN)], {"log": log, "n": client + 1}))
    return questions[:CLIENTS]


def _direct(driver, text: str, parameters: dict) -> list[list]:
    rows = []
    for statement in console.split_statements(text):
        records, _, _ = driver.execute_query(statement, parameters)
        rows.append(sorted(json.dumps([console.cell(v) for v in r.values()]) for r in records))
    return rows


def _through_console(app, text: str, parameters: dict) -> list[list]:
    client = app.test_client()
    page = client.get("/cypher").get_data(as_text=True)
    token = re.search(r'name="csrf-token" content="([^"]+)"', page).group(1)
    response = client.post(
        "/api/cypher",
        json={"query": text, "parameters": parameters},
        headers={"X-CSRFToken": token},
    )
    assert response.status_code == 200, response.get_data(as_text=True)[:300]
    return [sorted(json.dumps(row) for row in r["rows"]) for r in response.json["results"]]


def test_twenty_requests_at_once_answer_what_neo4j_answers(app, neo4j_driver, log_name):
    _graph(neo4j_driver, log_name)
    questions = _asked(log_name)
    assert len(questions) == CLIENTS
    with ThreadPoolExecutor(CLIENTS) as clients:
        answers = list(clients.map(lambda asked: _through_console(app, *asked), questions))
    expected = [_direct(neo4j_driver, *asked) for asked in questions]
    assert answers == expected
    # the graph is there: most questions have rows to compare
    assert sum(1 for answer in answers if any(answer)) >= CLIENTS // 2
