"""Structure induction: a compact procedure with repeats read straight off a segmentation.

The transformer proposes procedures it learned from generated facades; on annotations unlike its training data
its structures can be far off. Induction is the symbolic counterpart that `facaid.pipeline.reconstruct` ranks
beside the model's candidates when those fit badly:

1. **Snap**: edge coordinates closer than ``snap`` x the image side (at least 1 px) become one line, so that
   hand-drawn edges that almost line up (a row of windows, a floor line) do.
2. **Cut**: guillotine cuts along lines that cross no rectangle, floors first, then tiles, as in
   `facaid.grammar.decompose`, kept as a tree with exact lengths.
3. **Fold**: along every split, runs of at least two periods of 1-4 similar siblings (the same shape and
   every length within ``tolerance``) become one ``repeat`` whose pattern is the run's average. Repeats of
   floors get the roles floors/floor and repeats of tiles bay/tile, so variations can change their counts
   and swap them.

The result is an ordinary procedure: the pipeline sizes it like any candidate and keeps whichever
reproduces the input better.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facaid.grammar.guillotine import chunked_split, cut_rects, least_crossed_cut, partition
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import MAX_COUNT, Procedure, ProcedureError
from facaid.labels import BACKGROUND, FACADE, LABELS
from facaid.segmentation import Segmentation


@dataclass
class _Tree:
    """A node with exact lengths: a leaf, a split, or a repeat of a pattern (``lengths`` along ``axis``)."""

    rule: str
    label: int = 0
    axis: str = ""
    lengths: list[float] = field(default_factory=list)
    children: list[_Tree] = field(default_factory=list)
    count: int = 0
    tail: int = 0
    key: tuple = ()  # the shape: rules, axes, labels, counts; equal keys mean the lengths line up
    size: int = 1  # nodes in the procedure it becomes

    def __post_init__(self):
        if self.rule == "leaf":
            self.key = ("leaf", self.label)
        else:
            self.key = (self.rule, self.axis, self.count, self.tail, tuple(c.key for c in self.children))
            self.size = 1 + sum(c.size for c in self.children)


def _merge_round(rects: np.ndarray, tol: float) -> tuple[np.ndarray, bool]:
    """One round of merging same-label pieces that touch along one axis and nearly agree on the other (an
    element cut into pieces where a neighbour's edge notches it); the larger piece's extent is kept."""
    n = len(rects)
    area = (rects[:, 3] - rects[:, 1]) * (rects[:, 4] - rects[:, 2])
    used = np.zeros(n, dtype=bool)
    out = []
    for lo_col, hi_col, a_col, b_col in ((2, 4, 1, 3), (1, 3, 2, 4)):
        touch = (rects[:, None, hi_col] == rects[None, :, lo_col]) & (rects[:, None, 0] == rects[None, :, 0])
        near = (np.abs(rects[:, None, a_col] - rects[None, :, a_col]) <= tol) & \
               (np.abs(rects[:, None, b_col] - rects[None, :, b_col]) <= tol)
        for i, j in zip(*np.nonzero(touch & near), strict=True):
            if used[i] or used[j]:
                continue
            big = i if area[i] >= area[j] else j
            merged = rects[big].copy()
            merged[lo_col], merged[hi_col] = rects[i, lo_col], rects[j, hi_col]
            out.append(merged)
            used[i] = used[j] = True
    if not out:
        return rects, False
    return np.concatenate([rects[~used], np.array(out, dtype=rects.dtype)]), True


def _clean(rects: np.ndarray, tol: float) -> np.ndarray:
    """Pieces of one element merged back together, then slivers thinner than half the tolerance dropped
    (their pixels become wall)."""
    changed = True
    while changed and len(rects) > 1:
        rects, changed = _merge_round(rects, tol)
    thin = np.minimum(rects[:, 3] - rects[:, 1], rects[:, 4] - rects[:, 2]) < min(2.0, tol / 2)
    return rects[~thin]


def _grow(rects: np.ndarray, box: tuple[int, int, int, int], tol: float) -> np.ndarray:
    """Clip to the box; an edge within the rectangle's tolerance of the box's edge moves onto it."""
    x0, y0, x1, y1 = box
    r = rects.copy()
    r[:, [1, 3]] = np.clip(r[:, [1, 3]], x0, x1)
    r[:, [2, 4]] = np.clip(r[:, [2, 4]], y0, y1)
    for lo_col, hi_col, lo, hi in ((1, 3, x0, x1), (2, 4, y0, y1)):
        m = np.minimum(tol, (r[:, hi_col] - r[:, lo_col]) / 4)
        r[:, lo_col] = np.where(r[:, lo_col] - lo <= m, lo, r[:, lo_col])
        r[:, hi_col] = np.where(hi - r[:, hi_col] <= m, hi, r[:, hi_col])
    return r[(r[:, 3] > r[:, 1]) & (r[:, 4] > r[:, 2])]


def _overlap_groups(rects: np.ndarray, lo_col: int, hi_col: int, tol: float) -> tuple[np.ndarray, list]:
    """Rectangles grouped along one axis: (rects, [(start, stop, members)]) in order, not overlapping. Two
    rectangles share a band when they overlap by more than their tolerances; within a band, edges within
    tolerance of the band's median edge move onto it (a row of windows drawn a few pixels apart lines up);
    bands that still overlap by a few pixels are cut between them."""
    rects = rects.copy()
    lo, hi = rects[:, lo_col], rects[:, hi_col]  # views: the snapping below writes into rects
    m = np.minimum(tol, (hi - lo) / 4)
    inner_lo, inner_hi = lo + m, hi - m
    groups: list[list[int]] = []
    reach = -np.inf
    for i in np.argsort(inner_lo, kind="stable").tolist():
        if groups and inner_lo[i] < reach:
            groups[-1].append(i)
            reach = max(reach, inner_hi[i])
        else:
            groups.append([i])
            reach = inner_hi[i]
    bands = []
    for g in groups:
        idx = np.array(g)
        for edge in (lo, hi):
            med = int(np.median(edge[idx]))
            near = idx[np.abs(edge[idx] - med) <= m[idx]]
            edge[near] = med
        bands.append([int(lo[idx].min()), int(hi[idx].max()), idx, float(inner_lo[idx].min()),
                      float(inner_hi[idx].max())])
    for a, b in zip(bands[:-1], bands[1:], strict=False):
        if a[1] > b[0]:  # overlap within tolerance: cut between their cores
            cut = int(round(min(max((a[1] + b[0]) / 2, a[4]), b[3])))
            a[1], b[0] = cut, cut
    keep = (rects[:, 3] > rects[:, 1]) & (rects[:, 4] > rects[:, 2])
    return rects, [(a, b, idx[keep[idx]]) for a, b, idx, _, _ in bands]


def _spanning(rects: np.ndarray, box: tuple[int, int, int, int], axis: str) -> tuple[np.ndarray, list] | None:
    """Bands along ``axis`` cut only at the rectangles that span the whole box across it (cornices, balcony
    rows, a shop row): each such rectangle is a band and the rest between them one band each. None where no
    rectangle spans the box, or all do."""
    lo_col, hi_col, a_col, b_col = (2, 4, 1, 3) if axis == "y" else (1, 3, 2, 4)
    full = (rects[:, a_col] == box[a_col - 1]) & (rects[:, b_col] == box[b_col - 1])
    if not full.any() or full.all():
        return None
    bands = []
    pos = box[lo_col - 1]
    rest = np.flatnonzero(~full)
    for i in np.flatnonzero(full)[np.argsort(rects[full, lo_col], kind="stable")].tolist():
        inside = rest[(rects[rest, lo_col] >= pos) & (rects[rest, hi_col] <= rects[i, lo_col])]
        if len(inside):
            bands.append((pos, int(rects[i, lo_col]), inside))
        bands.append((int(rects[i, lo_col]), int(rects[i, hi_col]), np.array([i])))
        pos = int(rects[i, hi_col])
    inside = rest[rects[rest, lo_col] >= pos]
    if len(inside):
        bands.append((pos, box[hi_col - 1], inside))
    if sum(len(idx) for _, _, idx in bands) != len(rects):
        return None  # something crosses a spanning rectangle (only after snapping): no clean cut
    return rects, bands


class _Inducer:
    def __init__(self, tol: float, tolerance: float, min_px: float, lookahead: int):
        self.tol, self.tolerance, self.min_px, self.lookahead = tol, tolerance, min_px, lookahead

    def cut(self, rects: np.ndarray, box: tuple[int, int, int, int], prefer_y: bool, depth: int = 0) -> _Tree:
        """Split the box into bands of rectangles with wall between them; the wall is what no rectangle covers.
        Near the top, every way to cut (bands along y or x, strict bands, or only at the rectangles that span
        the box) is tried and the one that folds shortest kept; deeper, floors alternate with tiles. Where no band
        structure exists (a pinwheel), cut where the fewest rectangles are crossed, as `decompose` does."""
        rects = _grow(rects, box, self.tol)
        x0, y0, x1, y1 = box
        if len(rects) == 0:
            return _Tree("leaf", label=FACADE)
        inner = ((rects[:, 1] > x0) | (rects[:, 3] < x1) | (rects[:, 2] > y0) | (rects[:, 4] < y1)).any()
        if not inner or depth > 48:  # one rectangle fills the box (or several, overlapping after snapping)
            area = (rects[:, 3] - rects[:, 1]) * (rects[:, 4] - rects[:, 2])
            return _Tree("leaf", label=int(rects[np.argmax(area), 0]))
        options = []
        for axis in (("y", "x") if prefer_y else ("x", "y")):
            lo_col, hi_col, lo, hi = (2, 4, y0, y1) if axis == "y" else (1, 3, x0, x1)
            snapped, bands = _overlap_groups(rects, lo_col, hi_col, self.tol)
            if len(bands) > 1 or (bands[0][0], bands[0][1]) != (lo, hi):
                options.append((axis, snapped, bands))
        if depth < self.lookahead:
            for axis in ("y", "x"):
                spans = _spanning(rects, box, axis)
                if spans is not None and len(spans[1]) > 1:
                    options.append((axis, *spans))
                # strict bands (no tolerance) keep rows that overlap at all together: the wings of a building
                # whose floors do not line up stay whole, to be told apart one level down
                lo_col, hi_col, lo, hi = (2, 4, y0, y1) if axis == "y" else (1, 3, x0, x1)
                strict = _overlap_groups(rects, lo_col, hi_col, 0.0)
                if 1 < len(strict[1]) < len(next((o[2] for o in options if o[0] == axis), [])):
                    options.append((axis, *strict))
        if not options:
            axis, lo_col, hi_col, lo, hi, cut = least_crossed_cut(rects, box)
            options.append((axis, *_overlap_groups(cut_rects(rects, [cut], lo_col, hi_col), lo_col, hi_col, 0.0)))
        if depth >= self.lookahead or len(options) == 1:
            return self._split(box, depth, *options[0])
        trees = [self._split(box, depth, *o) for o in options]
        return min(trees, key=lambda t: t.size)  # the first (preferred) one on a tie

    def _split(self, box: tuple[int, int, int, int], depth: int, axis: str, rects: np.ndarray, bands: list) -> _Tree:
        x0, y0, x1, y1 = box
        lo, hi = (y0, y1) if axis == "y" else (x0, x1)
        lengths: list[float] = []
        children: list[_Tree] = []
        pos = lo
        for a, b, idx in bands:
            for start, stop, members in ((pos, a, None), (a, b, idx)):
                if stop <= start:
                    continue
                if members is None:
                    child = _Tree("leaf", label=FACADE)
                else:
                    sub = (x0, start, x1, stop) if axis == "y" else (start, y0, stop, y1)
                    child = self.cut(rects[members], sub, axis == "x", depth + 1)
                if child.rule == "split" and child.axis == axis:
                    lengths.extend(child.lengths)
                    children.extend(child.children)
                else:
                    lengths.append(float(stop - start))
                    children.append(child)
            pos = b
        if pos < hi:
            lengths.append(float(hi - pos))
            children.append(_Tree("leaf", label=FACADE))
        return _fold(axis, lengths, children, self.tolerance, self.min_px)


def _close(a: float, b: float, tol: float, px: float) -> bool:
    return abs(a - b) <= max(px, tol * max(a, b))


def _similar(a: tuple[float, _Tree], b: tuple[float, _Tree], tol: float, px: float) -> bool:
    """Same shape and every length (the node's own and all inside it) within the tolerance."""
    if a[1].key != b[1].key or not _close(a[0], b[0], tol, px):
        return False
    stack = [(a[1], b[1])]
    while stack:
        u, v = stack.pop()
        if any(not _close(p, q, tol, px) for p, q in zip(u.lengths, v.lengths, strict=True)):
            return False
        stack.extend(zip(u.children, v.children, strict=True))
    return True


def _average(nodes: list[_Tree]) -> _Tree:
    """One node of the common shape whose every length is the mean of the nodes' lengths."""
    first = nodes[0]
    if first.rule == "leaf":
        return first
    lengths = np.mean([n.lengths for n in nodes], axis=0).tolist()
    children = [_average([n.children[i] for n in nodes]) for i in range(len(first.children))]
    return _Tree(first.rule, axis=first.axis, lengths=lengths, children=children, count=first.count,
                 tail=first.tail)


def _best_run(items: list[tuple[float, _Tree]], i: int, tol: float, px: float) -> tuple[int, int, int, int] | None:
    """(covered, period, repeats, tail) of the longest periodic run starting at item ``i``, or None."""
    best = None
    n = len(items)
    for p in (1, 2, 3, 4):
        reps = 1
        while (reps < MAX_COUNT and i + (reps + 1) * p <= n
               and all(_similar(items[i + j], items[i + reps * p + j], tol, px) for j in range(p))):
            reps += 1
        if reps < 2:
            continue
        t = 0
        while t < p - 1 and i + reps * p + t < n and _similar(items[i + t], items[i + reps * p + t], tol, px):
            t += 1
        if best is None or reps * p + t > best[0]:
            best = (reps * p + t, p, reps, t)
    return best


def _fold(axis: str, lengths: list[float], children: list[_Tree], tol: float, px: float) -> _Tree:
    """A split whose runs of similar children (already folded themselves) become repeats."""
    items = list(zip(lengths, children, strict=True))
    out: list[tuple[float, _Tree]] = []
    i = 0
    while i < len(items):
        run = _best_run(items, i, tol, px)
        if run is None:
            out.append(items[i])
            i += 1
            continue
        covered, p, reps, t = run
        part = items[i : i + covered]
        groups = [part[j::p] for j in range(p)]  # pattern position j: its copies, the tail's included
        repeat = _Tree("repeat", axis=axis, lengths=[float(np.mean([g[0] for g in grp])) for grp in groups],
                       children=[_average([g[1] for g in grp]) for grp in groups], count=reps, tail=t)
        out.append((float(sum(length for length, _ in part)), repeat))
        i += covered
    if len(out) == 1:
        return out[0][1]
    return _Tree("split", axis=axis, lengths=[length for length, _ in out], children=[c for _, c in out])


def _node(tree: _Tree) -> Node:
    if tree.rule == "leaf":
        return Node.leaf(LABELS[tree.label])
    children = [_node(c) for c in tree.children]
    if tree.rule == "repeat":
        role = "floors" if tree.axis == "y" else "bay"
        for c in children:
            if not c.is_leaf or c.label not in ("facade", "background"):
                c.role = c.role or ("floor" if tree.axis == "y" else "tile")
        return Node.repeat(tree.axis, tree.count, [(Size("abs", v), c) for v, c in
                                                   zip(tree.lengths, children, strict=True)],
                           tail=tree.tail, role=role)
    lengths = [int(round(v)) for v in tree.lengths]
    # one child floats, so that a resized facade grows there: the largest repeat (which then lays out more
    # copies), else the largest wall piece, else the largest background piece (not the sky beside a wall)
    modes = ["abs"] * len(lengths)
    for kind in ("repeat", FACADE, BACKGROUND):
        found = [i for i, c in enumerate(tree.children)
                 if (c.rule == kind if kind == "repeat" else c.rule == "leaf" and c.label == kind)]
        if found:
            modes[max(found, key=lambda i: lengths[i])] = "flt"
            break
    items = [(Size(m, v), c) for m, v, c in zip(modes, tree.lengths, children, strict=True)]
    return chunked_split(tree.axis, items, lengths)


def induce_procedure(seg: Segmentation, *, snap: float = 0.01, tolerance: float = 0.15, min_px: float = 2.0,
                     lookahead: int = 2) -> Procedure | None:
    """A procedure with repeats for the (flattened) segmentation, or None where the grammar's limits (depth,
    nodes) are exceeded. Edges closer than ``snap`` x the longer side (at most a quarter of the element) are
    taken as aligned; siblings whose lengths agree within ``tolerance`` (or ``min_px``) fold into repeats; the
    top ``lookahead`` levels try every way to cut and keep the shortest. Chosen on generated facades, clean
    and jittered (bench/bench_induce.py)."""
    tol = max(1.0, snap * max(seg.width, seg.height))
    rects = partition(seg)
    rects = _clean(rects[rects[:, 0] != FACADE], tol)  # the wall is what the elements and background leave
    tree = _Inducer(tol, tolerance, min_px, lookahead).cut(rects, (0, 0, seg.width, seg.height), True)
    proc = Procedure(seg.width, seg.height, _node(tree), {"source": "facaid.reading.induce"})
    try:
        return Procedure.from_dict(proc.to_dict())
    except ProcedureError:
        return None
