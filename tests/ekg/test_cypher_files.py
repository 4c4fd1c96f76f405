"""Every statement of every file in cypher/ is planned by the session's Neo4j (whichever
release ``ROBOTALE_TEST_NEO4J_VERSION`` names) without a deprecation: what a new release
removed or deprecated shows up here before it breaks a command."""

from __future__ import annotations

import re
from importlib.resources import files

import pytest

from robotale.queries import statements

NAMES = sorted(
    entry.name.removesuffix(".cypher")
    for entry in files("robotale.cypher").iterdir()
    if entry.name.endswith(".cypher")
)
#: files whose statements administer users: planned on the system database
SYSTEM = {"console_user"}
_PARAMETER = re.compile(r"\$(\w+)")


def _deprecations(driver, statement: str, database: str | None = None) -> list[str]:
    parameters = dict.fromkeys(_PARAMETER.findall(statement))
    _, summary, _ = driver.execute_query(f"EXPLAIN {statement}", parameters, database_=database)
    return [
        status.status_description
        for status in summary.gql_status_objects
        if "deprecat" in (status.status_description or "").lower()
    ]


@pytest.mark.parametrize("name", NAMES)
def test_every_statement_is_planned_without_deprecations(neo4j_driver, name):
    database = "system" if name in SYSTEM else None
    for statement in statements(name):
        deprecated = _deprecations(neo4j_driver, statement, database)
        assert not deprecated, f"{name}: {deprecated}"


def test_the_check_sees_a_deprecated_function(neo4j_driver):
    """The node lookup the queries used before elementId: the server says it is deprecated."""
    assert _deprecations(neo4j_driver, "MATCH (n) WHERE id(n) = $node RETURN n")
