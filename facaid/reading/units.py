"""Typical copies and what makes each copy differ from them: the units the lattice reader lays out.

A *unit* is a typical copy (a tile, a floor's margin, the attic's or the ground floor's cell of a column): one real
copy of the photo's, resampled to the typical size, and the exact tree of it. It is a real copy and not a vote
across them (issue 67): a new floor must look like a floor of the building, and a vote of floors that differ is a
blend of them. `medoid` picks it: the copy the others differ from least.

A *delta* makes the typical copy into one copy (`Deltas.of`): sizes where the copy has the typical shape but lays
out differently by more than a hand's jitter (no leaf), leaves it paints with another label (a closed blind: one
leaf; a missing sill: none), or its own exact tree. Pixels within `EDGE` of an edge between two labels count for
nothing, but for an element one of the two leaves out (`steady`): a hand's jitter is restored, not copied, and a
thin sill that one copy lacks is no jitter. A delta must put right `LEAF_GAIN` of the image per leaf: a few
pixels, so that nothing drawn is priced away.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.decompose import tree_of_label_map
from facaid.grammar.execute import execute
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.grammar.shapes import elements, leaf_paths, shape
from facaid.labels import BACKGROUND, FACADE, LABEL_ID, LABELS
from facaid.metrics import appears, near_edges
from facaid.segmentation import decompose_grid, region_boxes

EDGE = 0.06  # a copy that differs only this close (a share of the unit's shorter side) to an edge differs by jitter
LEAF_GAIN = 0.00001  # a delta's leaf must put right this share of the image's pixels (5 px of a 500k px image)
ONE_OFF = 1.0  # a delta of one copy pays this many times a leaf's price
DELETE = 0.0  # an element left out of a copy pays this share of a leaf (an annotator may have missed it)
MIN_AREA = 0.01  # leaves under this share of a unit are not relabelled alone (a sliver would be its own element)
SLIVER = 0.05  # nor those thinner than this share of the unit's shorter side

Delta = tuple[tuple[int, ...], Size | None, Node | None]  # (path inside the unit, its size, the node put there)


def resample(crop: np.ndarray, h: int, w: int) -> np.ndarray:
    """``crop`` resampled to h x w by its nearest pixels."""
    ys = np.minimum((np.arange(h) + 0.5) * crop.shape[0] / h, crop.shape[0] - 1).astype(np.int64)
    xs = np.minimum((np.arange(w) + 0.5) * crop.shape[1] / w, crop.shape[1] - 1).astype(np.int64)
    return crop[ys][:, xs]


def medoid(groups: list[list[np.ndarray]]) -> int:
    """The index of the group (a copy, or a row or column of copies, each a list of maps of equal shapes across the
    groups) that differs from the others in the fewest pixels."""
    n = len(groups)
    cost = np.zeros(n)
    for a in range(n):
        for b in range(a + 1, n):
            d = sum(int((x != y).sum()) for x, y in zip(groups[a], groups[b], strict=True))
            cost[a] += d
            cost[b] += d
    return int(np.argmin(cost))


def with_windows(node: Node) -> Node:
    """The tree with its window leaves in the role ``window``, so that the window size is a named parameter."""
    for _, n in node.walk():
        if n.rule == "leaf" and n.label == "window":
            n.role = "window"
    return node


def exact_tree(label_map: np.ndarray) -> Node:
    """The exact tree of a map, its windows in their role."""
    return with_windows(tree_of_label_map(label_map))


class Unit:
    """A typical copy: ``crop`` (one real copy) resampled to h x w, and its exact tree."""

    def __init__(self, crop: np.ndarray, h: int, w: int):
        self.h, self.w = h, w
        self.map = resample(crop, h, w)
        self.tree = exact_tree(self.map)
        boxes = execute(Procedure(w, h, self.tree))
        self.leaves = [(path, leaf, box[1:]) for (path, leaf), box in zip(leaf_paths(self.tree), boxes,
                                                                          strict=True)]


def jitter_band(crop: np.ndarray) -> np.ndarray:
    """The pixels of ``crop`` within `EDGE` of its shorter side of an edge: where a hand's jitter is forgiven."""
    r = max(1, round(EDGE * min(crop.shape)))
    return near_edges(crop, r, r)


def missing(drawn: np.ndarray, crop: np.ndarray) -> np.ndarray:
    """The pixels of the elements of ``crop`` (connected regions of a label but wall and background) that ``drawn``
    leaves out: it paints their label on less than half their area where they are or off by half their thinner side
    (a 3 px sill drawn 2 px lower is there). An element left out is a difference however thin it is, not a hand's
    jitter."""
    out = np.zeros(crop.shape, dtype=bool)
    rows = decompose_grid(crop.astype(np.int64) + 1)
    rows[:, 0] -= 1
    for label in {int(v) for v in rows[:, 0]} - {FACADE, BACKGROUND}:
        for x0, y0, x1, y1 in region_boxes(rows, (label,)):
            own = crop[y0:y1, x0:x1] == label
            if not appears(drawn, label, (x0, y0, x1, y1), int(own.sum())):
                out[y0:y1, x0:x1] |= own
    return out


def steady(drawn: np.ndarray, crop: np.ndarray) -> np.ndarray:
    """Where ``drawn`` and ``crop`` must agree: away from ``crop``'s edges (`jitter_band`), and on every element
    either of them has that the other leaves out (`missing`)."""
    return ~jitter_band(crop) | missing(drawn, crop) | missing(crop, drawn)


def off(drawn: np.ndarray, crop: np.ndarray) -> int:
    """The pixels ``drawn`` gets wrong of ``crop`` where they must agree (`steady`)."""
    return int(((drawn != crop) & steady(drawn, crop)).sum())


def resized(reference: Node, own: Node, jitter: float, path: tuple[int, ...] = ()) -> list[tuple[tuple, Size]]:
    """The sizes of ``own`` (a tree of ``reference``'s shape) that differ from the reference's by more than
    ``jitter`` pixels, by child path; a split's only floating child takes what is left whatever its value."""
    out = []
    floating = sum(1 for s in reference.sizes if s.mode == "flt")
    for i, (a, b) in enumerate(zip(reference.sizes, own.sizes, strict=True)):
        if (a.mode != b.mode or abs(a.value - b.value) > jitter) and not (a.mode == b.mode == "flt" and floating == 1):
            out.append(((*path, i), b))
    for i, (a, b) in enumerate(zip(reference.children, own.children, strict=True)):
        if a.rule != "leaf":
            out.extend(resized(a, b, jitter, (*path, i)))
    return out


class Deltas:
    """What makes a typical copy into each copy, each delta kept where a leaf buys at least `LEAF_GAIN` of the
    image."""

    def __init__(self, area: int):
        self.least = LEAF_GAIN * area

    def of(self, reference: Unit, crop: np.ndarray, relabel: bool = True) -> list[Delta]:
        """What makes ``reference`` into ``crop`` (see the module's docstring): its sizes where ``crop``'s tree has
        the reference's shape; else the reference's leaves relabelled (unless ``relabel`` is off: a copy that other
        deltas reach into must keep the shape of the tree it lays out) or ``crop``'s own tree, whichever puts more
        right for its leaves; else nothing."""
        node = exact_tree(crop)
        if shape(node) == shape(reference.tree):
            jitter = max(1.0, EDGE * min(crop.shape))
            return [(path, size, None) for path, size in resized(reference.tree, node, jitter)]
        drawn = resample(reference.map, *crop.shape)
        agree = steady(drawn, crop)
        before = int(((drawn != crop) & agree).sum())
        if not before:
            return []
        relabels, cost = self._relabels(reference, crop, drawn, agree) if relabel else ([], 0.0)
        relabelled = before - int(((drawn != crop) & agree).sum())
        if self.net(before, ONE_OFF * max(DELETE, elements(node))) > max(0.0, self.net(relabelled, cost)):
            return [((), None, node)]
        return relabels if self.net(relabelled, cost) > 0 else []

    def _relabels(self, reference: Unit, crop: np.ndarray, drawn: np.ndarray,
                  agree: np.ndarray) -> tuple[list[Delta], float]:
        """The leaves of the reference that ``crop`` paints mostly with another label, relabelled (a leaf each),
        and their price; ``drawn`` (the reference laid out on the crop) is painted as they are."""
        out, cost = [], 0.0
        sy, sx = crop.shape[0] / reference.h, crop.shape[1] / reference.w
        for path, leaf, (x0, y0, x1, y1) in reference.leaves:
            a, b, c, d = round(x0 * sx), round(y0 * sy), round(x1 * sx), round(y1 * sy)
            if min(c - a, d - b) < SLIVER * min(crop.shape) or (c - a) * (d - b) < MIN_AREA * crop.size:
                continue  # a sliver of the unit relabelled would be an element of its own
            counts = np.bincount(crop[b:d, a:c][agree[b:d, a:c]], minlength=len(LABELS))
            best, own = int(counts.argmax()), LABEL_ID[leaf.label]
            price = ONE_OFF * (1 if best not in (FACADE, BACKGROUND) else DELETE)
            if best != own and self.worth(counts[best] - counts[own], price):
                out.append((path, None, with_windows(Node.leaf(LABELS[best]))))
                drawn[b:d, a:c] = best
                cost += price
        return out, cost

    def worth(self, gain: float, cost: float) -> bool:
        return gain > 0 and gain >= self.least * cost

    def net(self, gain: float, cost: float) -> float:
        """Pixels put right less what the leaves cost (each `LEAF_GAIN` of the image): above 0, worth it."""
        return gain - self.least * cost if gain > 0 else 0.0


__all__ = ["DELETE", "EDGE", "LEAF_GAIN", "MIN_AREA", "ONE_OFF", "SLIVER", "Delta", "Deltas", "Unit", "exact_tree",
           "jitter_band", "medoid", "missing", "off", "resample", "resized", "with_windows"]
