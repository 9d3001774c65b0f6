"""JSON request bodies with bounded nesting: the API's parser and the pages' pasted JSON read through here, so a
document nested thousands of levels deep is a 400 naming the problem instead of a RecursionError (a 500), and
nothing deeper than `MAX_DEPTH` reaches the code that stores or walks the data."""

from __future__ import annotations

import json
from typing import Any

from rest_framework import parsers
from rest_framework.exceptions import ParseError

from facaid.grammar.procedure import MAX_DEPTH as GRAMMAR_MAX_DEPTH

# A procedure's node at grammar depth d lies 3 + 2d containers deep in a request ({"data": {"root": {"children":
# [...]}}}) and its sizes' pairs 2 deeper; the grammar allows d <= 32 (facaid.grammar.procedure.MAX_DEPTH)
MAX_DEPTH = 2 * GRAMMAR_MAX_DEPTH + 8


class JSONError(ValueError):
    """Malformed or too deeply nested JSON; the message says which."""


def depth_error(obj: Any, limit: int = MAX_DEPTH) -> str | None:
    """The message for a document nested deeper than ``limit`` containers, else None. Walked without recursion,
    with one iterator per open container: memory grows with the depth, not with the size."""
    stack = [iter((obj,))]
    while stack:
        for value in stack[-1]:
            if isinstance(value, dict | list):
                if len(stack) > limit:
                    return f"JSON nested more than {limit} levels deep"
                stack.append(iter(value.values() if isinstance(value, dict) else value))
                break
        else:
            stack.pop()
    return None


def loads(raw: str | bytes) -> Any:
    """`json.loads` with bounded nesting; raise `JSONError` with a message for a person."""
    try:
        obj = json.loads(raw)
    except RecursionError:
        raise JSONError(f"JSON nested more than {MAX_DEPTH} levels deep") from None
    except ValueError as exc:  # malformed, not UTF-8, or an integer of more digits than Python converts
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
