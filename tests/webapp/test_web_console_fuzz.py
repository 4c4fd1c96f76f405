"""Fuzz the console's JSON encoder (hypothesis): any value Neo4j can hand back becomes strict
JSON (no NaN or Infinity tokens, integers a browser holds exactly), both as a Python value and
after a round trip through the session's real Neo4j.

A few hundred examples per run; `make fuzz` runs many more (ROBOTALE_FUZZ_EXAMPLES)."""

from __future__ import annotations

import json
import math
import os
from typing import Any

import pytest

hypothesis = pytest.importorskip("hypothesis", reason="hypothesis is in the dev extra")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from robotale.webapp import console  # noqa: E402

INT64 = st.integers(min_value=-(2**63), max_value=2**63 - 1)
SCALARS = (
    st.none() | st.booleans() | INT64 | st.floats(allow_nan=True, allow_infinity=True) | st.text()
)
#: what Neo4j accepts as a parameter and returns as it was (lists, maps with text keys)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(), inner, max_size=5),
    max_leaves=20,
)


def expected(value: Any) -> Any:
    """The JSON the console should send for ``value``, written from the rules, not the code."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return value if -(2**53 - 1) <= value <= 2**53 - 1 else str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "NaN"
        if math.isinf(value):
            return "Infinity" if value > 0 else "-Infinity"
        return value
    if isinstance(value, list):
        return [expected(item) for item in value]
    return {key: expected(item) for key, item in value.items()}


def strict(text: str) -> Any:
    def refuse(name: str) -> None:
        raise AssertionError(f"{name} in the console's JSON")

    return json.loads(text, parse_constant=refuse)


@given(VALUES | st.binary(max_size=20))
@settings(max_examples=int(os.environ.get("ROBOTALE_FUZZ_EXAMPLES", "400")))
def test_any_value_becomes_strict_json(value):
    encoded = json.dumps(console.cell(value), allow_nan=False)
    decoded = strict(encoded)
    if isinstance(value, bytes):
        assert decoded == value.hex()
    else:
        assert decoded == expected(value)


@given(VALUES)
@settings(
    max_examples=int(os.environ.get("ROBOTALE_FUZZ_EXAMPLES", "150")),
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
def test_values_through_neo4j_become_strict_json(neo4j_driver, value):
    [result] = console.run_read_only(neo4j_driver, "RETURN $value AS value", {"value": value})
    decoded = strict(json.dumps(result.to_dict(), allow_nan=False))
    assert decoded["rows"] == [[expected(value)]]
