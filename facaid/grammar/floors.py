"""Floors that repeat: neighbouring runs of floors with the same tree become one repeat.

The canonical trees of the generator (`facaid.generator.canonical`) write alike floors as a repeat; a decoded tree
may write them one by one, the same picture with another tree. `merge_repeated_floors` brings a decoded tree to
the canonical form of its floors (`facaid.decoding` does, within `FLOOR_TOLERANCE`), `merge_floor_runs` merges
one floors split, and `structure` is what a tree looks like without its size values.
"""

from __future__ import annotations

from facaid.grammar.nodes import Node, Size

SLOT_ROLES = ("floor", "ground")  # roles of a slot in the facade's layout, whatever node fills it


def _floor_run(size: Size, node: Node) -> tuple[int, list[tuple[Size, Node]]] | None:
    """A child of a floors split as (floors, pattern): a repeat of floors or one floor; None if neither."""
    if size.mode != "flt":
        return None
    if node.rule == "repeat" and node.role == "floors" and isinstance(node.count, int) and not node.tail:
        return node.count, list(zip(node.sizes, node.children, strict=True))
    if node.role == "floor":
        return 1, [(Size("flt", 1.0), node)]
    return None


def merge_floor_runs(split: Node, tolerance: float | None = None) -> None:
    """Neighbouring runs of floors whose trees (and bands) are the same become one repeat, in place: the
    generator compared floors before `canonical` removed the gaps, so two runs may look alike only now. The
    merged run takes the first run's proportions for every floor. With ``tolerance``, runs merge only when their
    sizes also agree within that fraction (`merge_repeated_floors`)."""
    items = list(zip(split.sizes, split.children, strict=True))
    merged: list[tuple[Size, Node]] = []
    known: dict[int, tuple] = {}  # structure by id(node): a run is compared with both its neighbours

    def shape(pattern: list[tuple[Size, Node]]) -> tuple:
        out = []
        for s, n in pattern:
            if id(n) not in known:
                known[id(n)] = structure(n)
            out.append((s.mode, known[id(n)]))
        return tuple(out)

    for size, node in items:
        if merged:
            prev = _floor_run(*merged[-1])
            cur = _floor_run(size, node)
            if (prev and cur and shape(prev[1]) == shape(cur[1])
                    and (tolerance is None or _alike(prev[1], cur[1], tolerance))):
                repeat = Node.repeat(split.axis, prev[0] + cur[0], prev[1], role="floors")
                merged[-1] = (Size("flt", merged[-1][0].value + size.value), repeat)
                continue
        merged.append((size, node))
    split.sizes = [s for s, _ in merged]
    split.children = [n for _, n in merged]


def merge_repeated_floors(root: Node, tolerance: float | None = None) -> Node:
    """A decoded tree in the canonical form of its floors, in place; returns the root. The model may write two
    neighbouring floors alike as two floors where `canonical` writes a repeat: the same picture, a different
    tree. Their runs merge (sizes within ``tolerance``, see `merge_floor_runs`), and a floors split left with one
    child gives way to it, as in `canonical`."""

    def visit(node: Node) -> Node:
        node.children = [visit(child) for child in node.children]
        if node.rule == "split" and node.role == "floors":
            merge_floor_runs(node, tolerance)
            if len(node.children) == 1:
                return lone_child(node)
        return node

    return visit(root)


def lone_child(node: Node) -> Node:
    """The only child of a split (or centred mirror), taking its place: it takes over the node's role if it has
    none, and always a `SLOT_ROLES` role."""
    child = node.children[0]
    if child.role is None or node.role in SLOT_ROLES:
        child.role = node.role
    return child


def _alike(a: list[tuple[Size, Node]], b: list[tuple[Size, Node]], tolerance: float) -> bool:
    """Whether two patterns of the same structure have sizes within ``tolerance`` of each other (relative)."""

    def close(x: Size, y: Size) -> bool:
        return abs(x.value - y.value) <= tolerance * max(abs(x.value), abs(y.value))

    def same(m: Node, n: Node) -> bool:
        return (all(close(x, y) for x, y in zip(m.sizes, n.sizes, strict=True))
                and all(same(c, d) for c, d in zip(m.children, n.children, strict=True)))

    if len(a) == 1 and len(b) == 1:  # one floor each: its own sizes (its slot's share is the run's length)
        return same(a[0][1], b[0][1])
    return all(close(s, t) and same(m, n) for (s, m), (t, n) in zip(a, b, strict=True))


def structure(node: Node) -> tuple:
    """What a tree looks like without its size values: equal for trees a tree edit distance cannot tell apart."""
    return (node.rule, node.label, node.axis, node.role, node.count, node.tail, node.center,
            tuple(s.mode for s in node.sizes), tuple(structure(c) for c in node.children))
