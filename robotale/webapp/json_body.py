"""A request's JSON body, read only when it is small and shallow enough.

Python's parser recurses once per level: a body nested thousands deep raised
``RecursionError`` (an HTTP 500), and a deep parameter cost the worker that packs it for
Neo4j. The size is checked before the body is read and the depth before it is parsed, each
refusal one sentence.
"""

from __future__ import annotations

import json
import re
from typing import Any

from flask import Request

from robotale.errors import InputError

#: bytes a JSON request body may have
MAX_BYTES = 1_000_000
#: levels of arrays and objects a JSON request body may nest
MAX_DEPTH = 32

_STRING = re.compile(r'"(?:\\.|[^"\\])*"', re.DOTALL)
_BRACKET = re.compile(r"[\[\]{}]")


def read_json(
    request: Request, shape: str, max_bytes: int = MAX_BYTES, max_depth: int = MAX_DEPTH
) -> Any:
    """The parsed body of ``request``; :class:`InputError` when it is larger than
    ``max_bytes``, nests deeper than ``max_depth`` or is no JSON (the sentence then asks for
    ``shape``, what the endpoint takes)."""
    if request.content_length is not None and request.content_length > max_bytes:
        raise InputError(_too_large(request.content_length, max_bytes))
    data = request.stream.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise InputError(_too_large(None, max_bytes))
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(f"The request body is not UTF-8 text (byte {error.start}).") from None
    if (found := depth(text)) > max_depth:
        raise InputError(
            f"The request's JSON nests {found} levels deep; send at most {max_depth} levels "
            "of arrays and objects."
        )
    try:
        return json.loads(text)
    except json.JSONDecodeError as error:
        raise InputError(
            f"Send {shape} as JSON (the body is not: {error.msg} at line {error.lineno}, "
            f"column {error.colno})."
        ) from None


def depth(text: str) -> int:
    """How deep the arrays and objects of JSON ``text`` nest (strings left out)."""
    deepest = level = 0
    for bracket in _BRACKET.findall(_STRING.sub("", text)):
        level += 1 if bracket in "[{" else -1
        deepest = max(deepest, level)
    return deepest


def _too_large(size: int | None, limit: int) -> str:
    sent = f" ({size:,} bytes)" if size is not None else ""
    return f"The request body is larger than {limit:,} bytes{sent}; send a smaller one."
