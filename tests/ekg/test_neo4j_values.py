"""The values an event property is sent to Neo4j as, column by column: each missing value is
None and each other one the plain Python value written by hand here."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from robotale.ekg.load import neo4j_values


@pytest.mark.parametrize(
    ("column", "expected"),
    [
        (pd.Series([0.5, 2.0, -1.25]), [0.5, 2.0, -1.25]),
        (pd.Series([0.5, np.nan, 3.0]), [0.5, None, 3.0]),
        (pd.Series([np.nan, np.nan]), [None, None]),
        (pd.Series([0.5, None], dtype="Float64"), [0.5, None]),
        (pd.Series([0.5, 1.5], dtype="float32"), [0.5, 1.5]),
        (pd.Series([], dtype=float), []),
        (pd.Series([3, None], dtype="Int64"), [3, None]),
        (pd.Series(["a", None]), ["a", None]),
    ],
    ids=["floats", "a-gap", "all-gaps", "nullable", "float32", "empty", "ints", "text"],
)
def test_missing_values_become_none_and_the_others_plain_python(column, expected):
    values = neo4j_values(column)
    assert values == expected
    assert all(type(v) is type(e) for v, e in zip(values, expected, strict=True))
