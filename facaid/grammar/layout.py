"""How a node lays out its children along its axis: the grammar's sizing rules, in plain Python floats.

Shared by the executor (`facaid.grammar.execute`) and by validation (`count_leaves`, which bounds what a
procedure expands to without executing it). Nodes are `facaid.grammar.procedure.Node` objects, sizes `Size`s
(``mode``, ``value``); this module reads their attributes and imports neither, so that the procedure module can
use it.
"""

from __future__ import annotations

import contextlib
from typing import NamedTuple

from facaid.grammar.limits import MAX_COUNT, MAX_INSTANCES, MAX_LEAVES


def nominal(size, length: float) -> float:
    """The length a size asks for before floating sizes share the remainder."""
    return size.value * length if size.mode == "rel" else size.value


def repeat_count(node, length: float) -> int:
    """How many times a repeat node lays out its pattern in a region of the given length."""
    if node.count != "fill":
        return node.count
    pattern = sum(nominal(s, length) for s in node.sizes)
    tail = sum(nominal(s, length) for s in node.sizes[: node.tail])
    return max(1, min(MAX_COUNT, int((length - tail) / pattern + 0.5)))


def expand(node, length: float) -> tuple[list, list, list[bool]]:
    """The plain split a repeat or mirror node stands for: (sizes, children, reflected) along its axis."""
    if node.rule == "split":
        return node.sizes, node.children, [False] * len(node.children)
    if node.rule == "repeat":
        n = repeat_count(node, length)
        t = node.tail
        return (node.sizes * n + node.sizes[:t], node.children * n + node.children[:t],
                [False] * (len(node.children) * n + t))
    # mirror
    back = list(range(len(node.children) - (2 if node.center else 1), -1, -1))
    return (node.sizes + [node.sizes[i] for i in back], node.children + [node.children[i] for i in back],
            [False] * len(node.children) + [True] * len(back))


def expand_over(node, length: float, pending: list | None) -> tuple[list, list, list[bool], list | None, list | None]:
    """`expand` with the exceptions applied: those of ``node`` (a repeat's `Override`s) and ``pending``, the
    overrides of repeats above it that reach into it, each ``(steps, override, owner)`` with ``steps`` the indices
    of the expanded children still to follow from ``node`` down. Returns (sizes, children, reflected, below,
    sources): ``below[i]`` the pending overrides of child ``i`` (None when it has none) and ``sources[i]`` the
    ``(owner, override)`` whose size child ``i`` takes (None for its own); both None when nothing applies here.
    An override from further up wins over one from nearer (a cell's exception over its column's)."""
    sizes, children, reflected = expand(node, length)
    exceptions = node.exceptions if node.rule == "repeat" else ()
    if not exceptions and not pending:
        return sizes, children, reflected, None, None
    entries = []
    if exceptions:
        k, n = len(node.children), repeat_count(node, length)
        for o in exceptions:
            if o.copy < n or (o.copy == n and o.path[0] < node.tail):
                entries.append(((o.copy * k + o.path[0], *o.path[1:]), o, node))
    if pending:
        entries.extend(pending)
    if not entries:
        return sizes, children, reflected, None, None
    sizes, children = list(sizes), list(children)
    below: list = [None] * len(children)
    sources: list = [None] * len(children)
    for steps, o, owner in entries:
        i = steps[0]
        if i >= len(children):
            continue  # a copy this length does not lay out
        if len(steps) > 1:
            below[i] = (below[i] or []) + [(steps[1:], o, owner)]
            continue
        if o.size is not None:
            sizes[i] = o.size
            sources[i] = (owner, o)
        if o.node is not None:
            children[i] = o.node
    return sizes, children, reflected, below, sources


def layout(sizes: list, length: float) -> list[float]:
    """Lengths of the children of a split of the given length (see the rules in `procedure`). A length below 0
    (a last child laid out where rounding put its start a hair past its end) counts as 0."""
    length = max(length, 0.0)
    fixed = 0.0
    weights = 0.0
    for s in sizes:
        if s.mode == "flt":
            weights += s.value
        else:
            fixed += s.value * length if s.mode == "rel" else s.value
    if weights > 0:
        scale = length / fixed if fixed > length else 1.0
        share = max(length - fixed, 0.0) / weights
    else:
        scale = length / fixed if fixed > 0 else 0.0
        share = 0.0
    out = []
    for s in sizes:
        if s.mode == "flt":
            out.append(s.value * share)
        elif s.mode == "rel":
            out.append(s.value * length * scale)
        else:
            out.append(s.value * scale)
    return out


class _TooMany(Exception):
    pass


class Expansion(NamedTuple):
    """What laying a tree out costs: the rectangles it draws and the node instances it visits (every node once
    per copy of it, splits and repeats included; a leaf under a chain of one-child splits costs the chain)."""

    leaves: int
    instances: int


def count_expansion(root, width: float, height: float, max_leaves: int = MAX_LEAVES,
                    max_instances: int = MAX_INSTANCES) -> Expansion:
    """What a tree expands to in a ``width`` x ``height`` image (`Expansion`), counting stopped as soon as either
    figure is past its limit (then that figure is its limit + 1). Counted from the regions' extents without laying
    out positions: the copies of a repeat (same node, same extent) are counted once, so a tree of a million leaves
    costs what its distinct nodes do. (The executor places copies at float offsets, so a copy's extent may differ
    from this one's by a rounding error, which could move a ``"fill"`` count only if its quotient sat exactly on a
    half: a bound, not a layout.)"""
    memo: dict[tuple[int, float, float], tuple[int, int]] = {}
    leaves = instances = 0

    def add(n_leaves: int, n_instances: int) -> None:
        nonlocal leaves, instances
        leaves += n_leaves
        instances += n_instances
        if leaves > max_leaves or instances > max_instances:
            raise _TooMany

    def count(node, w: float, h: float, pending: list | None = None) -> tuple[int, int]:
        if node.rule == "leaf":
            add(1, 1)
            return 1, 1
        key = (id(node), w, h)
        known = memo.get(key) if pending is None else None  # overrides reaching in make an instance its own
        if known is not None:
            add(*known)
            return known
        add(0, 1)
        along_x = node.axis == "x"
        length = w if along_x else h
        sizes, children, _, below, _ = expand_over(node, length, pending)
        n_leaves, n_instances = 0, 1
        for i, (child, extent) in enumerate(zip(children, layout(sizes, length), strict=True)):
            sub = below[i] if below is not None else None
            a, b = count(child, extent, h, sub) if along_x else count(child, w, extent, sub)
            n_leaves, n_instances = n_leaves + a, n_instances + b
        if pending is None:
            memo[key] = (n_leaves, n_instances)
        return n_leaves, n_instances

    with contextlib.suppress(_TooMany):
        count(root, float(width), float(height))
    return Expansion(min(leaves, max_leaves + 1), min(instances, max_instances + 1))


def count_leaves(root, width: float, height: float, limit: int = MAX_LEAVES) -> int:
    """How many rectangles a tree expands to in a ``width`` x ``height`` image, or ``limit + 1`` as soon as it is
    more than ``limit`` (`count_expansion`)."""
    return count_expansion(root, width, height, limit, 1 << 62).leaves
