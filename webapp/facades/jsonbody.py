"""JSON request bodies with bounded nesting: the API's parser and the pages' pasted JSON read through here, so a
document nested thousands of levels deep is a 400 naming the problem instead of a RecursionError (a 500), and
nothing deeper than `MAX_DEPTH` reaches the code that stores or walks the data."""

from __future__ import annotations

import json
from typing import Any

from rest_framework import parsers
from rest_framework.exceptions import ParseError

MAX_DEPTH = 64  # procedures nest at most 32 nodes deep (facaid.grammar.procedure.MAX_DEPTH), each an object and a list


class JSONError(ValueError):
    """Malformed or too deeply nested JSON; the message says which."""


def depth_error(obj: Any, limit: int = MAX_DEPTH) -> str | None:
    """The message for a document nested deeper than ``limit`` containers, else None (walked without recursion)."""
    stack = [(obj, 1)]
    while stack:
        value, depth = stack.pop()
        if isinstance(value, dict | list):
            if depth > limit:
                return f"JSON nested more than {limit} levels deep"
            stack.extend((v, depth + 1) for v in (value.values() if isinstance(value, dict) else value))
    return None


def loads(raw: str | bytes) -> Any:
    """`json.loads` with bounded nesting; raise `JSONError` with a message for a person."""
    try:
        obj = json.loads(raw)
    except RecursionError:
        raise JSONError(f"JSON nested more than {MAX_DEPTH} levels deep") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise JSONError(f"not valid JSON: {exc}") from None
    message = depth_error(obj)
    if message:
        raise JSONError(message)
    return obj


class JSONParser(parsers.JSONParser):
    """DRF's JSON parser (strict: no NaN or Infinity) with bounded nesting."""

    def parse(self, stream, media_type=None, parser_context=None):
        try:
            data = super().parse(stream, media_type, parser_context)
        except RecursionError:
            raise ParseError(f"JSON parse error - nested more than {MAX_DEPTH} levels deep") from None
        message = depth_error(data)
        if message:
            raise ParseError(f"JSON parse error - {message}")
        return data
