"""The checks of a procedure that need no parsing: a size spec, the free-form notes (``meta``) and what executing
the tree would cost."""

from __future__ import annotations

import json
from collections.abc import Iterator
from typing import TYPE_CHECKING, Any

from facaid.grammar.budget import charge
from facaid.grammar.errors import ProcedureError
from facaid.grammar.layout import count_expansion
from facaid.grammar.limits import MAX_COUNT, MAX_DEPTH, MAX_EXTENT, MAX_INSTANCES, MAX_LEAVES, MAX_META_CHARS
from facaid.grammar.repeats import path_problem
from facaid.numbers import finite

if TYPE_CHECKING:
    from facaid.grammar.nodes import Node
    from facaid.grammar.procedure import Procedure

MODES = ("abs", "rel", "flt")
TOO_COSTLY = (f"expands to more than {MAX_INSTANCES} node instances (each node once per copy of it, repeats and splits "
              "included, and each exception once at every level its path runs through): the limit of what one tree "
              "may cost")


def is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def check_size(path: str, i: int, mode: str, value: Any, what: str | None = None) -> None:
    kind = type(value)
    if (kind is float or kind is int) and mode in MODES and 0 <= value <= (1 if mode == "rel" else MAX_EXTENT):
        return  # most sizes: told fine before any message is made (NaN and infinities fail the range)
    what = what or f"sizes[{i}]"
    if mode not in MODES:
        raise ProcedureError(path, f"{what} has unknown mode {mode!r}; expected one of {', '.join(MODES)}")
    if not is_number(value):
        raise ProcedureError(path, f"{what} value must be a number, got {value!r}")
    if not finite(value):
        raise ProcedureError(path, f"{what} value must be finite, got {value!r}")
    if value < 0:
        raise ProcedureError(path, f"{what} is negative ({value!r})")
    if mode == "rel" and value > 1:
        raise ProcedureError(path, f"{what} is a relative size above 1 ({value!r})")
    if value > MAX_EXTENT:
        raise ProcedureError(path, f"{what} is too large ({value!r} > {MAX_EXTENT:g})")


def _texts(value: Any) -> Iterator[str]:
    """Every key and string in a JSON value."""
    stack = [value]
    while stack:
        value = stack.pop()
        if isinstance(value, str):
            yield value
        elif isinstance(value, dict):
            yield from (k for k in value if isinstance(k, str))
            stack.extend(value.values())
        elif isinstance(value, list):
            stack.extend(value)


def check_meta(meta: dict) -> None:
    """Free-form notes, but plain JSON that every database stores and every encoder writes back: finite numbers,
    text without NUL or unpaired surrogates, at most `MAX_META_CHARS` written out."""
    try:
        text = json.dumps(meta, ensure_ascii=False, allow_nan=False, separators=(",", ":"))
        text.encode("utf-8")
    except (ValueError, TypeError, UnicodeEncodeError, RecursionError) as exc:
        raise ProcedureError("(document)", f"meta must be plain JSON text and finite numbers ({exc})") from None
    if any("\x00" in text for text in _texts(meta)):
        raise ProcedureError("(document)", "meta must not hold NUL characters")
    if len(text) > MAX_META_CHARS:
        raise ProcedureError("(document)", f"meta is too long ({len(text)} characters written out; at most "
                                           f"{MAX_META_CHARS})")


def least_units(node: Node, bounds: dict[int, int]) -> int:
    """A lower bound of what one instance of ``node`` costs (`count_expansion`'s units), from the bounds of its
    children (``bounds``, by ``id``) alone, whatever its size: each ``"fill"`` repeat lays out at least one copy,
    every copy of a repeat that an exception replaces a node of may cost nothing, and each instance of a repeat
    handles all its exceptions. Computed bottom-up as a tree is read: the root's (laid out once, where a node below
    may never be) refuses a tree sure to cost too much before its exceptions are counted along their paths."""
    if node.rule == "leaf":
        return 1
    kids = [1 if c.rule == "leaf" else bounds[id(c)] for c in node.children]
    touched = {o.copy for o in node.exceptions if o.node is not None}  # a copy with a node replaced: maybe nothing
    return _least(node.rule, kids, node.count, node.tail, node.center, len(node.exceptions), touched)


def _least(rule: str, kids: list[int], count, tail: int, center: bool, exceptions: int, touched: set) -> int:
    if rule == "split":
        return 1 + sum(kids)
    if rule == "mirror":
        return 1 + 2 * sum(kids) - (kids[-1] if center else 0)
    copies = 1 if count == "fill" else count
    tail_units = 0 if count == "fill" and touched or count in touched else sum(kids[:tail])
    return 1 + exceptions + sum(kids) * sum(1 for c in range(copies) if c not in touched) + tail_units


def least_units_of_json(obj: Any, depth: int = 0) -> int | None:
    """`least_units` of a procedure's root as JSON, before any of it is read into nodes (a node's fields only, and of
    each exception whether it has a node): None wherever it is not plainly a node of the grammar, which reading it
    then names. For what a person sends, so that a tree sure to cost too much is refused in the time its JSON took
    to decode (the 8 x 1,010-exception tree: 1 ms here, 12 ms to read)."""
    if depth > MAX_DEPTH or not isinstance(obj, dict):
        return None
    rule = obj.get("rule")
    if rule == "leaf":
        return 1
    children = obj.get("children")
    if rule not in ("split", "repeat", "mirror") or not isinstance(children, list) or not children:
        return None
    kids = []
    for child in children:
        k = least_units_of_json(child, depth + 1)
        if k is None:
            return None
        kids.append(k)
    count, tail, exceptions = obj.get("count"), obj.get("tail", 0), obj.get("exceptions", [])
    if rule == "repeat":
        if not (count == "fill" or type(count) is int and 1 <= count <= MAX_COUNT) or type(tail) is not int \
                or not 0 <= tail < len(kids) or not isinstance(exceptions, list):
            return None
        touched = [e.get("copy") for e in exceptions if isinstance(e, dict) and "node" in e]
        if not all(type(c) is int for c in touched):
            return None  # a copy that is not one: reading it says so
        return _least(rule, kids, count, tail, False, len(exceptions), set(touched))
    return _least(rule, kids, None, 0, obj.get("center") is True, 0, set())


def check_expansion(proc: Procedure) -> None:
    """The cost model: what executing the tree would cost, bounded before any of it is paid (`count_expansion`,
    from the distinct nodes only, so a crafted tree is refused in microseconds), and charged to the work budget of
    the request it is part of (`facaid.grammar.budget`). Each leaf is an instance, so `MAX_LEAVES` holds too. An
    exception must reach a node that is laid out, in some copy: one that names a copy or a child that the tree
    never lays out (past what a ``"fill"`` repeat lays out at its length, say) would be carried for nothing."""
    applied: set[int] = set()
    cost = count_expansion(proc.root, proc.width, proc.height, applied=applied)
    if cost.instances > MAX_INSTANCES or cost.leaves > MAX_LEAVES:
        raise ProcedureError("root", TOO_COSTLY)
    for path, node in proc.root.walk():
        for e, o in enumerate(node.exceptions):
            if id(o) not in applied:  # the paths are walked only here: a tree refused for its cost never is
                problem = path_problem(node, o) or (f"names copy {o.copy} at path {list(o.path)}, which is never "
                                                    "laid out at this size")
                raise ProcedureError(path, f"exceptions[{e}].{problem}")
    charge(cost.instances)
