"""The console's verdict against a real server that has APOC loaded: no spelling of a query
(comments ended by each line terminator, unicode escapes, backticks, query options, ``USE``,
subqueries, ``IN TRANSACTIONS``, parameters, nested calls) gets a plugin's function or
procedure run, or anything written. What would have run is observed from outside: an HTTP
service on 127.0.0.1 counts the requests APOC would send it, and the graph is counted before
and after. A second server, started with robotale's default settings, does not load APOC at
all."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest
from counting_service import counting_service
from neo4j import Driver, GraphDatabase

from robotale.ekg import plan_check, readonly
from robotale.errors import InputError
from robotale.neo4j_server import jars
from robotale.neo4j_server.server import LocalServer, PortInUse, ServerOptions, free_port

pytestmark = pytest.mark.slow

#: a call that fetches the service's URL when APOC runs it
FETCH = "apoc.cypher.runFirstColumnSingle('LOAD CSV FROM $url AS l RETURN l', {url: $url})"
TERMINATORS = {
    "lf": "\n",
    "cr": "\r",
    "crlf": "\r\n",
    "line-separator": "\u2028",
    "paragraph-separator": "\u2029",
    "next-line": "\u0085",
    "vertical-tab": "\x0b",
    "form-feed": "\x0c",
}
#: (query, the rows Neo4j returns when what hides the plugin's call really hides it)
SPELLINGS: dict[str, tuple[str, list | None]] = {
    # the two the text check let through
    "comment ended by cr": (f"RETURN 1 AS a //x\r, {FETCH} AS v", None),
    "unicode escape": ("RETURN apoc.\\u0076ersion() AS v", None),
    **{
        f"comment ended by {name}": (f"RETURN 1 AS a //x{end}, {FETCH} AS v", [[1]])
        for name, end in TERMINATORS.items()
    },
    **{
        f"leading comment ended by {name}": (f"//x{end}CALL apoc.load.json($url)", None)
        for name, end in TERMINATORS.items()
    },
    "block comment": (f"RETURN /* x */ {FETCH} /* y */ AS v", None),
    "escape in the namespace": (
        "RETURN \\u0061poc.cypher.runFirstColumnSingle($q, {}) AS v",
        None,
    ),
    "escape in a procedure": ("CALL apoc.\\u006Coad.json($url)", None),
    "backticks": ("RETURN `apoc`.`version`() AS v", None),
    "backticked part": ("RETURN apoc.`cypher`.runFirstColumnSingle($q, {}) AS v", None),
    "spaced dots": ("RETURN apoc . cypher . runFirstColumnSingle($q, {}) AS v", None),
    "upper-case procedure call": ("call apoc.load.json($url) yield value return value", None),
    "cypher version": (f"CYPHER 5 RETURN {FETCH} AS v", None),
    "cypher runtime": (f"CYPHER runtime=slotted RETURN {FETCH} AS v", None),
    "cypher planner and runtime": (f"CYPHER planner=cost runtime=pipelined RETURN {FETCH}", None),
    "profile": (f"PROFILE RETURN {FETCH} AS v", None),
    "explain then profile": (f"EXPLAIN CYPHER 5 RETURN {FETCH} AS v", None),
    "use": (f"USE neo4j RETURN {FETCH} AS v", None),
    "use behind a comment": ("//\rUSE system SHOW TRANSACTIONS", None),
    "call subquery": (f"CALL () {{ RETURN {FETCH} AS v }} RETURN v", None),
    "old call subquery": (f"CALL {{ RETURN {FETCH} AS v }} RETURN v", None),
    "collect subquery": (f"RETURN COLLECT {{ RETURN {FETCH} AS v }} AS c", None),
    "exists subquery": (f"RETURN EXISTS {{ WITH 1 AS x WHERE {FETCH} IS NULL }} AS e", None),
    "count subquery": (f"RETURN COUNT {{ WITH 1 AS x WHERE {FETCH} IS NULL }} AS c", None),
    "union": (f"RETURN 1 AS v UNION RETURN {FETCH} AS v", None),
    "in transactions": (
        f"UNWIND [1] AS i CALL (i) {{ RETURN {FETCH} AS v }} IN TRANSACTIONS RETURN v",
        None,
    ),
    "in transactions behind a comment": (
        "UNWIND [1] AS i //\rCALL (i) { RETURN i AS v } IN TRANSACTIONS RETURN v",
        None,
    ),
    "query as a parameter": ("RETURN apoc.cypher.runFirstColumnSingle($q, {}) AS v", None),
    "procedure through a parameter": (
        "CALL apoc.cypher.run($q, {}) YIELD value RETURN value",
        None,
    ),
    "nested in a function": (f"RETURN toUpper(toString({FETCH})) AS v", None),
    "in a list comprehension": (f"RETURN [x IN [1] | {FETCH}] AS v", None),
    "in reduce": (f"RETURN reduce(s = '', x IN [1] | s + toString({FETCH})) AS v", None),
    "in case": (f"RETURN CASE WHEN true THEN {FETCH} END AS v", None),
    "in where": (f"WITH 1 AS x WHERE {FETCH} IS NULL RETURN x", None),
    "in order by": (f"UNWIND [1, 2] AS x RETURN x ORDER BY {FETCH}", None),
    "in limit": ("RETURN 1 AS x LIMIT toInteger(size(apoc.version()))", None),
    "in a map": (f"RETURN {{a: {FETCH}}} AS m", None),
    "in a pattern predicate": (f"MATCH (n) WHERE n.x = {FETCH} RETURN n", None),
    "in a procedure's argument": (
        f"CALL db.labels() YIELD label WITH label WHERE {FETCH} IS NULL RETURN label",
        None,
    ),
    "after an allowed procedure": ("CALL db.labels() YIELD label CALL apoc.load.json($url)", None),
    # what the attacker did with APOC
    "list transactions": (
        "CALL apoc.cypher.run('SHOW TRANSACTIONS YIELD currentQuery', {}) YIELD value RETURN value",
        None,
    ),
    "read settings": ("CALL apoc.config.list() YIELD key, value RETURN key, value", None),
    "read settings as a map": ("RETURN apoc.config.map() AS settings", None),
    "terminate through a comment": ("//\rTERMINATE TRANSACTIONS 'neo4j-transaction-1'", None),
    "list transactions through a comment": ("//\rSHOW TRANSACTIONS", None),
    "settings through a comment": ("//\rCALL dbms.listConfig()", None),
    "exhaust the heap": ("RETURN size(apoc.text.repeat('a', 300000000)) AS n", None),
    # writes
    "apoc create": ("CALL apoc.create.node(['Probe'], {}) YIELD node RETURN node", None),
    "apoc cypher doIt": ("CALL apoc.cypher.doIt('CREATE (:Probe)', {})", None),
    "create behind a comment": ("//\rCREATE (:Probe)", None),
    "merge behind an escape": ("M\\u0045RGE (p:Probe) RETURN p", None),
    "periodic iterate": (
        "CALL apoc.periodic.iterate('RETURN 1', 'CREATE (:Probe)', {}) YIELD total",
        None,
    ),
}


@pytest.fixture(scope="module")
def service() -> Iterator[dict]:
    """An HTTP service on 127.0.0.1 that counts what it is asked (``hits``)."""
    with counting_service(b'{"secret": 1}\n') as seen:
        yield seen


def _server_with_apoc(home: Path, overlay: str) -> Iterator[tuple[Driver, Driver]]:
    """A local server of ``home`` with APOC core and extended in its plugins folder and
    ``overlay`` as the user's settings: (an administrator's driver, the console user's)."""
    plugins = home / "plugins"
    plugins.mkdir(parents=True)
    for jar in jars.apoc_with_file_access():
        (plugins / jar.name).symlink_to(jar)
    (home / "neo4j.conf").write_text(overlay)
    server = LocalServer(home)
    for attempt in range(3):  # a free port can be taken before Neo4j binds it
        try:
            running = server.start(ServerOptions(free_port(), free_port(), heap="1g"))
            break
        except PortInUse:
            if attempt == 2:
                raise
    admin = GraphDatabase.driver(running.bolt_uri, auth=("neo4j", server.password()))
    user, password = server.console_credentials()
    console = GraphDatabase.driver(running.bolt_uri, auth=(user, password))
    try:
        yield admin, console
    finally:
        console.close()
        admin.close()
        server.stop()


@pytest.fixture(scope="module")
def apoc_server(tmp_path_factory) -> Iterator[tuple[Driver, Driver]]:
    """A server where APOC loads and may do everything (the overlay allows it)."""
    overlay = (
        "dbms.security.procedures.allowlist=apoc.*\ndbms.security.procedures.unrestricted=apoc.*\n"
    )
    yield from _server_with_apoc(tmp_path_factory.mktemp("apoc-home"), overlay)


def _parameters(service: dict) -> dict:
    return {"url": service["url"], "q": f"LOAD CSV FROM '{service['url']}' AS l RETURN l"}


def test_apoc_runs_for_an_administrator_so_the_probes_would_notice(apoc_server, service):
    admin, _ = apoc_server
    before = service["hits"]
    records, _, _ = admin.execute_query(f"RETURN {FETCH} AS v", _parameters(service))
    assert records[0]["v"] == ['{"secret": 1}']
    records, _, _ = admin.execute_query(
        "CALL apoc.load.json($url) YIELD value RETURN value", _parameters(service)
    )
    assert records[0]["value"] == {"secret": 1}
    assert service["hits"] == before + 2
    records, _, _ = admin.execute_query("RETURN apoc.\\u0076ersion() AS v")
    assert records[0]["v"].startswith("5.26")


@pytest.mark.parametrize("name", list(SPELLINGS))
def test_no_spelling_runs_a_plugin_or_writes(apoc_server, service, name):
    admin, console = apoc_server
    query, harmless = SPELLINGS[name]
    hits, nodes = service["hits"], _nodes(admin)
    try:
        results = readonly.run_read_only(
            console, query, _parameters(service), timeout=60, database="neo4j"
        )
    except InputError as refusal:
        assert "\n" not in str(refusal)
    else:
        assert harmless is not None, f"{query!r} ran"
        assert [result.rows for result in results] == [harmless]
    assert service["hits"] == hits, f"{query!r} reached the service"
    assert _nodes(admin) == nodes, f"{query!r} wrote"


@pytest.mark.parametrize("name", list(SPELLINGS))
def test_the_plan_alone_refuses_what_neo4j_would_run(apoc_server, service, name):
    """Without the text filter: Neo4j's plan of each query is refused, or Neo4j cannot plan
    it, or it hides the call from Neo4j too (a terminator Neo4j does not end comments at)."""
    _, console = apoc_server
    query, harmless = SPELLINGS[name]
    with console.session(database="neo4j") as session:
        try:
            readonly.refuse_plan(session, query, _parameters(service), "neo4j")
        except plan_check.QueryRefused:
            return
        except Exception as error:  # Neo4j's own refusal to plan it (syntax, unknown name)
            assert type(error).__module__.startswith("neo4j"), error
            return
    assert harmless is not None, f"the plan of {query!r} passed"


def test_the_allowed_functions_and_procedures_still_run(apoc_server):
    _, console = apoc_server
    results = readonly.run_read_only(
        console,
        "RETURN duration.between(date('2024-01-01'), date('2024-01-03')).days AS d, "
        "toUpper('a') AS u, vector.similarity.cosine([1.0, 0.0], [1.0, 0.0]) AS c",
        database="neo4j",
    )
    assert results[0].rows == [[2, "A", 1.0]]


def test_a_default_server_does_not_load_apoc(tmp_path):
    for admin, console in _server_with_apoc(tmp_path / "home", ""):
        # spelled past the text filter: the server itself has no such function or procedure
        for query in ("RETURN apoc.\\u0076ersion() AS v", "CALL apoc.\\u0068elp('load')"):
            with pytest.raises(Exception, match=r"Unknown function|no procedure"):
                admin.execute_query(query)
            with pytest.raises(
                InputError, match=r"^Neo4j could not run the query: (Unknown|There)"
            ):
                readonly.run_read_only(console, query, database="neo4j")
        records, _, _ = admin.execute_query("CALL db.labels() YIELD label RETURN count(*) AS n")
        assert records[0]["n"] >= 0


def _nodes(driver: Driver) -> int:
    records, _, _ = driver.execute_query("MATCH (n) RETURN count(n) AS n")
    return records[0]["n"]
