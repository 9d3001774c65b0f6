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

from facaid.grammar.guillotine import chunked_split, clean_cuts, cut_rects, least_crossed_cut, partition
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import BACKGROUND, FACADE, LABEL_ID, LABELS
from facaid.segmentation import Segmentation, decompose_grid


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
        cuts = clean_cuts(rects, lo_col, hi_col, lo, hi)
        if cuts:
            break
    else:  # no clean cut: cut once where the fewest rectangles are crossed, cutting those in two
        axis, lo_col, hi_col, lo, hi, cut = least_crossed_cut(rects, box)
        cuts = [cut]
        rects = cut_rects(rects, cuts, lo_col, hi_col)
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
    return chunked_split(axis, list(zip(_sizes(lengths, labels), [c for _, c in items], strict=True)), lengths)


def procedure_from_segmentation(seg: Segmentation) -> Procedure:
    """An exact procedure for the flattened segmentation: executing it gives back its label map."""
    rects = partition(seg)
    root = _build(rects, (0, 0, seg.width, seg.height), prefer_y=True)
    return Procedure(seg.width, seg.height, root, {"source": "guillotine decomposition"})


def tree_of_label_map(label_map: np.ndarray, prefer_y: bool = True) -> Node:
    """The exact tree of a label map (H, W) of label ids, background included: executing it on a W x H region
    paints the map back, pixel for pixel."""
    h, w = label_map.shape
    rects = decompose_grid(label_map.astype(np.int64) + 1)  # + 1: background is kept as a rectangle too
    rects[:, 0] -= 1
    return _build(rects, (0, 0, w, h), prefer_y)
