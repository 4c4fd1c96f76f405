"""The one Cypher statement splitter, for robotale's own files and for the console."""

from __future__ import annotations

from importlib.resources import files

import pytest

from robotale.queries import split_statements, statements


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("RETURN 1; RETURN 2;", ["RETURN 1", "RETURN 2"]),
        ("RETURN 'a;b' AS x; RETURN \"c;d\"", ["RETURN 'a;b' AS x", 'RETURN "c;d"']),
        (r"RETURN 'it\'s; fine'; RETURN 2", [r"RETURN 'it\'s; fine'", "RETURN 2"]),
        (
            "MATCH (`odd;name`) RETURN 1; RETURN `a``;b`",
            ["MATCH (`odd;name`) RETURN 1", "RETURN `a``;b`"],
        ),
        ("RETURN 'http://x;y'", ["RETURN 'http://x;y'"]),
        ("RETURN 4/2; RETURN 1", ["RETURN 4/2", "RETURN 1"]),
        ("RETURN 1 // no; split\n; RETURN 2", ["RETURN 1 // no; split", "RETURN 2"]),
        ("/* a; b */ RETURN 1;;  ; // only a comment;\n", ["/* a; b */ RETURN 1"]),
        ("RETURN 'open; string", ["RETURN 'open; string"]),
        ("", []),
    ],
)
def test_statements_split_at_semicolons_outside_strings_names_and_comments(text, expected):
    assert split_statements(text) == expected


def test_comments_can_be_left_out_without_joining_words():
    text = "// head; note\nMATCH (n) /* why; */RETURN n // tail\n;\nRETURN '// kept' AS s;"
    assert split_statements(text, comments=False) == [
        "MATCH (n)  RETURN n",
        "RETURN '// kept' AS s",
    ]


def test_every_file_splits_where_its_lines_end_in_a_semicolon():
    # robotale's files end each statement at the end of a line, so a reader counts them
    # by looking at the lines.
    for resource in files("robotale.cypher").iterdir():
        if not resource.name.endswith(".cypher"):
            continue
        name = resource.name.removesuffix(".cypher")
        lines = [
            line.rstrip()
            for line in resource.read_text(encoding="utf-8").splitlines()
            if line.strip() and not line.lstrip().startswith("//")
        ]
        ends = sum(line.endswith(";") for line in lines)
        expected = ends + (0 if lines[-1].endswith(";") else 1)
        found = statements(name)
        assert len(found) == expected, name
        assert not any(s.endswith(";") or "//" in s.split("'")[0] for s in found), name
