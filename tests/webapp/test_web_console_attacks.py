"""What an attacker tried with the read-only console, through the real app and the session's
real Neo4j: reading files and loopback services, administration, other sessions'
transactions, exhausting memory, and answers that are not JSON."""

from __future__ import annotations

import json
import os
import resource
import stat
import time
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
from counting_service import counting_service

from robotale.ekg import readonly
from robotale.neo4j_server.server import (
    CONSOLE_USER,
    LocalServer,
    create_console_user,
    security_settings,
)
from robotale.webapp import console

#: the session's Neo4j is robotale's local server unless the run was pointed at another
LOCAL_SERVER = not os.environ.get("NEO4J_URI")
ONLY_READS = "The console only reads"


def run(client, query: str, parameters: dict | None = None):
    return client.post(
        "/api/cypher",
        json={"query": query, "parameters": parameters or {}},
        headers={"X-CSRFToken": client.csrf},
    )


def refused(response) -> str:
    """The one-sentence refusal of a console request."""
    assert response.status_code == 400, response.get_data(as_text=True)[:500]
    message = response.json["error"]
    assert "\n" not in message and "results" not in response.json
    return message


@pytest.fixture
def loopback_service() -> Iterator[dict]:
    """An HTTP service on 127.0.0.1 holding a secret; ``hits`` counts the requests it got."""
    secret = uuid.uuid4().hex
    with counting_service(f"secret\n{secret}\n".encode()) as seen:
        seen["secret"] = secret
        yield seen


def test_load_csv_reads_no_file(client, tmp_path):
    secret = uuid.uuid4().hex
    path = tmp_path / "secret.csv"
    path.write_text(f"secret\n{secret}\n")
    for query in (
        f"LOAD CSV FROM 'file://{path}' AS line RETURN line",
        f"load  csv with headers from 'file://{path}' AS line RETURN line",
        "LOAD/* hidden */CSV FROM $url AS line RETURN line",
        f"CALL () {{ LOAD CSV FROM 'file://{path}' AS line RETURN line }} RETURN line",
    ):
        response = run(client, query, {"url": f"file://{path}"})
        assert refused(response).startswith(f"{ONLY_READS} the graph: LOAD CSV")
        assert secret not in response.get_data(as_text=True)


def test_load_csv_fetches_no_loopback_service(client, loopback_service):
    url = loopback_service["url"]
    response = run(client, "LOAD CSV FROM $url AS line RETURN line", {"url": url})
    assert "LOAD CSV" in refused(response)
    assert loopback_service["hits"] == 0
    assert loopback_service["secret"] not in response.get_data(as_text=True)


@pytest.mark.parametrize(
    "query",
    [
        "SHOW USERS",
        "SHOW TRANSACTIONS",
        "SHOW TRANSACTIONS YIELD currentQuery RETURN currentQuery",
        "SHOW SETTINGS",
        "show procedures",
        "TERMINATE TRANSACTIONS 'neo4j-transaction-1'",
        "USE system SHOW USERS",
        "CREATE USER mallory SET PASSWORD 'secret-secret'",
        "ALTER USER neo4j SET PASSWORD 'secret-secret'",
        "STOP DATABASE neo4j",
        "GRANT ROLE admin TO mallory",
        # behind the query options that may lead a statement
        "CYPHER 5 SHOW USERS",
        "cypher runtime = slotted SHOW TRANSACTIONS YIELD currentQuery RETURN currentQuery",
        "PROFILE CYPHER 5 planner=cost TERMINATE TRANSACTIONS 'neo4j-transaction-1'",
        "CYPHER 5 USE system SHOW USERS",
    ],
)
def test_administration_commands_are_refused(client, query):
    message = refused(run(client, query))
    assert message.startswith(ONLY_READS), message


@pytest.mark.parametrize(
    "query",
    [
        "CALL dbms.listConfig()",
        "CALL dbms.listConfig() YIELD name, value RETURN name, value",
        "CALL db.clearQueryCaches()",
        "CALL `db`.`clearQueryCaches`()",
        "call db.clearQueryCaches",
        "MATCH (n) WITH count(n) AS c CALL dbms.listConnections() YIELD connectionId RETURN *",
        "CYPHER 5 CALL dbms.listConfig() YIELD name RETURN name",
    ],
)
def test_procedures_outside_the_allow_list_are_refused(client, query):
    message = refused(run(client, query))
    assert message.startswith(f"{ONLY_READS} the graph: the procedure "), message


@pytest.mark.parametrize(
    "query",
    [
        # APOC's functions run the Cypher they are given as text: LOAD CSV inside a string
        "RETURN apoc.cypher.runFirstColumnSingle('LOAD CSV FROM $url AS l RETURN l', "
        "{url: $url}) AS line",
        "RETURN `apoc`.`cypher`.runFirstColumnMany($text, {url: $url}) AS lines",
        "MATCH (n) WITH count(n) AS c RETURN apoc . util . md5([c]) AS hash",
        "RETURN [x IN [1] | mine.secret(x)] AS values",
    ],
)
def test_functions_of_plugins_are_refused(client, loopback_service, query):
    text = "LOAD CSV FROM $url AS l RETURN l"
    response = run(client, query, {"url": loopback_service["url"], "text": text})
    message = refused(response)
    assert message.startswith(f"{ONLY_READS} the graph: the function "), message
    assert "is not one of Neo4j's own" in message
    assert loopback_service["hits"] == 0


def test_neo4j_own_dotted_functions_still_run(client):
    response = run(
        client,
        "RETURN duration.between(date('2024-01-01'), date('2024-01-03')).days AS days, "
        "point.distance(point({x: 0, y: 0}), point({x: 3, y: 4})) AS distance, "
        "date.truncate('month', date('2024-05-17')) AS month",
    )
    assert response.status_code == 200, response.get_data(as_text=True)
    assert response.json["results"][0]["rows"] == [[2, 5.0, "2024-05-01"]]


def test_a_read_behind_query_options_still_runs(client):
    response = run(client, "CYPHER 5 runtime=slotted UNWIND [1, 2] AS i RETURN sum(i) AS total")
    assert response.status_code == 200, response.get_data(as_text=True)
    assert response.json["results"][0]["rows"] == [[3]]


def test_every_dotted_function_neo4j_lists_as_its_own_is_allowed(neo4j_driver):
    records, _, _ = neo4j_driver.execute_query(
        "SHOW FUNCTIONS YIELD name, isBuiltIn WHERE isBuiltIn AND name CONTAINS '.' RETURN name"
    )
    namespaces = {record["name"].split(".")[0].lower() for record in records}
    assert {"duration", "point", "datetime"} <= namespaces
    assert namespaces <= readonly.BUILT_IN_FUNCTION_NAMESPACES


def test_allowed_procedures_answer_as_neo4j_does(client, neo4j_driver, log_name):
    neo4j_driver.execute_query("CREATE (:ConsoleLabelProbe {log: $log})", log=log_name)
    response = run(client, "CALL db.labels() YIELD label RETURN label ORDER BY label")
    assert response.status_code == 200
    records, _, _ = neo4j_driver.execute_query(
        "CALL db.labels() YIELD label RETURN label ORDER BY label"
    )
    expected = [[record["label"]] for record in records]
    assert "ConsoleLabelProbe" in {row[0] for row in expected}
    assert response.json["results"][0]["rows"] == expected


def test_another_sessions_transaction_cannot_be_terminated(client, neo4j_driver, log_name):
    with neo4j_driver.session() as session:
        tx = session.begin_transaction(metadata={"probe": log_name})
        tx.run("CREATE (:ConsoleKeep {log: $log})", log=log_name).consume()
        found, _, _ = neo4j_driver.execute_query(
            "SHOW TRANSACTIONS YIELD transactionId, metaData "
            "WHERE metaData.probe = $log RETURN transactionId",
            log=log_name,
        )
        [transaction] = [record["transactionId"] for record in found]
        response = run(client, "TERMINATE TRANSACTIONS $id", {"id": transaction})
        assert refused(response).startswith(ONLY_READS)
        tx.commit()  # still alive: the console did not end it
    kept, _, _ = neo4j_driver.execute_query(
        "MATCH (n:ConsoleKeep {log: $log}) RETURN count(n) AS n", log=log_name
    )
    assert kept[0]["n"] == 1


def test_read_only_batches_in_transactions_are_refused(client):
    query = "UNWIND range(1, 3) AS i CALL (i) { RETURN i * 2 AS j } IN TRANSACTIONS RETURN j"
    message = refused(run(client, query))
    assert message.startswith(ONLY_READS) and "IN TRANSACTIONS" in message


def test_a_heap_exhausting_query_fails_once_with_a_sentence(client):
    started = time.monotonic()
    response = run(client, "RETURN reduce(s = 'ab', i IN range(1, 40) | s + s) AS s")
    message = refused(response)
    assert "memory" in message
    # Not the driver's retries (more than 30 s before): Neo4j refuses once, the console says so.
    assert time.monotonic() - started < 30
    assert run(client, "RETURN 1 AS one").json["results"][0]["rows"] == [[1]]


def test_one_enormous_value_does_not_grow_the_dashboard(client):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024
    message = refused(run(client, "RETURN range(1, 20000000) AS numbers"))
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024 - before
    assert "does not fit" in message or "did not finish" in message, message
    # 20 million integers take about 700 MB as Python objects; the dashboard took none of it.
    assert grown < 100, f"the dashboard grew by {grown} MB"


def test_answers_are_bounded_in_bytes(neo4j_driver):
    query = "UNWIND range(1, 50) AS i RETURN i, 'xxxxxxxxxx' AS text"
    limit = 200
    sizes = [len(json.dumps([i, "xxxxxxxxxx"])) for i in range(1, 51)]
    expected = sum(1 for end in range(1, 51) if sum(sizes[:end]) <= limit)
    [result] = console.run_read_only(neo4j_driver, query, byte_limit=limit)
    assert len(result.rows) == expected < 50
    assert result.total == 50 and result.cut == "bytes" and result.complete


def test_every_value_is_valid_json(client):
    response = run(
        client,
        "RETURN 0.0 / 0.0 AS nan, 1.0 / 0.0 AS inf, -1.0 / 0.0 AS minus, "
        "9223372036854775807 AS largest, -9223372036854775808 AS smallest, "
        "9007199254740991 AS exact",
    )
    assert response.status_code == 200

    def no_constants(name: str) -> None:
        raise AssertionError(f"{name} is not JSON")

    body = json.loads(response.get_data(as_text=True), parse_constant=no_constants)
    assert body["results"][0]["rows"] == [
        ["NaN", "Infinity", "-Infinity", str(2**63 - 1), str(-(2**63)), 2**53 - 1]
    ]


def test_integers_neo4j_cannot_hold_are_one_sentence(client):
    response = client.post(
        "/api/cypher",
        data='{"query": "RETURN $n AS n", "parameters": {"n": 1180591620717411303424}}',
        content_type="application/json",
        headers={"X-CSRFToken": client.csrf},
    )
    message = refused(response)
    assert "$n" in message and str(2**70) in message


def test_the_console_logs_in_as_its_own_user(client, neo4j_driver, monkeypatch):
    user, password = f"console_{uuid.uuid4().hex[:8]}", uuid.uuid4().hex
    create_console_user(neo4j_driver, user, password)
    try:
        monkeypatch.setenv("ROBOTALE_CONSOLE_USER", user)
        monkeypatch.setenv("ROBOTALE_CONSOLE_PASSWORD", password)
        response = run(client, "CALL dbms.showCurrentUser() YIELD username RETURN username")
        assert response.json["results"][0]["rows"] == [[user]]
        assert "ROBOTALE_CONSOLE_USER" not in client.get("/cypher").get_data(as_text=True)
    finally:
        neo4j_driver.execute_query("DROP USER $user", user=user, database_="system")


def _session_server_home(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The robotale home of the local server this test session started."""
    for root in tmp_path_factory.getbasetemp().glob("robotale-home*"):
        running = LocalServer(root).running()
        if running is not None and running.bolt_uri == os.environ["NEO4J_URI"]:
            return root
    raise AssertionError("the session's local server was not found")


def test_the_local_server_gives_the_console_a_user_of_its_own(
    client, neo4j_driver, monkeypatch, tmp_path_factory
):
    if not LOCAL_SERVER:
        pytest.skip("the tests run against a server robotale did not start")
    home = _session_server_home(tmp_path_factory)
    for name in ("NEO4J_URI", "NEO4J_USER", "NEO4J_PASSWORD", "ROBOTALE_CONSOLE_USER"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("ROBOTALE_HOME", str(home))  # robotale's own server, as after `start`
    server = LocalServer()
    server.console_password_file.unlink(missing_ok=True)
    try:
        for _ in range(2):  # created by the first request, logged in as by the second
            response = run(client, "CALL dbms.showCurrentUser() YIELD username RETURN username")
            assert response.json["results"][0]["rows"] == [[CONSOLE_USER]]
        assert stat.S_IMODE(server.console_password_file.stat().st_mode) == 0o600
        users, _, _ = neo4j_driver.execute_query(
            "SHOW USERS YIELD user WHERE user = $user RETURN user",
            user=CONSOLE_USER,
            database_="system",
        )
        assert [record["user"] for record in users] == [CONSOLE_USER]
        assert "GRANT ROLE reader" not in client.get("/cypher").get_data(as_text=True)
        assert "LOAD CSV" in refused(
            run(client, "LOAD CSV FROM 'file:///etc/passwd' AS l RETURN l")
        )
    finally:
        server.console_password_file.unlink(missing_ok=True)
        neo4j_driver.execute_query(
            "DROP USER $user IF EXISTS", user=CONSOLE_USER, database_="system"
        )


def test_with_robotales_own_user_the_page_says_how_to_give_it_a_reader(client, monkeypatch):
    monkeypatch.delenv("ROBOTALE_CONSOLE_USER", raising=False)
    page = client.get("/cypher").get_data(as_text=True)
    assert "GRANT ROLE reader" in page and "ROBOTALE_CONSOLE_USER" in page


def test_the_local_server_caps_a_transaction_and_reads_no_file_urls(neo4j_driver):
    assert security_settings("1g")["db.memory.transaction.max"] == "512m"
    assert security_settings("2048m")["db.memory.transaction.max"] == "1024m"
    if not LOCAL_SERVER:
        pytest.skip("the tests run against a server robotale did not start")
    records, _, _ = neo4j_driver.execute_query(
        "CALL dbms.listConfig() YIELD name, value "
        "WHERE name IN ['dbms.security.allow_csv_import_from_file_urls', "
        "'db.memory.transaction.max'] RETURN name, value"
    )
    values = {record["name"]: record["value"] for record in records}
    assert values["dbms.security.allow_csv_import_from_file_urls"] == "false"
    assert values["db.memory.transaction.max"] != "0B"


@pytest.mark.slow
def test_with_apoc_installed_cypher_given_as_text_reads_no_url(
    neo4j_server, tmp_path, loopback_service
):
    """APOC's functions run Cypher handed to them as a string, where the text check sees no
    LOAD CSV and the plan shows none: on a server with APOC that fetches a loopback service
    even in a READ transaction. The console refuses the function."""
    from neo4j import READ_ACCESS, GraphDatabase

    from robotale.ekg.readonly import QueryRefused, run_read_only
    from robotale.neo4j_server import jars
    from robotale.neo4j_server.server import ServerOptions, free_port

    plugins = tmp_path / "plugins"
    plugins.mkdir()
    for jar in jars.apoc_with_file_access():  # APOC opens URLs with what these bring
        (plugins / jar.name).symlink_to(jar)
    # robotale's server loads no plugin's routines unless the user's settings name them
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / "neo4j.conf").write_text("dbms.security.procedures.allowlist=apoc.*\n")
    server = LocalServer(tmp_path / "home")
    options = ServerOptions(free_port(), free_port(), "512m", "64m", plugins)
    running = server.start(options)
    attack = (
        "RETURN apoc.cypher.runFirstColumnSingle('LOAD CSV FROM $url AS l RETURN l', "
        "{url: $url}) AS line"
    )
    url = loopback_service["url"]
    try:
        auth = ("neo4j", server.password() or "")
        with GraphDatabase.driver(running.bolt_uri, auth=auth) as driver:
            # The threat is real: without the console's check the service is read.
            with driver.session(default_access_mode=READ_ACCESS) as session:
                line = session.run(attack, url=url).single()["line"]
            assert line == ["secret"] and loopback_service["hits"] == 1
            with pytest.raises(QueryRefused, match=r"function apoc\.cypher\.runFirstColumnSingle"):
                run_read_only(driver, attack, {"url": url}, database="neo4j")
            assert loopback_service["hits"] == 1
    finally:
        server.stop()
