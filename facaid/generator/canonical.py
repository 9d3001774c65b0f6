"""The canonical form of a generated procedure: no structure that its segmentation cannot show.

The builder decides in metres whether a gap of wall exists (the wall under a sill, the padding beside a window,
a strip of sky). Once the facade is scaled to pixels many of these gaps are narrower than a segmentation shows
reliably (the model reads coordinates in 128 steps of the image side), so one picture would come from two trees
and no model could tell which one to write. `canonical` removes such leaves: wall and background (which the
model never sees as rectangles of their own) narrower than `MIN_GAP` of the image side along their parent's axis,
and any leaf under one pixel (rounding drops it from the segmentation). A split or centred mirror left with one
child gives way to that child, which takes over its role if it has none.
"""

from __future__ import annotations

from facaid.grammar.execute import first_boxes
from facaid.grammar.procedure import Node, Procedure, validate

MIN_GAP = 1 / 128  # of the image side: narrower wall or background is invisible in the model's input
IMPLICIT = ("facade", "background")


def canonical(proc: Procedure) -> Procedure:
    """The procedure with invisible gaps removed (in place); returns it, validated."""
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
        if not keep or len(keep) == len(node.children):
            return node
        if node.rule == "mirror" and node.center and keep[-1] != len(node.children) - 1:
            node.center = False  # the middle child went
        node.sizes = [node.sizes[i] for i in keep]
        node.children = [node.children[i] for i in keep]
        if len(node.children) == 1 and (node.rule == "split" or node.center):
            child = node.children[0]
            if child.role is None:
                child.role = node.role
            return child
        return node

    proc.root = visit(proc.root)
    validate(proc)
    return proc


def structure(node: Node) -> tuple:
    """What a tree looks like without its size values: equal for trees a tree edit distance cannot tell apart."""
    return (node.rule, node.label, node.axis, node.role, node.count, node.tail, node.center,
            tuple(s.mode for s in node.sizes), tuple(structure(c) for c in node.children))
