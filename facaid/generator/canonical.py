"""The canonical form of a generated procedure: no structure that its segmentation cannot show.

The builder decides in metres whether a gap of wall exists (the wall under a sill, the padding beside a window,
a strip of sky). Once the facade is scaled to pixels many of these gaps are narrower than a segmentation shows
reliably (the first models read coordinates in 128 steps of the image side; the shipped one reads 256, so a gap
that is kept is two steps wide at least), so one picture would come from two trees and no model could tell which
one to write. `canonical` removes such leaves: wall and background (which the
model never sees as rectangles of their own) narrower than `MIN_GAP` of the image side along their parent's axis,
and any leaf under one pixel (rounding drops it from the segmentation). A split or centred mirror left with one
child gives way to that child, which takes over its role if it has none, and always takes over a `SLOT_ROLES`
role: the builder gives a floor or a ground floor without margins that role itself, so a floor whose margins
are too thin to see must get it too (it kept its row's ``bay`` before, and the same picture had two trees).
Likewise a row of bays mirrored around a centre bay that rounds to the same tree as the other bays becomes the
repeat that draws the same row (`_plain_row`).
"""

from __future__ import annotations

from facaid.grammar.execute import first_boxes
from facaid.grammar.procedure import Node, Procedure, Size

MIN_GAP = 1 / 128  # of the image side: narrower wall or background is not part of the canonical tree
IMPLICIT = ("facade", "background")
SLOT_ROLES = ("floor", "ground")  # roles of a slot in the facade's layout, whatever node fills it


def canonical(proc: Procedure) -> Procedure:
    """The procedure with invisible gaps removed (in place); returns it (`generate_procedure` validates it)."""
    boxes = first_boxes(proc)

    def invisible(node: Node, axis: str) -> bool:
        if node.rule != "leaf" or id(node) not in boxes:
            return False
        x0, y0, x1, y1 = boxes[id(node)]
        extent, side = (x1 - x0, proc.width) if axis == "x" else (y1 - y0, proc.height)
        return extent < (MIN_GAP * side if node.label in IMPLICIT else 1.0)

    def visit(node: Node) -> Node:
        node.children = [visit(child) for child in node.children]
        if node.rule not in ("split", "mirror") or len(node.children) < 2:
            return node
        keep = [i for i, child in enumerate(node.children) if not invisible(child, node.axis)]
        if keep and len(keep) < len(node.children):
            if node.rule == "mirror" and node.center and keep[-1] != len(node.children) - 1:
                node.center = False  # the middle child went
            node.sizes = [node.sizes[i] for i in keep]
            node.children = [node.children[i] for i in keep]
        if node.rule == "split" and node.role == "floors":
            merge_floor_runs(node)
        if node.rule == "mirror" and node.role == "bay":
            node = _plain_row(node) or node
        if len(node.children) == 1 and (node.rule == "split" or node.center):
            return _lone_child(node)
        return node

    proc.root = visit(proc.root)
    return proc


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
    for size, node in items:
        if merged:
            prev = _floor_run(*merged[-1])
            cur = _floor_run(size, node)
            if (prev and cur and _pattern_structure(prev[1]) == _pattern_structure(cur[1])
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
                return _lone_child(node)
        return node

    return visit(root)


def _plain_row(mirror: Node) -> Node | None:
    """The repeat that draws ``mirror``, a row of bays mirrored around a centre bay that is, in pixels, the same
    as its other bays (a wider window capped at the same width); None when the centre differs. The builder
    compares the centre bay with the others in metres, and rounding to pixels can make them one."""
    if not mirror.center or not mirror.children or mirror.children[0].rule != "repeat":
        return None
    side = mirror.children[0]
    middle = list(zip(mirror.sizes[1:], mirror.children[1:], strict=True))  # the centre bay and a pillar before it
    pattern = list(zip(side.sizes, side.children, strict=True))
    if (not isinstance(side.count, int) or side.tail or len(middle) != len(pattern)
            or any(s != t or m.to_dict() != n.to_dict() for (s, m), (t, n) in zip(middle, pattern, strict=True))):
        return None
    tail = len(pattern) - 1  # a pillar before the centre also ends the row: (pillar bay) x n, pillar
    if tail and not (tail == 1 and pattern[0][1].is_leaf):
        return None
    return Node.repeat(mirror.axis, 2 * side.count + 1, pattern, tail=tail, role=mirror.role)


def _lone_child(node: Node) -> Node:
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


def _pattern_structure(pattern: list[tuple[Size, Node]]) -> tuple:
    return tuple((s.mode, structure(n)) for s, n in pattern)


def structure(node: Node) -> tuple:
    """What a tree looks like without its size values: equal for trees a tree edit distance cannot tell apart."""
    return (node.rule, node.label, node.axis, node.role, node.count, node.tail, node.center,
            tuple(s.mode for s in node.sizes), tuple(structure(c) for c in node.children))
