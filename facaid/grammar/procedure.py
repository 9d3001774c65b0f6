"""Procedures: derivation trees of the FaçAID split grammar, their JSON form and their validation.

A procedure holds the image size and a tree of nodes. Inner nodes split their region along one axis into children
whose sizes are given by size specs; leaves paint their region with one of the 12 CMP labels.

Rules (see docs/grammar.md for pictures):

- ``leaf``: a terminal; ``label`` is one of `facaid.labels.LABELS`.
- ``split``: ``axis`` ``x`` (left to right) or ``y`` (top to bottom); ``sizes[i]`` sizes ``children[i]``.
- ``repeat``: the pattern ``children`` (sized by ``sizes``) is laid out ``count`` times (an integer, or ``"fill"``:
  as many times as the nominal sizes fit), followed by the first ``tail`` pattern items again, so ``[pillar, tile]``
  with ``tail=1`` gives pillar tile pillar tile ... pillar.
- ``mirror``: ``children`` then the same children in reverse order, each copy reflected along the axis; with
  ``center`` the last child is the middle one and is not repeated.

A repeat may list ``exceptions``: copies that differ from the typical one by a delta, each an `Override` of one node
of one copy (its size, or the node itself: a closed blind, a missing sill, a taller first floor). The copy stays a
copy of the repeat, so changing the count adds or removes typical copies.

A size spec is ``[mode, value]``: ``abs`` is a length in pixels, ``rel`` a fraction of the parent's length, ``flt`` a
floating length: floating children share what the others leave, in proportion to their values (their nominal pixel
lengths). When fixed sizes overflow the parent they are scaled down to fit and the floating ones get nothing; when a
node has no floating child its fixed sizes are scaled to fill the parent exactly. Every node may carry a ``role``
(what it stands for: floor, tile, ...); it never changes execution.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from facaid.grammar.checks import (
    MODES,
    TOO_COSTLY,
    check_expansion,
    check_meta,
    check_size,
    is_number,
    least_units,
    least_units_of_json,
)
from facaid.grammar.errors import ProcedureError
from facaid.grammar.limits import (
    MAX_CHILDREN,
    MAX_COUNT,
    MAX_DEPTH,
    MAX_EXCEPTIONS,
    MAX_EXTENT,
    MAX_INSTANCES,
    MAX_LEAVES,
    MAX_META_CHARS,
    MAX_NODES,
)
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.repeats import recount
from facaid.labels import LABEL_ID, LABELS
from facaid.numbers import finite

FORMAT = "facaid-procedure"
FORMAT_VERSION = 1
GRAMMAR_VERSION = "facaid-split-1"

RULES = ("leaf", "split", "repeat", "mirror")
AXES = ("x", "y")
ROLES = (
    "image",  # the whole picture: building and background around it
    "facade",  # one building or wing
    "attic",  # roof storey and main cornice
    "floors",  # a group of upper floors
    "floor",  # one storey
    "ground",  # the ground floor
    "bay",  # a vertical strip of a floor: tiles and pillars
    "tile",  # one window unit: window with its sill, hood, blinds, ornament
    "window",  # the window itself with its blinds or railing
    "entrance",  # a door with its surround
    "shopfront",  # a shop front
    "band",  # a horizontal molding or balcony running across
    "margin",  # wall or background at the edges
)

__all__ = [
    "AXES", "FORMAT", "FORMAT_VERSION", "GRAMMAR_VERSION", "MAX_CHILDREN", "MAX_COUNT", "MAX_DEPTH", "MAX_EXCEPTIONS",
    "MAX_EXTENT", "MAX_INSTANCES", "MAX_LEAVES", "MAX_META_CHARS", "MAX_NODES", "MODES", "RULES", "ROLES",
    "Procedure", "ProcedureError", "parse_procedure", "recount", "validate",
]


@dataclass
class Procedure:
    width: float
    height: float
    root: Node
    meta: dict[str, Any] = field(default_factory=dict)  # free-form provenance (style, seed, ...)

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "format": FORMAT,
            "version": FORMAT_VERSION,
            "grammar": GRAMMAR_VERSION,
            "width": self.width,
            "height": self.height,
            "root": self.root.to_dict(),
        }
        if self.meta:
            out["meta"] = self.meta
        return out

    def to_json(self, indent: int | None = None) -> str:
        separators = (",", ":") if indent is None else (",", ": ")
        return json.dumps(self.to_dict(), indent=indent, separators=separators)

    @classmethod
    def from_dict(cls, obj: Any) -> Procedure:
        return parse_procedure(obj)

    @classmethod
    def from_json(cls, text: str | bytes) -> Procedure:
        try:
            obj = json.loads(text)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise ProcedureError("(document)", f"malformed JSON: {exc}") from None
        return parse_procedure(obj, sent=True)

    def nodes(self) -> Iterator[tuple[str, Node]]:
        return self.root.walk()

    def parameters(self) -> list[float]:
        """Every sizing parameter, in depth-first node order and size order within a node."""
        return [s.value for _, node in self.root.walk() for s in node.own_sizes()]

    def with_parameters(self, values: list[float]) -> Procedure:
        """A copy with the sizing parameters replaced (same order as `parameters`), validated."""
        values = [float(v) for v in values]
        expected = sum(len(node.own_sizes()) for _, node in self.root.walk())
        if len(values) != expected:
            raise ValueError(f"expected {expected} parameters, got {len(values)}")
        it = iter(values)

        def copy(node: Node) -> Node:
            sizes = [Size(s.mode, next(it)) for s in node.sizes]
            sized = [o._replace(size=Size(o.size.mode, next(it))) if o.size is not None else o
                     for o in node.exceptions]  # in `own_sizes` order: the node's, then its exceptions'
            children = [copy(c) for c in node.children]
            exceptions = [o._replace(node=copy(o.node)) if o.node is not None else o for o in sized]
            return Node(node.rule, node.label, node.axis, sizes, children, node.count, node.tail, node.center,
                        node.role, exceptions)

        out = Procedure(self.width, self.height, copy(self.root), dict(self.meta))
        validate(out)
        return out


# --- parsing and validation ---------------------------------------------------------------------------------

def _parse_node(obj: Any, path: str, depth: int, counter: list) -> Node:
    if depth > MAX_DEPTH:
        raise ProcedureError(path, f"tree too deep (more than {MAX_DEPTH} levels)")
    counter[0] += 1
    if counter[0] > MAX_NODES:
        raise ProcedureError(path, f"too many nodes (more than {MAX_NODES})")
    if not isinstance(obj, dict):
        raise ProcedureError(path, f"a node must be a JSON object, got {type(obj).__name__}")
    rule = obj.get("rule")
    if rule not in RULES:
        raise ProcedureError(path, f"unknown rule {rule!r}; expected one of {', '.join(RULES)}")
    role = obj.get("role")
    if role is not None and role not in ROLES:
        raise ProcedureError(path, f"unknown role {role!r}; expected one of {', '.join(ROLES)}")
    allowed = {"rule", "role", "label"} if rule == "leaf" else {"rule", "role", "axis", "sizes", "children"}
    if rule == "repeat":
        allowed |= {"count", "tail", "exceptions"}
    if rule == "mirror":
        allowed |= {"center"}
    extra = sorted(set(obj) - allowed)
    if extra:
        raise ProcedureError(path, f"unexpected key(s) for a {rule} node: {', '.join(extra)}")
    if rule == "leaf":
        label = obj.get("label")
        if label not in LABEL_ID:
            raise ProcedureError(path, f"leaf label {label!r} is not one of {', '.join(LABELS)}")
        return Node("leaf", label=label, role=role)

    axis = obj.get("axis")
    if axis not in AXES:
        raise ProcedureError(path, f"axis must be 'x' or 'y', got {axis!r}")
    sizes_in, children_in = obj.get("sizes"), obj.get("children")
    if not isinstance(sizes_in, list) or not isinstance(children_in, list):
        raise ProcedureError(path, f"a {rule} node needs lists 'sizes' and 'children'")
    if len(sizes_in) != len(children_in):
        raise ProcedureError(path, f"wrong arity: {len(sizes_in)} sizes for {len(children_in)} children")
    if not 1 <= len(children_in) <= MAX_CHILDREN:
        raise ProcedureError(path, f"a {rule} node needs 1 to {MAX_CHILDREN} children, got {len(children_in)}")
    sizes = []
    for i, s in enumerate(sizes_in):
        if not (isinstance(s, list) and len(s) == 2):
            raise ProcedureError(path, f"sizes[{i}] must be a [mode, value] pair, got {s!r}")
        check_size(path, i, s[0], s[1])
        sizes.append(Size(s[0], s[1]))
    node = Node(rule, axis=axis, sizes=sizes, role=role)
    if rule == "repeat":
        count, tail = obj.get("count"), obj.get("tail", 0)
        if count != "fill" and not (isinstance(count, int) and not isinstance(count, bool)):
            raise ProcedureError(path, f"count must be a positive integer or 'fill', got {count!r}")
        if count != "fill" and not 1 <= count <= MAX_COUNT:
            raise ProcedureError(path, f"count must be between 1 and {MAX_COUNT}, got {count!r}")
        if not (isinstance(tail, int) and not isinstance(tail, bool)) or not 0 <= tail <= len(sizes) - 1:
            raise ProcedureError(path, f"tail must be an integer from 0 to {len(sizes) - 1}, got {tail!r}")
        if count == "fill" and not any(s.value > 0 for s in sizes if s.mode != "rel"):
            raise ProcedureError(path, "a fill repeat needs a positive abs or flt size to count with")
        node.count, node.tail = count, tail
    if rule == "mirror":
        center = obj.get("center", False)
        if not isinstance(center, bool):
            raise ProcedureError(path, f"center must be true or false, got {center!r}")
        node.center = center
    node.children = [_parse_node(c, f"{path}/{i}", depth + 1, counter) for i, c in enumerate(children_in)]
    if rule == "repeat" and "exceptions" in obj:
        node.exceptions = _parse_exceptions(obj["exceptions"], node, path, depth, counter)
    counter[1][id(node)] = least_units(node, counter[1])  # the root's is a bound of the tree's (`parse_procedure`)
    return node


_EXCEPTION_KEYS = frozenset(("copy", "path", "size", "node"))


def _parse_exceptions(items: Any, node: Node, path: str, depth: int, counter: list) -> list[Override]:
    if not isinstance(items, list):
        raise ProcedureError(path, f"exceptions must be a list, got {type(items).__name__}")
    if len(items) > MAX_EXCEPTIONS:
        raise ProcedureError(path, f"too many exceptions ({len(items)}; at most {MAX_EXCEPTIONS})")
    out: list[Override] = []
    seen: set[tuple[int, tuple[int, ...]]] = set()
    last = MAX_COUNT if node.count == "fill" else node.count
    for e, item in enumerate(items):
        where = f"exceptions[{e}]"
        counter[0] += 1  # an exception counts as a node: what a tree may hold stays bounded
        if counter[0] > MAX_NODES:
            raise ProcedureError(path, f"too many nodes and exceptions (more than {MAX_NODES})")
        if not isinstance(item, dict):
            raise ProcedureError(path, f"{where} must be an object, got {type(item).__name__}")
        if not item.keys() <= _EXCEPTION_KEYS:
            extra = sorted(map(str, item.keys() - _EXCEPTION_KEYS))
            raise ProcedureError(path, f"{where} has unexpected key(s): {', '.join(extra)}")
        copy, steps = item.get("copy"), item.get("path")
        if not (isinstance(copy, int) and not isinstance(copy, bool)) or not 0 <= copy <= last:
            raise ProcedureError(path, f"{where}.copy must be a copy of the repeat, 0 to {last}, got {copy!r}")
        if (not isinstance(steps, list) or not 1 <= len(steps) <= MAX_DEPTH
                or not all(type(i) is int for i in steps) or min(steps) < 0):
            raise ProcedureError(path, f"{where}.path must be a list of 1 to {MAX_DEPTH} indices, got {steps!r}")
        if steps[0] >= len(node.children):
            raise ProcedureError(path, f"{where}.path[0] must be a pattern item, 0 to {len(node.children) - 1}, "
                                       f"got {steps[0]}")
        if copy == node.count and steps[0] >= node.tail:
            raise ProcedureError(path, f"{where}.copy {copy} is the tail, which lays out "
                                       + (f"items 0 to {node.tail - 1}" if node.tail else "nothing"))
        key = (copy, tuple(steps))
        if key in seen:
            raise ProcedureError(path, f"{where} names copy {copy} at path {steps} twice")
        seen.add(key)
        size = None
        if "size" in item:
            s = item["size"]
            if not (isinstance(s, list) and len(s) == 2):
                raise ProcedureError(path, f"{where}.size must be a [mode, value] pair, got {s!r}")
            check_size(path, e, s[0], s[1], what=f"{where}.size")
            size = Size(s[0], s[1])
        sub = None
        if "node" in item:
            if depth + len(steps) > MAX_DEPTH:
                raise ProcedureError(path, f"{where}: tree too deep (more than {MAX_DEPTH} levels)")
            sub = _parse_node(item["node"], f"{path}/!{e}", depth + len(steps), counter)
        if size is None and sub is None:
            raise ProcedureError(path, f"{where} changes nothing: give it a size, a node or both")
        out.append(Override(copy, key[1], size, sub))
    return out


def parse_procedure(obj: Any, sent: bool = False) -> Procedure:
    """Validate a decoded procedure JSON object and return a `Procedure`; raise `ProcedureError`. ``sent``: it comes
    from a person, who may have crafted it, so a tree sure to cost too much (`least_units_of_json`) is refused before
    any of it is read into nodes."""
    if sent and isinstance(obj, dict) and (least_units_of_json(obj.get("root")) or 0) > MAX_INSTANCES:
        raise ProcedureError("root", TOO_COSTLY)
    if not isinstance(obj, dict):
        raise ProcedureError("(document)", f"a procedure must be a JSON object, got {type(obj).__name__}")
    if obj.get("format") != FORMAT:
        raise ProcedureError("(document)", f"format must be {FORMAT!r}, got {obj.get('format')!r}")
    if obj.get("version") != FORMAT_VERSION:
        raise ProcedureError("(document)", f"unsupported version {obj.get('version')!r}; this is {FORMAT_VERSION}")
    if obj.get("grammar") != GRAMMAR_VERSION:
        raise ProcedureError("(document)",
                             f"made for grammar {obj.get('grammar')!r}; this build runs {GRAMMAR_VERSION!r}")
    for key in ("width", "height"):
        v = obj.get(key)
        if not is_number(v) or not finite(v) or not 1 <= v <= MAX_EXTENT:
            raise ProcedureError("(document)", f"{key} must be a number from 1 to {MAX_EXTENT:g}, got {v!r}")
    meta = obj.get("meta", {})
    if not isinstance(meta, dict):
        raise ProcedureError("(document)", f"meta must be an object, got {type(meta).__name__}")
    check_meta(meta)
    extra = sorted(set(obj) - {"format", "version", "grammar", "width", "height", "root", "meta"})
    if extra:
        raise ProcedureError("(document)", f"unexpected key(s): {', '.join(extra)}")
    if "root" not in obj:
        raise ProcedureError("(document)", "missing 'root'")
    counter = [0, {}]  # nodes and exceptions read; each node's `least_units`
    root = _parse_node(obj["root"], "root", 0, counter)
    if counter[1].get(id(root), 1) > MAX_INSTANCES:  # the root is laid out once (a node below may never be)
        raise ProcedureError("root", TOO_COSTLY)
    proc = Procedure(obj["width"], obj["height"], root, meta)
    check_expansion(proc)
    return proc


def validate(proc: Procedure) -> None:
    """Validate a procedure built in code (the generator, variations) exactly as JSON input is validated."""
    parse_procedure(proc.to_dict())
