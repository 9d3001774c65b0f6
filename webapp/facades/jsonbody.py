"""JSON request bodies with bounded nesting and text only: the API's parser and the pages' pasted JSON read through
here, so a document nested thousands of levels deep is a 400 naming the problem instead of a RecursionError (a
500), nothing deeper than `MAX_DEPTH` reaches the code that stores or walks the data, and no key or string in it
holds an unpaired surrogate (``"\\ud800"``: JSON may write one, UTF-8 cannot, so echoing it in an error message,
storing it or writing it to a file failed): a 400 that names the field. The API's answers are written by
`JSONRenderer`, which cannot fail on such text either. (A NUL is text: the fields that cannot store one say so.)"""

from __future__ import annotations

import json
import re
from typing import Any

import numpy as np
from django.conf import settings
from rest_framework import parsers, renderers
from rest_framework.exceptions import ParseError
from rest_framework.utils import json as drf_json

from facaid.grammar.procedure import MAX_DEPTH as GRAMMAR_MAX_DEPTH
from webapp.facades.errors import Invalid

# A procedure's node at grammar depth d lies 3 + 2d containers deep in a request ({"data": {"root": {"children":
# [...]}}}) and its sizes' pairs 2 deeper; the grammar allows d <= 32 (facaid.grammar.procedure.MAX_DEPTH)
MAX_DEPTH = 2 * GRAMMAR_MAX_DEPTH + 8

# surrogates are text only in pairs, which a decoded JSON string holds as one character: any left is unpaired
_NOT_TEXT = re.compile("[\ud800-\udfff]")


class JSONError(Invalid, ValueError):
    """Malformed or too deeply nested JSON, or a string that is not text; the message says which."""


def _where(path: tuple) -> str:
    out = "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".")
    return out or "the body"


def _text_error(text: str, path: tuple, what: str = "") -> str | None:
    bad = _NOT_TEXT.search(text)
    if bad is None:
        return None
    return f"{what or _where(path)} holds an unpaired surrogate (U+{ord(bad.group()):04X}): not plain JSON text"


def document_error(obj: Any, limit: int = MAX_DEPTH) -> str | None:
    """The message for a document nested deeper than ``limit`` containers, or with a key or string that is not
    plain text (naming where), else None. Walked without recursion, with one iterator per open container: memory
    grows with the depth, not with the size."""
    stack = [(iter(((None, obj),)), ())]
    while stack:
        items, where = stack[-1]
        for key, value in items:
            here = where if key is None else (*where, key)
            if isinstance(key, str) and (message := _text_error(key, here, f"a key of {_where(where)}")):
                return message
            if isinstance(value, str) and (message := _text_error(value, here)):
                return message
            if isinstance(value, dict | list):
                if len(stack) > limit:
                    return f"JSON nested more than {limit} levels deep"
                stack.append((iter(value.items() if isinstance(value, dict) else enumerate(value)), here))
                break
        else:
            stack.pop()
    return None


_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.S)  # a JSON string literal, escapes and all
_NOT_BRACKET = re.compile(r"[^\[\]{}]+")
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F]")  # a surrogate written as an escape (paired or not)


def plainly_fine(raw: str | bytes, limit: int = MAX_DEPTH) -> bool:
    """Whether a document that parsed is sure to pass `document_error`, told from its text in C-speed scans (the
    walk over every value took 8 ms of a 137 KB tree's 25 ms refusal): no surrogate in it, written or escaped, and
    its brackets, outside its strings, nested ``limit`` deep at most. False where it cannot tell (then walk)."""
    try:
        text = raw if isinstance(raw, str) else raw.decode("utf-8")
    except UnicodeDecodeError:  # UTF-16 or -32, which json.loads also reads
        return False
    if "\x00" in text or _SURROGATE_ESCAPE.search(text) or _NOT_TEXT.search(text):
        return False  # (a NUL: UTF-16 or -32 read as UTF-8, where the scans below would misread escapes)
    brackets = np.frombuffer(_NOT_BRACKET.sub("", _STRING.sub("", text)).encode(), dtype=np.uint8)
    if not len(brackets):
        return True
    return int(np.cumsum(np.where((brackets == ord("[")) | (brackets == ord("{")), 1, -1)).max()) <= limit


def loads(raw: str | bytes) -> Any:
    """`json.loads` with bounded nesting and plain text; raise `JSONError` with a message for a person."""
    try:
        obj = json.loads(raw)
    except RecursionError:
        raise JSONError(f"JSON nested more than {MAX_DEPTH} levels deep") from None
    except ValueError as exc:  # malformed, not UTF-8, or an integer of more digits than Python converts
        raise JSONError(f"not valid JSON: {exc}") from None
    if plainly_fine(raw):
        return obj
    message = document_error(obj)
    if message:
        raise JSONError(message)
    return obj


class JSONParser(parsers.JSONParser):
    """DRF's JSON parser (strict: no NaN or Infinity) with bounded nesting and plain text."""

    def parse(self, stream, media_type=None, parser_context=None):
        encoding = (parser_context or {}).get("encoding", settings.DEFAULT_CHARSET)
        try:  # as DRF's parser reads it (strict: no NaN or Infinity), keeping the text for `plainly_fine`
            text = (stream.read() if stream is not None else b"").decode(encoding)
            data = json.loads(text, parse_constant=drf_json.strict_constant if self.strict else None)
        except RecursionError:
            raise ParseError(f"JSON parse error - nested more than {MAX_DEPTH} levels deep") from None
        except ValueError as exc:
            raise ParseError(f"JSON parse error - {exc}") from None
        message = None if plainly_fine(text) else document_error(data)
        if message:
            raise ParseError(f"JSON parse error - {message}")
        return data


class JSONRenderer(renderers.JSONRenderer):
    """DRF's JSON renderer, which writes text as UTF-8 or, where that cannot be done (an unpaired surrogate that
    reached an answer some other way than a JSON body), escaped: the same JSON, not a 500."""

    def render(self, data, accepted_media_type=None, renderer_context=None):
        try:
            return super().render(data, accepted_media_type, renderer_context)
        except UnicodeEncodeError:
            return _EscapedJSONRenderer().render(data, accepted_media_type, renderer_context)


class _EscapedJSONRenderer(renderers.JSONRenderer):
    ensure_ascii = True
