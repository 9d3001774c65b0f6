"""How a node lays out its children along its axis: the grammar's sizing rules, in plain Python floats.

Shared by the executor (`facaid.grammar.execute`) and by validation (`count_leaves`, which bounds what a
procedure expands to without executing it). Nodes are `facaid.grammar.procedure.Node` objects, sizes `Size`s
(``mode``, ``value``); this module reads their attributes and imports neither, so that the procedure module can
use it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any, NamedTuple

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


def laid_out(node, n: int) -> Iterator[tuple[tuple[int, ...], Any]]:
    """The exceptions of the repeat ``node`` that apply when it lays out ``n`` copies (the tail's items too), each
    with its path's steps from the repeat down, the first the expanded child it names (`expand`'s order)."""
    k = len(node.children)
    for o in node.exceptions:
        if o.copy < n or (o.copy == n and o.path[0] < node.tail):
            yield (o.copy * k + o.path[0], *o.path[1:]), o


def expand_over(node, length: float, pending: list | None,
                applied: set[int] | None = None) -> tuple[list, list, list[bool], list | None, list | None]:
    """`expand` with the exceptions applied: those of ``node`` (a repeat's `Override`s) and ``pending``, the
    overrides of repeats above it that reach into it, each ``(steps, override, owner)`` with ``steps`` the indices
    of the expanded children still to follow from ``node`` down. Returns (sizes, children, reflected, below,
    sources): ``below[i]`` the pending overrides of child ``i`` (None when it has none) and ``sources[i]`` the
    ``(owner, override)`` whose size child ``i`` takes (None for its own); both None when nothing applies here.
    An override from further up wins over one from nearer (a cell's exception over its column's). The work is
    linear in the overrides handled (`count_expansion` charges each at every level it is carried through);
    ``applied``, where given, collects the ``id`` of each override that reaches its node here."""
    sizes, children, reflected = expand(node, length)
    exceptions = node.exceptions if node.rule == "repeat" else ()
    if not exceptions and not pending:
        return sizes, children, reflected, None, None
    entries = [(steps, o, node) for steps, o in laid_out(node, repeat_count(node, length))] if exceptions else []
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
            if below[i] is None:
                below[i] = []
            below[i].append((steps[1:], o, owner))
            continue
        if applied is not None:
            applied.add(id(o))
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


class _Paths:
    """Exception paths gathered into a trie, for counting: at a node instance, ``ends[i]`` the exceptions whose
    path ends at its expanded child ``i`` and ``kids[i]`` the paths that go on into it; ``total`` the exceptions
    at or below, which is what carrying them here costs (`Expansion`). Paths that share a prefix share its trie
    nodes, so the count walks a prefix once, whatever the number of exceptions it charges for."""

    __slots__ = ("ends", "kids", "total")

    def __init__(self) -> None:
        self.ends: dict[int, list] = {}
        self.kids: dict[int, _Paths] = {}
        self.total = 0

    @staticmethod
    def of(node, n: int) -> _Paths | None:
        """The exceptions of the repeat ``node`` that apply when it lays out ``n`` copies, each path's first step
        the expanded child it names (`expand_over`'s order); None when none does. Built from the paths in sorted
        order, each sharing its prefix with the one before (compared by slices, in C), so that the work is the
        trie's nodes, not the paths' steps."""
        keyed = sorted((steps, e, o) for e, (steps, o) in enumerate(laid_out(node, n)))  # e: no tie reaches o
        if not keyed:
            return None
        root = _Paths()
        made = [(root, None)]  # every trie node with its parent, parents first
        stack, before = [root], ()
        for steps, _, o in keyed:
            inner = steps[:-1]
            shared = _common(before, inner)
            del stack[shared + 1:]
            for s in inner[shared:]:
                t = _Paths()
                stack[-1].kids[s] = t
                made.append((t, stack[-1]))
                stack.append(t)
            stack[-1].ends.setdefault(steps[-1], []).append(o)
            before = inner
        for t, parent in reversed(made):
            t.total += sum(map(len, t.ends.values()))
            if parent is not None:
                parent.total += t.total
        return root


def _common(a: tuple, b: tuple) -> int:
    """The length of the longest common prefix of two tuples, by halving (each comparison a slice, in C)."""
    lo, hi = 0, min(len(a), len(b))
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if a[:mid] == b[:mid]:
            lo = mid
        else:
            hi = mid - 1
    return lo


class Expansion(NamedTuple):
    """What laying a tree out costs: the rectangles it draws and the units of work it takes. A unit is a node
    instance (every node once per copy of it, splits and repeats included; a leaf under a chain of one-child
    splits costs the chain), and, at each instance, each exception the walk handles there: each of a repeat's own,
    and each one of a repeat above whose path runs through the instance on its way down. Every walk of a tree (the
    executors, the named parameters, the exports) does about that much work per unit."""

    leaves: int
    instances: int


def count_expansion(root, width: float, height: float, max_leaves: int = MAX_LEAVES,
                    max_instances: int = MAX_INSTANCES, applied: set[int] | None = None) -> Expansion:
    """What a tree expands to in a ``width`` x ``height`` image (`Expansion`), counting stopped as soon as either
    figure is past its limit (then that figure is its limit + 1). Counted from the regions' extents without laying
    out positions: the copies of a repeat (same node, same extent, the same exceptions reaching in) are counted
    once, so a tree of a million leaves costs what its distinct nodes do, and exceptions are counted along their
    paths' trie (`_Paths`). ``applied``, where given, collects the ``id`` of every exception that reaches its node
    in some instance (complete only when the counting did not stop). (The executor places copies at float
    offsets, so a copy's extent may differ from this one's by a rounding error, which could move a ``"fill"`` count
    only if its quotient sat exactly on a half: a bound, not a layout.)"""
    memo: dict[tuple, tuple[int, int]] = {}
    tries: dict[tuple[int, int], _Paths | None] = {}
    leaves = instances = 0

    def add(n_leaves: int, n_instances: int) -> None:
        nonlocal leaves, instances
        leaves += n_leaves
        instances += n_instances
        if leaves > max_leaves or instances > max_instances:
            raise _TooMany

    def count(node, w: float, h: float, pending: list | None = None) -> tuple[int, int]:
        carried = sum(t.total for t in pending) if pending else 0
        if node.rule == "leaf":
            add(1, 1 + carried)
            return 1, 1 + carried
        key = (id(node), w, h, *map(id, pending)) if pending else (id(node), w, h)
        known = memo.get(key)
        if known is not None:
            add(*known)
            return known
        own = 1 + carried + len(node.exceptions)
        add(0, own)
        along_x = node.axis == "x"
        length = w if along_x else h
        sizes, children, _ = expand(node, length)
        paths = list(pending or ())
        if node.rule == "repeat" and node.exceptions:
            n = repeat_count(node, length)
            mine = tries.get((id(node), n), False)
            if mine is False:
                mine = tries[id(node), n] = _Paths.of(node, n)
            if mine is not None:
                paths.insert(0, mine)  # own first: an exception from further up wins
        below: list | None = None
        if paths:
            sizes, children = list(sizes), list(children)
            below = [None] * len(children)
            for t in paths:
                for i, ended in t.ends.items():
                    if i >= len(children):
                        continue  # a copy this length does not lay out
                    for o in ended:
                        if applied is not None:
                            applied.add(id(o))
                        if o.size is not None:
                            sizes[i] = o.size
                        if o.node is not None:
                            children[i] = o.node
                for i, deeper in t.kids.items():
                    if i < len(children):
                        below[i] = [*(below[i] or ()), deeper]
        n_leaves, n_instances = 0, own
        for i, (child, extent) in enumerate(zip(children, layout(sizes, length), strict=True)):
            sub = below[i] if below is not None else None
            a, b = count(child, extent, h, sub) if along_x else count(child, w, extent, sub)
            n_leaves, n_instances = n_leaves + a, n_instances + b
        memo[key] = (n_leaves, n_instances)
        return n_leaves, n_instances

    with contextlib.suppress(_TooMany):
        count(root, float(width), float(height))
    return Expansion(min(leaves, max_leaves + 1), min(instances, max_instances + 1))


def count_leaves(root, width: float, height: float, limit: int = MAX_LEAVES) -> int:
    """How many rectangles a tree expands to in a ``width`` x ``height`` image, or ``limit + 1`` as soon as it is
    more than ``limit`` (`count_expansion`)."""
    return count_expansion(root, width, height, limit, 1 << 62).leaves
