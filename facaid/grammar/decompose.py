"""From a segmentation to an exact procedure by guillotine cuts: the grammar can express any label map.

`procedure_from_segmentation` cuts the image along full lines that cross no rectangle (alternating axes,
recursively), so that splits follow the facade's own structure: floors first, then tiles. Where no clean
cut exists (a pinwheel of rectangles, or hand-drawn edges that almost line up) it cuts once where the
fewest rectangles are crossed and cuts those. The result reproduces the flattened label map pixel for
pixel. It knows no repeats or mirrors: it is the direct fit that structured procedures are compared with,
not a substitute for them.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.procedure import MAX_CHILDREN, Node, Procedure, Size
from facaid.labels import BACKGROUND, FACADE, LABEL_ID, LABELS
from facaid.segmentation import Segmentation, _compressed_grid, _decompose


def _partition(seg: Segmentation) -> np.ndarray:
    """Canonical rectangles (label, x0, y0, x1, y1) covering the whole image, background included."""
    arr = seg.to_array()
    if len(arr) == 0:
        return np.array([[BACKGROUND, 0, 0, seg.width, seg.height]], dtype=np.int64)
    xs, ys, grid = _compressed_grid(seg.width, seg.height, arr)
    cells = _decompose(grid.astype(np.int64) + 1)  # + 1: background is kept as a rectangle too
    return np.stack([cells[:, 0] - 1, xs[cells[:, 1]], ys[cells[:, 2]], xs[cells[:, 3]], ys[cells[:, 4]]], axis=1)


def _cuts(rects: np.ndarray, lo_col: int, hi_col: int, lo: int, hi: int) -> list[int]:
    """Positions strictly inside (lo, hi) where a line along the other axis crosses no rectangle."""
    edges = np.unique(np.concatenate([rects[:, lo_col], rects[:, hi_col]]))
    edges = edges[(edges > lo) & (edges < hi)]
    if len(edges) == 0:
        return []
    starts, stops = rects[:, lo_col], rects[:, hi_col]
    crossed = ((starts[None, :] < edges[:, None]) & (stops[None, :] > edges[:, None])).any(axis=1)
    return edges[~crossed].tolist()


def _sizes(lengths: list[int], labels: list[int | None]) -> list[Size]:
    """Exact lengths; the largest wall or background piece floats so that resizing stretches it."""
    sizes = [Size("abs", float(v)) for v in lengths]
    walls = [i for i, lab in enumerate(labels) if lab in (FACADE, BACKGROUND)]
    if walls:
        i = max(walls, key=lambda k: lengths[k])
        sizes[i] = Size("flt", float(lengths[i]))
    return sizes


def _build(rects: np.ndarray, box: tuple[int, int, int, int], prefer_y: bool, depth: int = 0) -> Node:
    x0, y0, x1, y1 = box
    if len(rects) == 1:
        return Node.leaf(LABELS[int(rects[0, 0])])
    axes = ("y", "x") if prefer_y else ("x", "y")
    for axis in axes:
        lo_col, hi_col, lo, hi = (2, 4, y0, y1) if axis == "y" else (1, 3, x0, x1)
        cuts = _cuts(rects, lo_col, hi_col, lo, hi)
        if cuts:
            break
    else:  # no clean cut: cut once where the fewest rectangles are crossed, cutting those in two
        axis, lo_col, hi_col, lo, hi, cut = _least_crossed_cut(rects, box)
        cuts = [cut]
        rects = _cut_rects(rects, cuts, lo_col, hi_col)
    bounds = [lo, *cuts, hi]
    items: list[tuple[Size, Node]] = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        inside = rects[(rects[:, lo_col] >= a) & (rects[:, hi_col] <= b)]
        sub = (x0, a, x1, b) if axis == "y" else (a, y0, b, y1)
        child = _build(inside, sub, axis == "x", depth + 1)
        if child.rule == "split" and child.axis == axis:
            # same direction: splice its children in (every size here is its exact length)
            items.extend(zip(child.sizes, child.children, strict=True))
        else:
            items.append((Size("abs", float(b - a)), child))
    lengths = [int(size.value) for size, _ in items]
    labels = [LABEL_ID[child.label] if child.rule == "leaf" else None for _, child in items]
    return _chunked(axis, list(zip(_sizes(lengths, labels), [c for _, c in items], strict=True)), lengths)


def _chunked(axis: str, items: list[tuple[Size, Node]], lengths: list[int]) -> Node:
    """A split, nested in groups when it has more children than a node may hold."""
    if len(items) <= MAX_CHILDREN:
        return Node.split(axis, items)
    step = -(-len(items) // MAX_CHILDREN)  # ceil: at most MAX_CHILDREN groups
    groups = []
    for k in range(0, len(items), step):
        part = items[k : k + step]
        groups.append((Size("abs", float(sum(lengths[k : k + step]))),
                       part[0][1] if len(part) == 1 else Node.split(axis, part)))
    return _chunked(axis, groups, [int(g.value) for g, _ in groups])


def _least_crossed_cut(rects: np.ndarray, box: tuple[int, int, int, int]) -> tuple:
    best = None
    for axis, lo_col, hi_col, lo, hi in (("y", 2, 4, box[1], box[3]), ("x", 1, 3, box[0], box[2])):
        edges = np.unique(np.concatenate([rects[:, lo_col], rects[:, hi_col]]))
        edges = edges[(edges > lo) & (edges < hi)]
        crossed = ((rects[None, :, lo_col] < edges[:, None]) & (rects[None, :, hi_col] > edges[:, None])).sum(axis=1)
        for e, c in zip(edges.tolist(), crossed.tolist(), strict=True):
            key = (c, abs(2 * e - lo - hi) / (hi - lo))
            if best is None or key < best[0]:
                best = (key, (axis, lo_col, hi_col, lo, hi, e))
    return best[1]


def _cut_rects(rects: np.ndarray, cuts: list[int], lo_col: int, hi_col: int) -> np.ndarray:
    """Split every rectangle at the given positions along one axis."""
    out = []
    for r in rects.tolist():
        points = [r[lo_col], *[c for c in cuts if r[lo_col] < c < r[hi_col]], r[hi_col]]
        for a, b in zip(points[:-1], points[1:], strict=True):
            piece = list(r)
            piece[lo_col], piece[hi_col] = a, b
            out.append(piece)
    return np.array(out, dtype=np.int64)


def procedure_from_segmentation(seg: Segmentation) -> Procedure:
    """An exact procedure for the flattened segmentation: executing it gives back its label map."""
    rects = _partition(seg)
    root = _build(rects, (0, 0, seg.width, seg.height), prefer_y=True)
    return Procedure(seg.width, seg.height, root, {"source": "guillotine decomposition"})
