"""Guillotine cuts: cutting a set of rectangles into two groups along a full line, the operation behind the exact
decomposition (`facaid.grammar.decompose`), the induced structures (`facaid.reading.induce`) and the sizing optimizer's
starting partition (`facaid.sizing`).

Rectangles are int64 rows ``(label, x0, y0, x1, y1)``; an axis is addressed by the columns of its low and high
edges (``lo_col``, ``hi_col``: 1 and 3 for x, 2 and 4 for y).
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import MAX_CHILDREN
from facaid.labels import BACKGROUND
from facaid.segmentation import Segmentation, compressed_grid, decompose_grid


def partition(seg: Segmentation) -> np.ndarray:
    """Canonical rectangles (label, x0, y0, x1, y1) covering the whole image, background included."""
    arr = seg.to_array()
    if len(arr) == 0:
        return np.array([[BACKGROUND, 0, 0, seg.width, seg.height]], dtype=np.int64)
    xs, ys, grid = compressed_grid(seg.width, seg.height, arr)
    cells = decompose_grid(grid.astype(np.int64) + 1)  # + 1: background is kept as a rectangle too
    return np.stack([cells[:, 0] - 1, xs[cells[:, 1]], ys[cells[:, 2]], xs[cells[:, 3]], ys[cells[:, 4]]], axis=1)


def clean_cuts(rects: np.ndarray, lo_col: int, hi_col: int, lo: int, hi: int) -> list[int]:
    """Positions strictly inside (lo, hi) where a line along the other axis crosses no rectangle."""
    edges = np.unique(np.concatenate([rects[:, lo_col], rects[:, hi_col]]))
    edges = edges[(edges > lo) & (edges < hi)]
    if len(edges) == 0:
        return []
    starts, stops = rects[:, lo_col], rects[:, hi_col]
    crossed = ((starts[None, :] < edges[:, None]) & (stops[None, :] > edges[:, None])).any(axis=1)
    return edges[~crossed].tolist()


def least_crossed_cut(rects: np.ndarray, box: tuple[int, int, int, int]) -> tuple:
    """Where no clean cut exists: the line crossing the fewest rectangles, nearest the middle on a tie, as
    ``(axis, lo_col, hi_col, lo, hi, position)``."""
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


def cut_rects(rects: np.ndarray, cuts: list[int], lo_col: int, hi_col: int) -> np.ndarray:
    """Split every rectangle at the given positions along one axis."""
    out = []
    for r in rects.tolist():
        points = [r[lo_col], *[c for c in cuts if r[lo_col] < c < r[hi_col]], r[hi_col]]
        for a, b in zip(points[:-1], points[1:], strict=True):
            piece = list(r)
            piece[lo_col], piece[hi_col] = a, b
            out.append(piece)
    return np.array(out, dtype=np.int64)


def chunked_split(axis: str, items: list[tuple[Size, Node]], lengths: list[int]) -> Node:
    """A split, nested in groups when it has more children than a node may hold."""
    if len(items) <= MAX_CHILDREN:
        return Node.split(axis, items)
    step = -(-len(items) // MAX_CHILDREN)  # ceil: at most MAX_CHILDREN groups
    groups = []
    for k in range(0, len(items), step):
        part = items[k : k + step]
        groups.append((Size("abs", float(sum(lengths[k : k + step]))),
                       part[0][1] if len(part) == 1 else Node.split(axis, part)))
    return chunked_split(axis, groups, [int(g.value) for g, _ in groups])
