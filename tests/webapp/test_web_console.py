"""The read-only Cypher console, through the app against the session's real Neo4j."""

from __future__ import annotations

from importlib.resources import files

import pytest

from robotale.errors import InputError
from robotale.webapp import console


def run(client, query: str, parameters: dict | None = None):
    return client.post(
        "/api/cypher",
        json={"query": query, "parameters": parameters or {}},
        headers={"X-CSRFToken": client.csrf},
    )


def test_reads_return_columns_and_rows_with_parameters(client):
    response = run(client, "UNWIND range(1, $n) AS i RETURN i, i * i AS square", {"n": 3})
    assert response.status_code == 200
    [result] = response.json["results"]
    assert result["columns"] == ["i", "square"]
    assert result["rows"] == [[1, 1], [2, 4], [3, 9]]
    assert result["total"] == 3


def test_several_statements_each_give_a_table(client):
    response = run(client, "RETURN 'a;b' AS text; // two\nRETURN 2 AS two;")
    assert [r["rows"] for r in response.json["results"]] == [[["a;b"]], [[2]]]


@pytest.mark.parametrize(
    "query",
    [
        "CREATE (n:ConsoleProbe {at: datetime()}) RETURN n",
        "MERGE (n:ConsoleProbe) SET n.x = 1",
        "MATCH (n:ConsoleKeep) DETACH DELETE n",
        "CREATE INDEX console_probe FOR (n:ConsoleProbe) ON (n.x)",
        "MATCH (n) CALL (n) { DETACH DELETE n } IN TRANSACTIONS",
        # a read first does not let the write through
        "RETURN 1 AS one; CREATE (:ConsoleProbe)",
    ],
)
def test_writes_are_refused_and_change_nothing(client, graph_counts, neo4j_driver, query):
    neo4j_driver.execute_query("MERGE (:ConsoleKeep {id: 1})")
    before = graph_counts()
    response = run(client, query)
    assert response.status_code == 400
    assert response.json["error"].startswith("The console only reads")
    assert graph_counts() == before
    indexes, _, _ = neo4j_driver.execute_query("SHOW INDEXES YIELD name RETURN collect(name) AS n")
    assert "console_probe" not in indexes[0]["n"]


def test_bad_syntax_and_missing_parameters_are_one_sentence(client):
    bad = run(client, "MATC (n) RETURN n").json["error"]
    assert bad.startswith("Neo4j could not run the query: Invalid input 'MATC'")
    missing = run(client, "RETURN $nothing AS x").json["error"]
    assert "nothing" in missing and "\n" not in missing
    assert run(client, "  // only a comment").json["error"].startswith("Type a Cypher query")


def test_rows_beyond_the_limit_are_counted_not_sent(neo4j_driver):
    [result] = console.run_read_only(
        neo4j_driver, "UNWIND range(1, 25) AS i RETURN i", row_limit=10
    )
    assert [row[0] for row in result.rows] == list(range(1, 11))
    assert result.total == 25


def test_accepted_plans_are_remembered_by_text_and_values_never_refusals(neo4j_driver):
    from robotale.ekg.connection import database
    from robotale.ekg.readonly import PlanVerdicts

    verdicts = PlanVerdicts()
    text = "UNWIND range(1, $n) AS i RETURN i"
    for _ in range(2):
        [result] = console.run_read_only(neo4j_driver, text, {"n": 3}, verdicts=verdicts)
        assert [row[0] for row in result.rows] == [1, 2, 3]
    assert verdicts.key(text, {"n": 3}, database()) in verdicts
    # other values are another question: its plan is asked for, not taken from the first
    assert verdicts.key(text, {"n": 4}, database()) not in verdicts
    write = "UNWIND range(1, $n) AS i CREATE (:Probe {i: i})"
    for _ in range(2):
        with pytest.raises(console.WriteRefused):
            console.run_read_only(neo4j_driver, write, {"n": 3}, verdicts=verdicts)
    assert verdicts.key(write, {"n": 3}, database()) not in verdicts
    assert verdicts.key(text, {"n": "x" * PlanVerdicts.KEY_BYTES}, database()) is None


def test_graph_values_are_shown_like_neo4j_browser(neo4j_driver, log_name):
    neo4j_driver.execute_query(
        "CREATE (:Event {log: $log, id: 'e1', activity: 'takeoff'})"
        "-[:DF {entityType: 'robot'}]->(:Event {log: $log, id: 'e2'})",
        log=log_name,
    )
    [result] = console.run_read_only(
        neo4j_driver,
        "MATCH p = (a:Event {log: $log, id: 'e1'})-[r:DF]->(b) "
        "RETURN a, r, p, date('2023-05-16') AS day, {k: [1, 'x']} AS map",
        {"log": log_name},
    )
    node, relationship, path, day, mapping = result.rows[0]
    assert node == f"(:Event {{activity: 'takeoff', id: 'e1', log: '{log_name}'}})"
    assert relationship == "[:DF {entityType: 'robot'}]"
    assert path[0] == node and path[1] == relationship and path[2].startswith("(:Event {id: 'e2'")
    assert day == "2023-05-16"
    assert mapping == {"k": [1, "x"]}


def test_statements_split_outside_strings_and_comments():
    text = "// intro; 'quote\nRETURN ';' AS a, \"x\\\";\" AS b; /* c; */ RETURN `we;ird`;\n// end"
    assert console.split_statements(text) == [
        "// intro; 'quote\nRETURN ';' AS a, \"x\\\";\" AS b",
        "/* c; */ RETURN `we;ird`",
    ]


def test_examples_are_the_analysts_files_of_the_cypher_folder(client):
    every = sorted(
        r.name.removesuffix(".cypher")
        for r in files("robotale.cypher").iterdir()
        if r.name.endswith(".cypher")
    )
    names = [name for name in every if name.startswith("ask_")]
    examples = console.examples()
    assert [e.name for e in examples] == names
    path = next(e for e in examples if e.name == "ask_robot_path")
    assert path.parameters == ["case", "log", "robot"]
    assert path.description.startswith("The path of robot $robot in run $case")
    page = client.get("/cypher").get_data(as_text=True)
    assert all(f'data-name="{name}"' in page for name in names)
    # robotale's own queries stay in cypher/ but are not offered
    assert "ekg_delete_log" in every
    assert not any(f'data-name="{name}"' in page for name in every if name not in names)


def test_the_console_needs_a_csrf_token_and_json(client):
    no_token = client.post("/api/cypher", json={"query": "RETURN 1"})
    assert no_token.status_code == 400 and "CSRF" in no_token.json["error"]
    not_json = client.post("/api/cypher", data="RETURN 1", headers={"X-CSRFToken": client.csrf})
    assert not_json.status_code == 400 and not_json.json["error"].startswith("Send {")
    with pytest.raises(InputError):
        console.run_read_only(None, "")  # type: ignore[arg-type]
