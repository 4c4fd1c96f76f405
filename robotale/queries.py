"""Load the Cypher files of ``cypher/`` (installed as the package ``robotale.cypher``) and split
text into statements, the one way robotale does (its own files, the dashboard's console)."""

from __future__ import annotations

import re
from collections.abc import Iterator
from functools import cache
from importlib.resources import files

#: one piece of Cypher text: a quoted string or name, a comment, a ``;``, or other code
_PIECE = re.compile(
    r"""(?P<quoted>'(?:\\.?|[^'\\])*(?:'|$)|"(?:\\.?|[^"\\])*(?:"|$)|`[^`]*(?:`|$))
      | (?P<comment>//[^\n\r]*|/\*.*?(?:\*/|$))
      | (?P<end>;)
      | (?P<code>[^'"`/;]+|/)""",
    re.VERBOSE | re.DOTALL,
)


@cache
def cypher(name: str) -> str:
    """The text of ``cypher/<name>.cypher``."""
    return (files("robotale.cypher") / f"{name}.cypher").read_text(encoding="utf-8")


def statements(name: str) -> list[str]:
    """The statements of a file that holds several, without their comments."""
    return split_statements(cypher(name), comments=False)


def split_statements(text: str, *, comments: bool = True) -> list[str]:
    """The statements of ``text``: split at each ``;`` outside strings, quoted names and
    comments, each stripped; statements of nothing but comments are dropped. Without
    ``comments`` the comments are taken out of the statements too."""
    found: list[str] = []
    parts: list[str] = []
    has_code = False
    for kind, piece in _pieces(text):
        if kind == "end":
            if has_code:
                found.append("".join(parts).strip())
            parts, has_code = [], False
            continue
        if kind == "comment" and not comments:
            piece = " " if piece.startswith("/*") else ""  # a block comment still separates
        parts.append(piece)
        has_code = has_code or (kind != "comment" and bool(piece.strip()))
    if has_code:
        found.append("".join(parts).strip())
    return found


def code_only(text: str) -> str:
    """``text`` with its strings, quoted names and comments blanked out (same length, so
    offsets still point into ``text``): what is left are keywords, names and operators."""
    return "".join(
        piece if kind in ("code", "end") else re.sub(r"[^\n]", " ", piece)
        for kind, piece in _pieces(text)
    )


def dotted_calls(text: str) -> list[tuple[str, str]]:
    """Every call of a dotted name in ``text`` (``apoc.cypher.run(``, `` `db`.labels ( ``),
    outside strings and comments, as (the word before it, the name with its quotes taken off):
    the word is ``CALL`` for a procedure."""
    # (is a name, text): words and quoted names are names; strings and punctuation are not
    tokens: list[tuple[bool, str]] = []
    for kind, piece in _pieces(text):
        if kind == "quoted":
            tokens.append((piece.startswith("`"), piece.strip("`")))
        elif kind in ("code", "end"):
            tokens += [(bool(_WORD.fullmatch(t)), t) for t in _TOKEN.findall(piece)]
    calls = []
    for start, (is_name, _) in enumerate(tokens):
        if not is_name or (start and tokens[start - 1][1] == "."):
            continue
        end = start
        while end + 2 < len(tokens) and tokens[end + 1][1] == "." and tokens[end + 2][0]:
            end += 2
        if end > start and end + 1 < len(tokens) and tokens[end + 1][1] == "(":
            before = tokens[start - 1][1] if start else ""
            calls.append((before, "".join(text for _, text in tokens[start : end + 1])))
    return calls


_TOKEN = re.compile(r"\w+|\S")
_WORD = re.compile(r"\w+")


def _pieces(text: str) -> Iterator[tuple[str, str]]:
    # An unterminated string or comment runs to the end of the text, as Neo4j reads it.
    for match in _PIECE.finditer(text):
        yield str(match.lastgroup), match.group()
