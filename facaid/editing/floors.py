"""The floors a floor edit takes: floors a split lays out one by one become the repeat they are
(`unrepeated_floors`, `as_floors_repeat`); the copy a floor more repeats is the plainest floor the entrance does not
reach into, and the one a floor fewer takes the floor another floor repeats most closely (`plain_floor`)."""

from __future__ import annotations

import json

import numpy as np

from facaid.editing.resizing import copy_lengths
from facaid.grammar.execute import first_boxes, flat_rows
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure
from facaid.grammar.repeats import copies_moved
from facaid.labels import LABEL_ID
from facaid.metrics import scaled_procedure_map
from facaid.segmentation import region_boxes

TWIN = 0.9  # a floor another repeats this closely is as good to take out as any other such (the judge's likeness)
PICTURE = 512  # the longer side of the picture floors are compared in
TWINS_AT_MOST = 64  # floors compared two by two at most (past it, a floor fewer takes the plainest)


def unrepeated_floors(proc: Procedure, inst) -> tuple[Node, int, int] | None:
    """Where a facade's upper floors are laid out by a split along y and no repeat (a house of one floor, or of two
    that differ): (that split, the index of its first floor and of its last + 1); None otherwise. `floors` ± 1
    makes them a repeat first (`as_floors_repeat`)."""
    floors = [(p, n) for p, n in proc.nodes() if n.role == "floor" and inst.outer.get(id(n))]
    if not floors or any(inst.count[id(n)] != 1 or "!" in p for p, n in floors):
        return None
    parents = {p.rsplit("/", 1)[0] for p, _ in floors}
    if len(parents) != 1:
        return None
    parent = dict(proc.nodes()).get(parents.pop())
    if parent is None or parent.rule != "split" or parent.axis != "y":
        return None
    at = sorted(int(p.rsplit("/", 1)[1]) for p, _ in floors)
    if at != list(range(at[0], at[-1] + 1)):
        return None
    return parent, at[0], at[-1] + 1


def as_floors_repeat(parent: Node, lo: int, hi: int, inst) -> None:
    """The floors ``parent.children[lo:hi]`` as one repeat (in place): of the floor most of them are (the last of
    those), the others its exceptions, each at its height."""
    floors = parent.children[lo:hi]
    heights = [inst.extent[id(f)][1] for f in floors]
    trees = [json.dumps(f.to_dict(), sort_keys=True) for f in floors]
    typical = max(range(len(floors)), key=lambda i: (trees.count(trees[i]), i))
    row = Node.repeat("y", len(floors), [(Size("flt", round(heights[typical], 4)), floors[typical])])
    for c, (floor, tree, h) in enumerate(zip(floors, trees, heights, strict=True)):
        size = Size("flt", round(h, 4)) if abs(h - heights[typical]) > 0.5 else None
        node = floor if tree != trees[typical] else None
        if size is not None or node is not None:
            row.exceptions.append(Override(c, (0,), size, node))
    total = round(sum(inst.extent[id(c)][1] for c in floors), 4)
    parent.sizes[lo:hi] = [Size("flt", total)]
    parent.children[lo:hi] = [row]


def plain_floor(proc: Procedure, floors: Node, inst, fewer: bool = False) -> int:
    """The copy of the floors' repeat that a floor more repeats, or with ``fewer`` a floor fewer takes: of those no
    door reaches into (the entrance's top can reach into the floor above the ground), the one fewest exceptions
    change, the last of those; a floor fewer first a copy another copy repeats (`twins` at least `TWIN`, else the
    most alike), so that what is taken out is a floor the facade keeps (of two floors with a long balcony and two
    without, the repeat's typical copy may be one of the first two, which differ by their windows)."""
    x0, y0, x1, _ = first_boxes(proc)[id(floors)]
    edges = y0 + np.concatenate([[0.0], np.cumsum(copy_lengths(floors, inst.extent[id(floors)][1]))])
    doors = region_boxes(flat_rows(proc), (LABEL_ID["door"],))
    reached = {c for _, top, _, bottom in doors.tolist() for c in range(floors.count)
               if top < edges[c + 1] - 1 and bottom > edges[c] + 1}
    changed = {c: sum(1 for o in floors.exceptions if o.copy == c) for c in range(floors.count)}
    twin = [0.0] * floors.count
    kept: set[int] = set()
    if fewer and floors.count <= TWINS_AT_MOST:
        scale = min(1.0, PICTURE / max(proc.width, proc.height))  # a small picture: a tree may be 100,000 px
        picture = scaled_procedure_map(proc, scale)[:, int(x0 * scale) : max(int(x0 * scale) + 1, int(x1 * scale))]
        twin = twins(picture, edges * scale)
        # a copy that alone lays the floor's own pattern out cannot go (`copies_moved` keeps it): its twin goes
        kept = {c for c in range(floors.count) if c in copies_moved(floors, floors.count - 1, c)}
    return min(range(floors.count), key=lambda c: (c in reached, c in kept, twin[c] < TWIN,
                                                   0.0 if twin[c] >= TWIN else -twin[c], changed[c], -c))


def twins(picture: np.ndarray, edges: np.ndarray) -> list[float]:
    """For each band [edges[c], edges[c + 1]) of a label map, how closely another band repeats it: the share of
    pixels equal to those of the most alike other band, over the lower one's height from the top, times the ratio
    of their heights."""
    bands = [picture[int(round(a)) : int(round(b))] for a, b in zip(edges[:-1], edges[1:], strict=True)]
    out = []
    for c, band in enumerate(bands):
        best = 0.0
        for d, other in enumerate(bands):
            h = min(len(band), len(other))
            if d == c or h == 0:
                continue
            best = max(best, float((band[:h] == other[:h]).mean()) * h / max(len(band), len(other)))
        out.append(best)
    return out


__all__ = ["as_floors_repeat", "plain_floor", "twins", "unrepeated_floors"]
