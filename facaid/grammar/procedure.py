"""Procedures: derivation trees of the FaçAID split grammar, their JSON form and their validation.

A procedure holds the image size and a tree of nodes. Inner nodes split their region along one axis into
children whose sizes are given by size specs; leaves paint their region with one of the 12 CMP labels.

Rules (see docs/grammar.md for pictures):

- ``leaf``: a terminal; ``label`` is one of `facaid.labels.LABELS`.
- ``split``: ``axis`` ``x`` (left to right) or ``y`` (top to bottom); ``sizes[i]`` sizes ``children[i]``.
- ``repeat``: the pattern ``children`` (sized by ``sizes``) is laid out ``count`` times (an integer, or
  ``"fill"``: as many times as the nominal sizes fit), followed by the first ``tail`` pattern items again,
  so ``[pillar, tile]`` with ``tail=1`` gives pillar tile pillar tile ... pillar.
- ``mirror``: ``children`` then the same children in reverse order, each copy reflected along the axis;
  with ``center`` the last child is the middle one and is not repeated.

A size spec is ``[mode, value]``: ``abs`` is a length in pixels, ``rel`` a fraction of the parent's length,
``flt`` a floating length: floating children share what the others leave, in proportion to their values
(their nominal pixel lengths). When fixed sizes overflow the parent they are scaled down to fit and the
floating ones get nothing; when a node has no floating child its fixed sizes are scaled to fill the parent
exactly. Every node may carry a ``role`` (what it stands for: floor, tile, ...); it never changes execution.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, NamedTuple

from facaid.grammar.layout import count_leaves
from facaid.grammar.limits import (
    MAX_CHILDREN,
    MAX_COUNT,
    MAX_DEPTH,
    MAX_EXTENT,
    MAX_LEAVES,
    MAX_META_CHARS,
    MAX_NODES,
)
from facaid.labels import LABEL_ID, LABELS
from facaid.numbers import finite

FORMAT = "facaid-procedure"
FORMAT_VERSION = 1
GRAMMAR_VERSION = "facaid-split-1"

RULES = ("leaf", "split", "repeat", "mirror")
AXES = ("x", "y")
MODES = ("abs", "rel", "flt")
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
    "AXES", "FORMAT", "FORMAT_VERSION", "GRAMMAR_VERSION", "MAX_CHILDREN", "MAX_COUNT", "MAX_DEPTH", "MAX_EXTENT",
    "MAX_LEAVES", "MAX_META_CHARS", "MAX_NODES", "MODES", "RULES", "ROLES", "Node", "Procedure", "ProcedureError",
    "Size", "parse_procedure", "validate",
]


class ProcedureError(ValueError):
    """An invalid procedure; the message names the node by its path, e.g. ``root/2/0``."""

    def __init__(self, path: str, message: str):
        super().__init__(f"node {path}: {message}")
        self.path = path


class Size(NamedTuple):
    """A child's size along its parent's axis. A named tuple, not a dataclass: the generator makes some 170 a
    facade, and a tuple is made in two thirds of a frozen dataclass's time."""

    mode: str  # one of MODES
    value: float


@dataclass(slots=True)
class Node:
    rule: str
    label: str | None = None  # leaf only
    axis: str | None = None  # inner nodes
    sizes: list[Size] = field(default_factory=list)
    children: list[Node] = field(default_factory=list)
    count: int | str | None = None  # repeat only: int or "fill"
    tail: int = 0  # repeat only
    center: bool = False  # mirror only
    role: str | None = None

    # --- construction helpers -------------------------------------------------------------------------
    @staticmethod
    def leaf(label: str, role: str | None = None) -> Node:
        return Node("leaf", label=label, role=role)

    @staticmethod
    def split(axis: str, items: list[tuple[Size, Node]], role: str | None = None) -> Node:
        return Node("split", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items], role=role)

    @staticmethod
    def repeat(axis: str, count: int | str, items: list[tuple[Size, Node]], tail: int = 0,
               role: str | None = None) -> Node:
        return Node("repeat", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items],
                    count=count, tail=tail, role=role)

    @staticmethod
    def mirror(axis: str, items: list[tuple[Size, Node]], center: bool = False, role: str | None = None) -> Node:
        return Node("mirror", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items],
                    center=center, role=role)

    def copy(self) -> Node:
        """A deep copy (sizes are immutable and shared)."""
        return Node(self.rule, self.label, self.axis, list(self.sizes), [c.copy() for c in self.children],
                    self.count, self.tail, self.center, self.role)

    @property
    def is_leaf(self) -> bool:
        return self.rule == "leaf"

    def walk(self, path: str = "root") -> Iterator[tuple[str, Node]]:
        """Depth-first pre-order over (path, node)."""
        yield path, self
        for i, child in enumerate(self.children):
            yield from child.walk(f"{path}/{i}")

    def bfs(self) -> Iterator[Node]:
        queue = [self]
        i = 0
        while i < len(queue):
            node = queue[i]
            i += 1
            yield node
            queue.extend(node.children)

    # --- JSON -----------------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"rule": self.rule}
        if self.role is not None:
            out["role"] = self.role
        if self.rule == "leaf":
            out["label"] = self.label
            return out
        out["axis"] = self.axis
        if self.rule == "repeat":
            out["count"] = self.count
            out["tail"] = self.tail
        if self.rule == "mirror":
            out["center"] = self.center
        out["sizes"] = [[s.mode, s.value] for s in self.sizes]
        out["children"] = [c.to_dict() for c in self.children]
        return out


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
        return parse_procedure(obj)

    def nodes(self) -> Iterator[tuple[str, Node]]:
        return self.root.walk()

    def parameters(self) -> list[float]:
        """Every sizing parameter, in depth-first node order and size order within a node."""
        return [s.value for _, node in self.root.walk() for s in node.sizes]

    def with_parameters(self, values: list[float]) -> Procedure:
        """A copy with the sizing parameters replaced (same order as `parameters`), validated."""
        values = [float(v) for v in values]
        expected = sum(len(node.sizes) for _, node in self.root.walk())
        if len(values) != expected:
            raise ValueError(f"expected {expected} parameters, got {len(values)}")
        it = iter(values)

        def copy(node: Node) -> Node:
            sizes = [Size(s.mode, next(it)) for s in node.sizes]
            return Node(node.rule, node.label, node.axis, sizes, [copy(c) for c in node.children],
                        node.count, node.tail, node.center, node.role)

        out = Procedure(self.width, self.height, copy(self.root), dict(self.meta))
        validate(out)
        return out


# --- parsing and validation ---------------------------------------------------------------------------------

def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


def _check_size(path: str, i: int, mode: str, value: Any) -> None:
    if mode not in MODES:
        raise ProcedureError(path, f"sizes[{i}] has unknown mode {mode!r}; expected one of {', '.join(MODES)}")
    if not _is_number(value):
        raise ProcedureError(path, f"sizes[{i}] value must be a number, got {value!r}")
    if not finite(value):
        raise ProcedureError(path, f"sizes[{i}] value must be finite, got {value!r}")
    if value < 0:
        raise ProcedureError(path, f"sizes[{i}] is negative ({value!r})")
    if mode == "rel" and value > 1:
        raise ProcedureError(path, f"sizes[{i}] is a relative size above 1 ({value!r})")
    if value > MAX_EXTENT:
        raise ProcedureError(path, f"sizes[{i}] is too large ({value!r} > {MAX_EXTENT:g})")


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


def _check_meta(meta: dict) -> None:
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


def _parse_node(obj: Any, path: str, depth: int, counter: list[int]) -> Node:
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
        allowed |= {"count", "tail"}
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
        _check_size(path, i, s[0], s[1])
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
    return node


def parse_procedure(obj: Any) -> Procedure:
    """Validate a decoded procedure JSON object and return a `Procedure`; raise `ProcedureError`."""
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
        if not _is_number(v) or not finite(v) or not 1 <= v <= MAX_EXTENT:
            raise ProcedureError("(document)", f"{key} must be a number from 1 to {MAX_EXTENT:g}, got {v!r}")
    meta = obj.get("meta", {})
    if not isinstance(meta, dict):
        raise ProcedureError("(document)", f"meta must be an object, got {type(meta).__name__}")
    _check_meta(meta)
    extra = sorted(set(obj) - {"format", "version", "grammar", "width", "height", "root", "meta"})
    if extra:
        raise ProcedureError("(document)", f"unexpected key(s): {', '.join(extra)}")
    if "root" not in obj:
        raise ProcedureError("(document)", "missing 'root'")
    root = _parse_node(obj["root"], "root", 0, [0])
    proc = Procedure(obj["width"], obj["height"], root, meta)
    _check_expansion(proc)
    return proc


def validate(proc: Procedure) -> None:
    """Validate a procedure built in code (the generator, variations) exactly as JSON input is validated."""
    parse_procedure(proc.to_dict())


def _check_expansion(proc: Procedure) -> None:
    if count_leaves(proc.root, proc.width, proc.height) > MAX_LEAVES:
        raise ProcedureError("root", f"expands to more than {MAX_LEAVES} rectangles")
