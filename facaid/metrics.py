"""Comparing label maps: pixel accuracy, per-class IoU, element counts, and cheap low-resolution rasterization."""

from __future__ import annotations

import math

import numpy as np

from facaid.grammar.execute import execute, to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.labels import BACKGROUND, FACADE, LABELS, PRIORITY
from facaid.segmentation import Segmentation, rasterize, region_roots


def pixel_accuracy(a: np.ndarray, b: np.ndarray) -> float:
    if a.shape != b.shape:
        raise ValueError(f"label maps differ in shape: {a.shape} vs {b.shape}")
    return float((a == b).mean())


def class_iou(a: np.ndarray, b: np.ndarray) -> dict[str, float]:
    """IoU per label present in either map."""
    out = {}
    for i, name in enumerate(LABELS):
        pa, pb = a == i, b == i
        union = int((pa | pb).sum())
        if union:
            out[name] = float((pa & pb).sum() / union)
    return out


def _regions(boxes: np.ndarray) -> int:
    """The number of connected regions of boxes (N, 4: x0, y0, x1, y1), as `region_roots` connects them."""
    return int(np.sum(region_roots(boxes) == np.arange(len(boxes))))


def element_counts(seg: Segmentation) -> np.ndarray:
    """How many elements of each class a segmentation shows: (len(LABELS),) int64, the connected regions of
    each element class's rectangles (`_regions`); the background and the wall count 0. Any cover of the same
    picture gives the same counts, so a flattened segmentation (pieces) counts like the rectangles the pieces
    came from."""
    return _row_counts(seg.to_array())


def element_counts_within(rows: np.ndarray, box: tuple[float, float, float, float]) -> np.ndarray:
    """`element_counts` of the rectangles ``rows`` (N, 5: label, x0, y0, x1, y1) whose centres lie in ``box``
    (x0, y0, x1, y1, half-open). Counting by centre, not clipping, keeps an element of the next region that a
    rough box edge grazes out of the count."""
    rows = np.asarray(rows, dtype=np.float64).reshape(-1, 5)
    cx, cy = (rows[:, 1] + rows[:, 3]) / 2, (rows[:, 2] + rows[:, 4]) / 2
    x0, y0, x1, y1 = box
    return _row_counts(rows[(cx >= x0) & (cx < x1) & (cy >= y0) & (cy < y1)])


def _row_counts(rows: np.ndarray) -> np.ndarray:
    out = np.zeros(len(LABELS), dtype=np.int64)
    rows = rows[(rows[:, 3] > rows[:, 1]) & (rows[:, 4] > rows[:, 2])]  # empty leaves show nothing
    for label in np.unique(rows[:, 0]).astype(int):
        if label not in (BACKGROUND, FACADE):
            out[label] = _regions(rows[rows[:, 0] == label, 1:])
    return out


def cell_span(lo: float, hi: float, scale: float) -> tuple[int, int]:
    """The cells j with lo <= (j + 0.5) / scale < hi, as [start, stop): those whose centres a span covers, as
    `_paint` samples them (start may be negative)."""
    return math.ceil(lo * scale - 0.5), math.ceil(hi * scale - 0.5)


def _paint(rows: list[tuple[int, float, float, float, float]], width: int, height: int, scale: float) -> np.ndarray:
    """Point-sample the label map at the centres of a (height*scale, width*scale) grid: a cell takes the label
    of the full-size pixel under its centre, so any scale samples the same picture consistently."""
    w, h = max(1, round(width * scale)), max(1, round(height * scale))
    sx, sy = w / width, h / height
    out = np.zeros((h, w), dtype=np.uint8)
    for lab, x0, y0, x1, y1 in sorted(rows, key=lambda r: PRIORITY[r[0]]):
        a, b = cell_span(x0, x1, sx)
        c, d = cell_span(y0, y1, sy)
        if a < b and c < d:
            out[max(c, 0) : d, max(a, 0) : b] = lab
    return out


def scaled_label_map(seg: Segmentation, scale: float) -> np.ndarray:
    """The segmentation's label map at ``scale`` (e.g. 0.25), painted in the paint order."""
    return _paint(list(seg.rects), seg.width, seg.height, scale)


def scaled_procedure_map(proc: Procedure, scale: float,
                         leaves: list[tuple[int, float, float, float, float]] | None = None) -> np.ndarray:
    """The executed procedure's label map at ``scale`` (``leaves``: its `execute` output, when at hand)."""
    return _paint(execute(proc) if leaves is None else leaves, round(proc.width), round(proc.height), scale)


def procedure_accuracy(proc: Procedure, target: Segmentation) -> float:
    """Exact pixel accuracy at full resolution of the executed procedure against a segmentation."""
    return pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(target))


def procedure_iou(proc: Procedure, target: Segmentation) -> dict[str, float]:
    return class_iou(rasterize(to_segmentation(proc)), rasterize(target))


def confusion(a: np.ndarray, b: np.ndarray, block: int = 1 << 20) -> np.ndarray:
    """The (L, L) counts of pixels labelled i in ``a`` and j in ``b`` (two label maps of one shape), counted
    about ``block`` pixels at a time, so that the temporaries stay a few MB whatever the maps' size."""
    if a.shape != b.shape:
        raise ValueError(f"label maps differ in shape: {a.shape} vs {b.shape}")
    n = len(LABELS)
    flat_a, flat_b = a.reshape(-1), b.reshape(-1)
    out = np.zeros(n * n, dtype=np.int64)
    for start in range(0, flat_a.size, block):
        pair = flat_a[start : start + block].astype(np.int64) * n + flat_b[start : start + block]
        out += np.bincount(pair, minlength=n * n)
    return out.reshape(n, n)


def measure(proc: Procedure, target: Segmentation) -> tuple[float, dict[str, float]]:
    """`procedure_accuracy` and `procedure_iou` together, from one rasterization of each map and their
    `confusion`: the same figures for about half the memory."""
    counts = confusion(rasterize(to_segmentation(proc)), rasterize(target))
    total, hits = int(counts.sum()), np.diag(counts)
    unions = counts.sum(axis=0) + counts.sum(axis=1) - hits
    iou = {name: float(hits[i] / unions[i]) for i, name in enumerate(LABELS) if unions[i]}
    return (float(hits.sum() / total) if total else float("nan")), iou


def element_rectangles(seg: Segmentation) -> int:
    """The elements of an annotation: its rectangles of a class other than wall and background."""
    return sum(1 for r in seg.rects if r.label not in (BACKGROUND, FACADE))


def element_leaves(proc: Procedure) -> int:
    """The element leaves a person writes and edits: leaf nodes of the tree (not their copies under repeats and
    mirrors) of a class other than wall and background."""
    return sum(1 for _, node in proc.root.walk() if node.rule == "leaf" and node.label not in ("background", "facade"))


def compression(proc: Procedure, seg: Segmentation) -> float:
    """Element rectangles of the input per element leaf of the procedure: how much the procedure says with repeats
    and mirrors (a flat list of the input's rectangles is about 1; a repeat of 8 windows counts one leaf). 1 when
    both are empty, infinity for elements and no element leaf."""
    n, leaves = element_rectangles(seg), element_leaves(proc)
    if leaves == 0:
        return 1.0 if n == 0 else float("inf")
    return n / leaves


def _grow(mask: np.ndarray, r: int, axis: int) -> np.ndarray:
    """``mask`` grown by ``r`` pixels both ways along ``axis`` (a running box sum)."""
    pad = [(r + 1, r) if a == axis else (0, 0) for a in range(2)]
    c = np.cumsum(np.pad(mask.astype(np.int32), pad), axis=axis)
    n = mask.shape[axis]
    return (np.take(c, np.arange(2 * r + 1, 2 * r + 1 + n), axis=axis) - np.take(c, np.arange(n), axis=axis)) > 0


def appears(label_map: np.ndarray, label: int, box: tuple[int, int, int, int], area: int,
            share: float = 0.5) -> bool:
    """Whether ``label_map`` paints ``label`` on at least ``share`` of ``area`` pixels within ``box`` (x0, y0, x1,
    y1: an element's) or off it by up to half its thinner side: a 3 px sill drawn 2 px lower is there."""
    x0, y0, x1, y1 = box
    height, width = label_map.shape
    r = max(1, (min(x1 - x0, y1 - y0) + 1) // 2)
    near = label_map[max(0, y0 - r) : min(height, y1 + r), max(0, x0 - r) : min(width, x1 + r)]
    return bool((near == label).sum() >= share * area)


def near_edges(label_map: np.ndarray, rx: int, ry: int) -> np.ndarray:
    """The pixels of a label map within ``rx`` (along x) and ``ry`` (along y) of an edge between two labels: where a
    hand-drawn edge may be off by that much."""
    border = np.zeros(label_map.shape, dtype=bool)
    across, down = label_map[:, 1:] != label_map[:, :-1], label_map[1:, :] != label_map[:-1, :]
    border[:, 1:] |= across
    border[:, :-1] |= across
    border[1:, :] |= down
    border[:-1, :] |= down
    return _grow(_grow(border, rx, 1), ry, 0)


def unexplained(pred: np.ndarray, given: np.ndarray, edge: float = 0.01) -> float:
    """The share of the image where the label map ``pred`` disagrees with ``given`` farther than ``edge`` x the
    image's width (along x) or height (along y) from every edge of ``given``: disagreement that edges moved by an
    annotator's hand cannot explain — whole elements missing, added or misplaced."""
    h, w = given.shape
    band = near_edges(given, max(1, round(edge * w)), max(1, round(edge * h)))
    return float(((pred != given) & ~band).mean())
