"""The aggregation specification and its where filters, read without Neo4j: what a
condition becomes (checked by hand), and one clear sentence for each thing refused."""

from __future__ import annotations

import datetime as dt

import pytest

from robotale.ekg.spec import parse_spec, read_spec
from robotale.ekg.where import parse_where
from robotale.errors import InputError

KNOWN = {"battery", "activity", "robot", "x", "y", "timestamp", "field name"}


def where(text: str):
    return parse_where(text, "n", KNOWN, "the where of step 1")


def test_and_binds_tighter_than_or_and_values_are_parameters():
    found = where("battery < 50 and not activity = 'charge' or x in [1, 2.5] and y is not null")
    assert found.cypher == (
        "((n.`battery` < $w0 AND (NOT n.`activity` = $w1)) OR (n.`x` IN $w2 AND n.`y` IS NOT NULL))"
    )
    assert found.parameters == {"w0": 50, "w1": "charge", "w2": [1, 2.5]}
    assert found.names == {"battery", "activity", "x", "y"}


def test_quoted_names_texts_and_times():
    found = where(
        '`field name` == "it\'s" AND '
        "(robot != 'a\\'b' OR timestamp >= datetime('2024-03-31T01:00:00'))"
    )
    # a parenthesised part keeps its own parentheses
    assert found.cypher == (
        "(n.`field name` = $w0 AND ((n.`robot` <> $w1 OR n.`timestamp` >= $w2)))"
    )
    assert found.parameters["w0"] == "it's" and found.parameters["w1"] == "a'b"
    assert found.parameters["w2"] == dt.datetime(2024, 3, 31, 1, 0, tzinfo=dt.UTC)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("speed > 3", "names 'speed'"),
        ("battery >", "at its end: expected a value"),
        ("battery > 3 battery", r"at character 13 \('battery'\): expected and, or or the end"),
        ("battery > 3; MATCH (m) DETACH DELETE m", "cannot be read at character 12"),
        ("x = 1 or", "at its end: expected a property name"),
        ("and = 1", "expected a property name"),
        ("`a`b` = 1", "cannot be read"),
        ("x in 1", "expected \\[ after in"),
        ("x is 1", "expected null"),
        ("timestamp > datetime('yesterday')", "'yesterday' is not an ISO time"),
        ("(x = 1", "expected \\)"),
        ("", "is empty"),
    ],
)
def test_refused_conditions(text, message):
    with pytest.raises(InputError, match=message):
        where(text)


def test_a_specification_file(tmp_path):
    path = tmp_path / "spec.yaml"
    path.write_text(
        "steps:\n"
        "  - aggr_type: entities\n"
        "    ent_type: robot\n"
        "    group_by: type\n"
        "  - aggr_type: EVENTS\n"
        "    group_by: [activity, {grid: {size: 2}}, {window: {size: 5min}, as: slot},\n"
        "               {band: {property: battery, width: 10}},\n"
        "               {regions: {areas: {a: {box: [0, 0, 1, 1]},\n"
        "                                  b: [[0, 0], [2, 0], [0, 2]]}}}]\n"
        "    where: battery < 50\n"
        "    attr_aggrs: [{name: battery, function: minmax}]\n"
    )
    first, second = read_spec(path)
    assert (first.aggr_type, first.ent_type, first.origin) == ("ENTITIES", "robot", "Entity")
    assert [k.name for k in second.group_by] == [
        "activity",
        "cell",
        "slot",
        "battery_band",
        "region",
    ]
    assert second.group_by[2].size == 300 and second.group_by[1].inputs == ("x", "y")
    assert second.group_by[4].areas[0] == ("a", ((0, 0), (1, 0), (1, 1), (0, 1)))
    assert second.attr_aggrs[0].outputs() == ["battery_min", "battery_max"]
    assert second.reads() == ["activity", "x", "y", "timestamp", "battery"]


@pytest.mark.parametrize(
    ("document", "message"),
    [
        ({}, "has no steps"),
        (
            {"steps": [{"aggr_type": "NODES", "group_by": ["a"]}]},
            "needs aggr_type ENTITIES or EVENTS",
        ),
        ({"steps": [{"aggr_type": "ENTITIES", "group_by": ["a"]}]}, "give their ent_type"),
        (
            {"steps": [{"aggr_type": "EVENTS", "ent_type": "robot", "group_by": ["a"]}]},
            "leave ent_type out",
        ),
        ({"steps": [{"aggr_type": "EVENTS", "group_by": []}]}, "needs a group_by list"),
        (
            {"steps": [{"aggr_type": "EVENTS", "group_by": ["a"], "wher": "x"}]},
            "unknown key 'wher'",
        ),
        ({"steps": [{"aggr_type": "EVENTS", "group_by": ["a", "a"]}]}, "names a key twice"),
        (
            {"steps": [{"aggr_type": "EVENTS", "group_by": [{"grid": {"size": 0}}]}]},
            "positive size",
        ),
        (
            {"steps": [{"aggr_type": "EVENTS", "group_by": [{"window": {"size": "soon"}}]}]},
            "positive size",
        ),
        (
            {"steps": [{"aggr_type": "EVENTS", "group_by": [{"band": {"width": 5}}]}]},
            "needs property",
        ),
        (
            {
                "steps": [
                    {
                        "aggr_type": "EVENTS",
                        "group_by": [{"regions": {"areas": {"a": [[0, 0], [1, 1]]}}}],
                    }
                ]
            },
            "neither a polygon",
        ),
        ({"steps": [{"aggr_type": "EVENTS", "group_by": [{"hexagons": {}}]}]}, "derived keys are"),
        (
            {
                "steps": [
                    {
                        "aggr_type": "EVENTS",
                        "group_by": ["a"],
                        "attr_aggrs": [{"name": "b", "function": "MEDIAN"}],
                    }
                ]
            },
            "asks for the function 'MEDIAN'",
        ),
        (
            {"steps": [{"aggr_type": "EVENTS", "group_by": ["a`b"]}]},
            "cannot be used as a Neo4j name",
        ),
    ],
)
def test_refused_specifications(document, message):
    with pytest.raises(InputError, match=message):
        parse_spec(document)


def test_a_file_that_is_no_yaml(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("steps:\n  - [unclosed\n")
    with pytest.raises(InputError, match=r"bad\.yaml is not valid YAML at line"):
        read_spec(path)
    with pytest.raises(InputError, match="cannot be read"):
        read_spec(tmp_path / "missing.yaml")
