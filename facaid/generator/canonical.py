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
from facaid.grammar.floors import lone_child, merge_floor_runs
from facaid.grammar.nodes import Node
from facaid.grammar.procedure import Procedure

MIN_GAP = 1 / 128  # of the image side: narrower wall or background is not part of the canonical tree
IMPLICIT = ("facade", "background")


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
        node.children = [child if child.rule == "leaf" else visit(child) for child in node.children]
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
            return lone_child(node)
        return node

    proc.root = visit(proc.root)
    return proc


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
