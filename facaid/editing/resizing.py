"""Resizing a procedure: fixed sizes keep their pixels, floating ones stretch, repeats lay out as many copies as fit.

Used by variations (`facaid.editing.variation`) and by the named parameters' width and height
(`facaid.editing.parameters`).
"""

from __future__ import annotations

from facaid.grammar.execute import first_boxes
from facaid.grammar.layout import expand_over, layout
from facaid.grammar.procedure import MAX_COUNT, MAX_EXTENT, Procedure, validate
from facaid.grammar.repeats import recount


def copy_procedure(proc: Procedure) -> Procedure:
    return Procedure(proc.width, proc.height, proc.root.copy(), dict(proc.meta))


def regions(proc: Procedure) -> dict[int, float]:
    """Length along its own axis of the first instance of every inner node, keyed by id(node)."""
    boxes = box_sizes(proc)
    return {id(n): boxes[id(n)][0 if n.axis == "x" else 1] for _, n in proc.nodes()
            if n.rule != "leaf" and id(n) in boxes}


def repeat_unit(node, length: float) -> tuple[float, float]:
    """A counted repeat laid out on ``length``: the length of one typical copy of its pattern (one that no
    exception resizes; with none such, the mean copy) and of its tail."""
    k = len(node.children)
    lengths = layout(expand_over(node, length, None)[0], length)
    tail = sum(lengths[k * node.count:])
    resized = {o.copy for o in node.exceptions if len(o.path) == 1 and o.size is not None}
    typical = next((c for c in range(node.count) if c not in resized), None)
    if typical is None:
        return (length - tail) / node.count, tail
    return sum(lengths[typical * k:(typical + 1) * k]), tail


def copy_lengths(node, length: float) -> list[float]:
    """The length each copy of the counted repeat ``node`` lays out to on ``length``."""
    k = len(node.children)
    lengths = layout(expand_over(node, length, None)[0], length)
    return [sum(lengths[c * k : (c + 1) * k]) for c in range(node.count)]


def resize(proc: Procedure, width: float, height: float) -> Procedure:
    """The facade at a new size: fixed sizes keep their pixels, floating ones stretch, and every repeat
    lays out as many copies of its pattern as now fit beside its tail (rounded, at least one), as a ``"fill"``
    repeat counts them."""
    if not (1 <= width <= MAX_EXTENT and 1 <= height <= MAX_EXTENT):
        raise ValueError(f"size must be between 1 and {MAX_EXTENT:g} pixels, got {width}x{height}")
    old = regions(proc)
    units = {}  # a repeat's pattern length and its tail's, at the old size
    for _, node in proc.nodes():
        if node.rule == "repeat" and node.count != "fill" and id(node) in old:
            units[id(node)] = repeat_unit(node, old[id(node)])
    out = copy_procedure(proc)
    out.width, out.height = width, height
    # match nodes of the copy with the original by position in the walk
    pairs = list(zip((n for _, n in proc.nodes()), (n for _, n in out.nodes()), strict=True))
    for orig, new in pairs:  # top-down: a parent's count settles before its children are measured
        if id(orig) not in units:
            continue
        lengths = regions(out)
        if id(new) in lengths:
            unit, tail = units[id(orig)]
            recount(out.root, new, max(1, min(MAX_COUNT, round((lengths[id(new)] - tail) / unit))))
    validate(out)
    return out


def box_sizes(proc: Procedure) -> dict[int, tuple[float, float]]:
    """(width, height) of the first instance of every node, keyed by id(node)."""
    return {k: (b[2] - b[0], b[3] - b[1]) for k, b in first_boxes(proc).items()}
