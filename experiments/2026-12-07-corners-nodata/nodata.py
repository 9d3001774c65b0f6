"""No-data regions of a photo: the pure black (or white) wedges an earlier rectification leaves at its edges, which
the corner proposal (`facaid.photo.rectify.propose_corners`) must neither follow nor take in.

A wedge is a region of almost pure black (white) touching the photo's edge and larger than a speck; its straight
border with the photo is a strong line that outvoted the facade's own, and the proposal took the photo's frame.
"""

from __future__ import annotations

import numpy as np

DARK, LIGHT = 8, 248  # luminance at most (at least) this is no data
SPECK = 0.002  # of the photo's area: a smaller region at the edge is a speck, not a wedge
NEAR = 3  # work pixels: a segment whose middle lies this near a wedge is its border
SHRINK = 0.01  # of the quadrilateral's side: how far a side moves in at a step, off a wedge
LEFT_IN = 0.002  # of the quadrilateral's area: the wedge it may still hold (JPEG's ringing at the border)
STEPS = 60


def nodata_mask(luma: np.ndarray) -> np.ndarray:
    """The no-data pixels of a photo's luminance (uint8, work size): the almost pure black or white regions that
    touch its edge, each larger than `SPECK` of it."""
    import cv2

    out = np.zeros(luma.shape, dtype=bool)
    for mask in (luma <= DARK, luma >= LIGHT):
        n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=4)
        edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
        for k in edge[edge > 0]:
            if stats[k, cv2.CC_STAT_AREA] >= SPECK * luma.size:
                out |= labels == k
    return out


def off_wedges(segments: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The segments (N, 5: x1, y1, x2, y2, length, work pixels) but those along a wedge's border: whose middle
    lies within `NEAR` pixels of no data."""
    if not mask.any() or not len(segments):
        return segments
    import cv2

    near = cv2.dilate(mask.astype(np.uint8), np.ones((2 * NEAR + 1, 2 * NEAR + 1), np.uint8)) > 0
    h, w = mask.shape
    mx = np.clip(((segments[:, 0] + segments[:, 2]) / 2).round().astype(int), 0, w - 1)
    my = np.clip(((segments[:, 1] + segments[:, 3]) / 2).round().astype(int), 0, h - 1)
    return segments[~near[my, mx]]


def clear_of(pts: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The quadrilateral ``pts`` (TL, TR, BR, BL, work pixels) with its sides moved in, one step at a time, the one
    nearest most of the no data it holds first, until it holds at most `LEFT_IN` of its area."""
    import cv2

    pts = pts.astype(float).copy()
    if not mask.any():
        return pts
    ys, xs = np.nonzero(mask)
    sides = ((0, 1, 3, 2), (1, 2, 0, 3), (2, 3, 1, 0), (3, 0, 2, 1))  # a side's ends, and the ends it moves to
    for _ in range(STEPS):
        inside = np.zeros(mask.shape, dtype=np.uint8)
        cv2.fillPoly(inside, [pts.round().astype(np.int32)], 1)
        held = inside[ys, xs] > 0
        if held.sum() <= LEFT_IN * max(1, inside.sum()):
            break
        px, py = xs[held], ys[held]
        counts = []
        for a, b, _, _ in sides:  # the held no data nearer this side than the others
            d = np.abs((pts[b, 0] - pts[a, 0]) * (pts[a, 1] - py) - (pts[a, 0] - px) * (pts[b, 1] - pts[a, 1]))
            counts.append(d / max(1e-9, np.hypot(*(pts[b] - pts[a]))))
        nearest = np.argmin(np.stack(counts), axis=0)
        a, b, ta, tb = sides[int(np.bincount(nearest, minlength=4).argmax())]
        pts[a] += SHRINK * (pts[ta] - pts[a])
        pts[b] += SHRINK * (pts[tb] - pts[b])
    return pts
