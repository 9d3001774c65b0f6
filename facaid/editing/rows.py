"""The rows a bay edit reaches besides the rows of tiles: a bay more (fewer) is a column put in (taken out) of the
whole building, not of its floors alone.

- A facade of wings keeps the other wings' bays (`building_of`).
- A row written out cell by cell under the bays (the generator's ground floor of shops between pillars, the door
  under one) takes a cell where the new tile goes, a copy of the nearest cell without a door (`aligned_rows`,
  `step_cells`): the entrance stays one, and every shop stays under its column.
- A row of its own over the bays (an attic's dormers, a frieze) opens its wall where the new bay goes instead of
  stretching (`wall_rows`, `open_wall`), so that a dormer stays over its column.
- A row mirrored around a centre bay (n bays, the centre, n bays) is first written as the repeat of 2n + 1 bays
  that draws it, the centre its exception (`unmirrored`): a mirror can only change by two.
"""

from __future__ import annotations

import numpy as np

from facaid.editing.resizing import repeat_unit
from facaid.grammar.execute import label_map
from facaid.grammar.layout import expand_over, layout
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure


def building_of(proc: Procedure, path: str) -> str:
    """The path (with a trailing "/") of the innermost node of role ``facade`` above ``path``: the building, of a
    facade of wings, that holds it; the root's where none is."""
    nodes = dict(proc.nodes())
    parts = path.split("/")
    for k in range(len(parts) - 1, 0, -1):
        above = "/".join(parts[:k])
        if nodes.get(above) is not None and nodes[above].role == "facade":
            return f"{above}/"
    return "root/"


def aligned_rows(proc: Procedure, extent: dict, boxes: dict, main: Node, building: str) -> list[tuple[Node, int]]:
    """The splits along x of the ``building`` some of whose children line up with the copies of the row of tiles
    ``main`` (as many, each as long and where it is, within `ALIGNED`), with the index of the first of those: a
    ground floor written out as a shop under each bay and the door under one. A bay more puts a cell in them where
    it puts its tile; a bay fewer takes one out. ``extent`` and ``boxes``: every node's first instance's size and
    box."""
    if id(main) not in boxes:  # a row only an exception lays out: none is placed by it
        return []
    length = extent[id(main)][0]
    cells = layout(expand_over(main, length, None)[0], length)
    start = boxes[id(main)][0]
    out = []
    for path, node in proc.nodes():
        if (node.rule != "split" or node.axis != "x" or len(node.children) < len(cells) or "!" in path
                or not f"{path}/".startswith(building) or id(node) not in extent or id(node) not in boxes):
            continue
        own = extent[id(node)][0]
        mine = layout(expand_over(node, own, None)[0], own)
        starts = boxes[id(node)][0] + np.concatenate([[0.0], np.cumsum(mine)])
        first = int(np.argmin(np.abs(starts - start)))
        if abs(starts[first] - start) > 2.0 or first + len(cells) > len(mine):
            continue
        if all(abs(a - b) <= max(ALIGNED * b, 2.0) for a, b in zip(mine[first:], cells, strict=False)):
            out.append((node, first))
    return out


ALIGNED = 0.1  # a cell of a row written out lines up with a tile when their lengths differ by at most this share


def step_cells(row: Node, offset: int, length: float, main: Node, moved: dict[int, int],
                source: int | None) -> float:
    """Put in ``row`` (a split whose children from ``offset`` on line up with ``main``'s, `aligned_rows`) the cells
    of the tiles ``moved`` adds, or take out those of the tiles it removes, in place; the change of its length. A
    new cell copies the source tile's cell, or the nearest one without a door (the entrance stays one); a removed
    tile's cell with the door leaves the nearest one without instead."""
    k = len(main.children)
    lengths = layout(expand_over(row, length, None)[0], length)
    copies = main.count

    def span(c: int) -> slice:
        return slice(offset + c * k, offset + (c + 1) * k)

    plain = [c for c in range(copies) if not holds_door(row.children[span(c)])]
    if not plain:
        return 0.0

    def nearest(c: int) -> int:
        return min(plain, key=lambda p: (abs(p - c), p))

    added = sorted(set(range(moved[copies])) - {moved[c] for c in range(copies) if c in moved})
    gone = sorted((c for c in range(copies) if c not in moved), reverse=True)
    change = 0.0
    if added:
        cell = nearest(source if source is not None else added[0] - 1)
        items = list(zip(row.sizes[span(cell)], row.children[span(cell)], strict=True))
        for a in added:
            for j, (size, child) in enumerate(items):
                row.sizes.insert(offset + a * k + j, size)
                row.children.insert(offset + a * k + j, child.copy())
            change += sum(lengths[span(cell)])
    taken = []  # the cells to take out, chosen before any goes (their indices are the row's as it is)
    for g in gone:
        if not plain:
            break
        taken.append(nearest(g))
        plain.remove(taken[-1])
    for cell in sorted(taken, reverse=True):
        change -= sum(lengths[span(cell)])
        del row.sizes[span(cell)]
        del row.children[span(cell)]
    return change


def opening(main: Node, length: float, start: float, moved: dict[int, int]) -> tuple[float, float]:
    """Where a bay edit of the row of tiles ``main`` (laid out on [start, start + length)) opens or closes the
    facade, as the copies ``moved`` says: (x, width), width negative where a copy goes (x its left edge)."""
    k = len(main.children)
    lengths = layout(expand_over(main, length, None)[0], length)
    edges = start + np.concatenate([[0.0], np.cumsum(lengths)])
    copies = main.count
    gone = [c for c in range(copies) if c not in moved]
    if gone:
        return float(edges[gone[0] * k]), -float(sum(lengths[gone[0] * k : (gone[0] + 1) * k])) * len(gone)
    added = sorted(set(range(moved[copies])) - {moved[c] for c in range(copies)})
    typical = repeat_unit(main, length)[0]
    return float(edges[min(added[0], copies) * k]), typical * len(added)


def wall_rows(proc: Procedure, extent: dict, boxes: dict, main: Node, building: str,
               own: dict[int, float]) -> list[Node]:
    """The splits along x of the ``building`` over the whole row of tiles ``main`` that hold none of it and nothing a
    bay edit already changes (``own``): an attic's row of dormers, a frieze. They open their wall where a new bay
    goes instead of stretching, so that what they hold stays over its column."""
    x0, _, x1, _ = boxes[id(main)]
    out = []
    for path, node in proc.nodes():
        if (node.rule != "split" or node.axis != "x" or "!" in path or not f"{path}/".startswith(building)
                or id(node) not in boxes or id(node) not in extent):
            continue
        b = boxes[id(node)]
        if b[0] > x0 + 2.0 or b[2] < x1 - 2.0:
            continue
        if any(id(n) in own or n is main for _, n in node.walk()):
            continue
        if any(id(n) in own or n is main for o in node.exceptions if o.node is not None for _, n in o.node.walk()):
            continue
        out.append(node)
    return out


def open_wall(row: Node, length: float, start: float, at: float, width: float) -> float | None:
    """Widen (narrow, for a negative ``width``) the wall leaf of ``row`` nearest ``at`` by ``width``, in place, and
    return ``width``; None where no wall leaf is within a bay of it or long enough to give up as much."""
    lengths = layout(expand_over(row, length, None)[0], length)
    edges = start + np.concatenate([[0.0], np.cumsum(lengths)])
    walls = [i for i, c in enumerate(row.children) if c.rule == "leaf" and c.label == "facade" and c.role is None
             and lengths[i] + width >= 1.0]
    if not walls:
        return None
    far = [max(0.0, edges[i] - at, at - edges[i + 1]) for i in walls]
    i = walls[int(np.argmin(far))]
    if min(far) > abs(width):
        return None
    row.sizes[i] = Size(row.sizes[i].mode, round(row.sizes[i].value + width, 4))
    return width


def holds_door(nodes: list[Node]) -> bool:
    return any(n.label == "door" or n.role == "entrance" for node in nodes for _, n in node.walk())


SAME = 0.001  # a mirror written as a repeat draws the same facade where at most this share of its pixels differ


def unmirrored(proc: Procedure) -> Procedure:
    """``proc`` (in place) with every row mirrored around a centre bay, of bays that look the same reflected,
    written as the repeat that draws the same pixels: n bays, the centre, n bays as 2n + 1 copies whose copy n is
    the centre (`_as_repeat`). A mirror whose reflected bays would differ (in more than `SAME` of the pixels: a
    pixel's rounding is the same) stays as it is."""
    found = [(parent, i) for _, parent in proc.nodes() for i, child in enumerate(parent.children)
             if _as_repeat(child) is not None]
    if not found:
        return proc
    before = label_map(proc)
    for parent, i in found:
        mirror = parent.children[i]
        parent.children[i] = _as_repeat(mirror)
        after = label_map(proc)
        if after.shape != before.shape or (after != before).mean() > SAME:
            parent.children[i] = mirror
    return proc


def _as_repeat(mirror: Node) -> Node | None:
    """The repeat of a centred mirror of a counted repeat of bays and its centre bay (a pillar before it where the
    bays have one), or None where it is not one."""
    if mirror.rule != "mirror" or not mirror.center or len(mirror.children) < 2:
        return None
    side = mirror.children[0]
    if side.rule != "repeat" or not isinstance(side.count, int) or side.tail or side.exceptions:
        return None
    pattern = list(zip(side.sizes, side.children, strict=True))
    middle = list(zip(mirror.sizes[1:], mirror.children[1:], strict=True))
    if len(middle) != len(pattern) or len(pattern) > 2 or (len(pattern) == 2 and not pattern[0][1].is_leaf):
        return None
    out = Node.repeat(mirror.axis, 2 * side.count + 1, [(s, c.copy()) for s, c in pattern], tail=len(pattern) - 1,
                      role=mirror.role or side.role)
    for j, ((size, node), (own, centre)) in enumerate(zip(pattern, middle, strict=True)):
        same = node.to_dict() == centre.to_dict()
        if size != own or not same:
            out.exceptions.append(Override(side.count, (j,), own if size != own else None,
                                           None if same else centre.copy()))
    return out


__all__ = ["ALIGNED", "SAME", "aligned_rows", "building_of", "holds_door", "open_wall", "opening", "step_cells",
           "unmirrored", "wall_rows"]
