"""Snapping an annotation's element edges to the medians of their clusters (one label, one edge, within a share of
the side): a try at restoring a hand's jitter before reading (notes.md, step 12)."""
import numpy as np

from facaid.labels import BACKGROUND, FACADE
from facaid.segmentation import Rect, Segmentation


def _clusters(values, spread):
    order = np.argsort(values, kind="stable")
    groups, cur = [], [order[0]]
    for i in order[1:]:
        if values[i] - values[cur[0]] > spread:
            groups.append(cur); cur = []
        cur.append(i)
    groups.append(cur)
    return groups

def snap(seg: Segmentation, share: float = 0.02, min_copies: int = 3) -> Segmentation:
    rects = [list(r) for r in seg.rects]
    idx_by_label = {}
    for k, r in enumerate(seg.rects):
        if r.label in (FACADE, BACKGROUND):
            continue
        idx_by_label.setdefault(r.label, []).append(k)
    for label, idx in idx_by_label.items():
        if len(idx) < min_copies:
            continue
        arr = np.array([rects[k] for k in idx], dtype=float)
        for col, side in ((1, seg.width), (3, seg.width), (2, seg.height), (4, seg.height)):
            # values of one edge; copies must also share the other edge of the axis loosely (same size class)
            vals = arr[:, col]
            for g in _clusters(vals, share * side):
                if len(g) >= min_copies:
                    m = float(np.median(vals[g]))
                    for i in g:
                        rects[idx[i]][col] = int(round(m))
    out = [Rect(*r) for r in rects if r[1] < r[3] and r[2] < r[4]]
    return Segmentation(seg.width, seg.height, tuple(out))
