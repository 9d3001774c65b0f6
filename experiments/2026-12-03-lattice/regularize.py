"""Regularize a hand-made segmentation: edges that almost line up are made to, before structure is read.

People draw each element on its own, so a row of windows has tops a few pixels apart, a blind misses its
window's edge by two pixels, and a sill is a little wider on one side. Flattening such a drawing into the
partition a split grammar needs cuts it into slivers, and no two floors or tiles come out the same shape, so
nothing folds into a repeat (experiments/2026-12-03-consensus-fold). `regularize` moves edges onto shared lines:

1. **Per class**: the tops of all windows (then their bottoms, lefts, rights; then the same for every other
   class) are clustered along their axis; an edge within ``snap`` x the image side of its cluster's median
   moves onto it. Rows of windows line up across the facade, columns top to bottom.
2. **Across classes**: every edge, of any class, within ``cross`` x the side of another joins its line, so a
   blind's edge meets its window's and no sliver is left between them.

An edge never moves by more than a quarter of its element's extent, and nothing is added or removed: the
result is the same drawing, tidied. The layered paint order is kept.
"""

from __future__ import annotations

import numpy as np

from facaid.labels import BACKGROUND, FACADE
from facaid.segmentation import Segmentation

# (low column, high column) of (label, x0, y0, x1, y1) rows, per axis
_COLUMNS = {"x": (1, 3), "y": (2, 4)}


def _clusters(values: np.ndarray, tol: float) -> list[np.ndarray]:
    """Indices of ``values`` grouped into runs whose neighbours (sorted) are at most ``tol`` apart and whose
    span stays within 2 x ``tol`` (a long chain is cut at its widest gap)."""
    order = np.argsort(values, kind="stable")
    runs: list[np.ndarray] = []
    start = 0
    for i in range(1, len(order) + 1):
        if i == len(order) or values[order[i]] - values[order[i - 1]] > tol:
            runs.append(order[start:i])
            start = i
    out: list[np.ndarray] = []
    while runs:
        run = runs.pop()
        v = values[run]
        if len(run) > 2 and v[-1] - v[0] > 2 * tol:
            cut = int(np.argmax(np.diff(v))) + 1
            runs.extend([run[:cut], run[cut:]])
        else:
            out.append(run)
    return out


def _snap(rows: np.ndarray, members: np.ndarray, tol: float) -> None:
    """Snap the edges named by ``members`` ((row, column) pairs) onto their clusters' medians, in place, where
    the move is within ``tol`` and a quarter of the element's extent along that axis."""
    if len(members) < 2:
        return
    values = rows[members[:, 0], members[:, 1]].astype(float)
    lo_col = np.where(members[:, 1] % 2 == 1, 1, 2)  # x edges are columns 1/3, y edges 2/4
    extent = rows[members[:, 0], lo_col + 2] - rows[members[:, 0], lo_col]
    for run in _clusters(values, tol):
        if len(run) < 2:
            continue
        target = int(round(float(np.median(values[run]))))
        move = np.abs(values[run] - target)
        ok = run[(move <= tol) & (move <= extent[run] / 4)]
        rows[members[ok, 0], members[ok, 1]] = target


def regularize(seg: Segmentation, *, snap: float = 0.012, cross: float = 0.005) -> Segmentation:
    """The segmentation with near-aligned edges aligned (see the module's docstring); degenerate results (an
    element squeezed to nothing) keep their original box."""
    rows = seg.to_array().copy()
    if len(rows) < 2:
        return seg
    elements = np.flatnonzero((rows[:, 0] != FACADE) & (rows[:, 0] != BACKGROUND))
    for axis, (lo, hi) in _COLUMNS.items():
        side = seg.width if axis == "x" else seg.height
        for label in np.unique(rows[elements, 0]):
            mine = elements[rows[elements, 0] == label]
            for col in (lo, hi):
                _snap(rows, np.stack([mine, np.full(len(mine), col)], axis=1), max(1.0, snap * side))
        every = np.concatenate([np.stack([elements, np.full(len(elements), col)], axis=1) for col in (lo, hi)])
        _snap(rows, every, max(1.0, cross * side))
    bad = (rows[:, 3] <= rows[:, 1]) | (rows[:, 4] <= rows[:, 2])
    rows[bad] = seg.to_array()[bad]
    return Segmentation.from_array(seg.width, seg.height, rows)
