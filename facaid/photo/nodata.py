"""No-data regions of a photo: the pure black, white or grey wedges an earlier rectification leaves at its edges, which
the corner proposal (`facaid.photo.corners.propose_corners`) must neither follow nor take in.

A wedge is a region of almost pure black or white, or of one flat grey (some tools fill with grey), that touches
the photo's edge, larger than a speck, nearly convex (its edges are straight: a ragged skyline is not one) and
uniform (a smooth sky's gradient is not one). Its straight border with the photo is a strong line that outvotes the
facade's own, so the segments along it are dropped where it is slanted (`off_wedges`); and the proposal is moved off
it as a rectangle of the facade's plane (`clear_of`), so that rectifying from it crops the facade and never skews it.
"""

from __future__ import annotations

import numpy as np

DARK, LIGHT = 8, 248  # luminance at most (at least) this is no data
FLAT = 1  # or a region whose every pixel's 3 x 3 neighbourhood spans at most this many grey levels
SPECK = 0.002  # of the photo's area: a smaller region at the edge is a speck, not a wedge
MOST = 0.5  # a photo more black (white) than this is a dark (bright) picture, not one with wedges
SOLID = 0.9  # a wedge fills at least this share of its convex hull (its edges are straight)
UNIFORM = 2.0  # ... and its grey levels spread by at most this (standard deviation): a smooth sky's gradient is more
AXIS_DEG = 2.0  # a segment this near horizontal or vertical along a wedge may be the facade's own line
NEAR = 3  # work pixels: a segment whose middle lies this near a wedge is its border
LEFT_IN = 0.002  # of the quadrilateral's area: the no data it may still hold (JPEG's ringing at the border)
GRID = 200  # cells a side of the facade's plane that the proposal is cleared on


def nodata_mask(luma: np.ndarray) -> np.ndarray:
    """The no-data pixels of a photo's luminance (uint8): its wedges (see the module's docstring)."""
    import cv2

    out = np.zeros(luma.shape, dtype=bool)
    square = np.ones((3, 3), np.uint8)
    flat = (cv2.dilate(luma, square).astype(int) - cv2.erode(luma, square)) <= FLAT
    for mask in (luma <= DARK, luma >= LIGHT, flat):
        n, labels, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=4)
        edge = np.unique(np.concatenate([labels[0], labels[-1], labels[:, 0], labels[:, -1]]))
        for k in edge[edge > 0]:
            if stats[k, cv2.CC_STAT_AREA] < SPECK * luma.size:
                continue
            region = labels == k
            ys, xs = np.nonzero(region)
            hull = cv2.convexHull(np.stack([xs, ys], axis=1).astype(np.int32))
            hull_area = cv2.contourArea(hull) + cv2.arcLength(hull, True) / 2
            solid = stats[k, cv2.CC_STAT_AREA] >= SOLID * max(1.0, hull_area)
            if solid and float(luma[region].std()) <= UNIFORM:
                out |= region
    return out if out.mean() <= MOST else np.zeros(luma.shape, dtype=bool)


def off_wedges(segments: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """The segments (N, 5: x1, y1, x2, y2, length, in the mask's pixels) but those along a wedge's slanted border:
    whose middle lies within `NEAR` pixels of no data. A segment within `AXIS_DEG` of the photo's axes stays: the
    straight roofline under a blown-out sky is the facade's own line, and an earlier rectification's wedges are
    slanted."""
    if not mask.any() or not len(segments):
        return segments
    near = _grown(mask, NEAR)
    h, w = mask.shape
    mx = np.clip(((segments[:, 0] + segments[:, 2]) / 2).round().astype(int), 0, w - 1)
    my = np.clip(((segments[:, 1] + segments[:, 3]) / 2).round().astype(int), 0, h - 1)
    angle = np.degrees(np.arctan2(np.abs(segments[:, 3] - segments[:, 1]), np.abs(segments[:, 2] - segments[:, 0])))
    upright = (angle <= AXIS_DEG) | (angle >= 90 - AXIS_DEG)
    return segments[~near[my, mx] | upright]


def held(pts: np.ndarray, mask: np.ndarray) -> float:
    """The share of the quadrilateral ``pts`` (TL, TR, BR, BL, in the mask's pixels) that is no data."""
    import cv2

    inside = np.zeros(mask.shape, dtype=np.uint8)
    cv2.fillPoly(inside, [pts.round().astype(np.int32)], 1)
    area = int(inside.sum())
    return float((inside.astype(bool) & mask).sum() / area) if area else 0.0


def clear_of(pts: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """The quadrilateral ``pts`` (TL, TR, BR, BL, in the mask's pixels) moved off the no data, as a rectangle of the
    facade's own plane: in the frame where ``pts`` is the unit square (`GRID` cells a side), the largest rectangle
    of cells that holds none (`largest_clear`). So a thin wedge along the top takes the top down by its own height,
    a wedge at a corner takes in whichever of its two sides leaves more, and the proposal stays the facade's
    rectangle: rectified from it, the facade is only cropped, never skewed. With the share of ``pts`` that the
    rectangle leaves out (0 where it holds no data): the caller says how much, for a wedge deep in the facade takes a
    part of it along."""
    import cv2

    pts = pts.astype(np.float32)
    if not mask.any():
        return pts.astype(float), 0.0
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    to_photo = cv2.getPerspectiveTransform(square, pts)
    centres = (np.arange(GRID, dtype=np.float32) + 0.5) / GRID
    u, v = np.meshgrid(centres, centres)
    where = cv2.perspectiveTransform(np.stack([u, v], axis=-1).reshape(-1, 1, 2), to_photo).reshape(GRID, GRID, 2)
    h, w = mask.shape
    bad = mask[np.clip(where[..., 1].round().astype(int), 0, h - 1), np.clip(where[..., 0].round().astype(int), 0,
                                                                              w - 1)]
    if bad.sum() <= LEFT_IN * GRID * GRID:
        return pts.astype(float), 0.0
    top, bottom, left, right = max(largest_clear(bad), _shrunk(bad), key=lambda r: (r[1] - r[0]) * (r[3] - r[2]))
    rect = np.array([[left, top], [right, top], [right, bottom], [left, bottom]], np.float32) / GRID
    lost = 1.0 - (bottom - top) * (right - left) / (GRID * GRID)
    return cv2.perspectiveTransform(rect.reshape(-1, 1, 2), to_photo).reshape(4, 2).astype(float), lost


def _shrunk(bad: np.ndarray) -> tuple[int, int, int, int]:
    """(top, bottom, left, right): ``bad``'s grid with a side at a time moved in, the one whose next line is the most
    bad, until at most `LEFT_IN` of the rest is (a sliver of JPEG's ringing along a side costs no strip of the
    facade, as the exact `largest_clear` would make it)."""
    top, bottom, left, right = 0, bad.shape[0], 0, bad.shape[1]
    while bottom - top > 1 and right - left > 1 and bad[top:bottom, left:right].sum() > LEFT_IN * (bottom - top) * (
            right - left):
        cut = {"top": bad[top, left:right].mean(), "bottom": bad[bottom - 1, left:right].mean(),
               "left": bad[top:bottom, left].mean(), "right": bad[top:bottom, right - 1].mean()}
        side = max(cut, key=cut.get)
        top, bottom = top + (side == "top"), bottom - (side == "bottom")
        left, right = left + (side == "left"), right - (side == "right")
    return top, bottom, left, right


def largest_clear(bad: np.ndarray) -> tuple[int, int, int, int]:
    """(top, bottom, left, right), ends exclusive: the rectangle of the most cells of ``bad`` (a boolean grid)
    that are all False, by the largest rectangle under each row's histogram of clear cells above it (a stack of
    rising bars); the whole grid's top row where every cell is bad."""
    rows, cols = bad.shape
    above = np.zeros(cols + 1, dtype=int)  # clear cells in a run ending at this row; a sentinel 0 at the end
    best, out = 0, (0, 1, 0, cols)
    for r in range(rows):
        above[:cols] = np.where(bad[r], 0, above[:cols] + 1)
        stack: list[int] = []
        for c in range(cols + 1):
            while stack and above[stack[-1]] >= above[c]:
                height = int(above[stack.pop()])
                start = stack[-1] + 1 if stack else 0
                if height * (c - start) > best:
                    best, out = height * (c - start), (r + 1 - height, r + 1, start, c)
            stack.append(c)
    return out


def data_edges(nodata: np.ndarray, box) -> tuple[float, float, float, float]:
    """How far out from ``box`` (x0, y0, x1, y1, work pixels) the photo's data reaches on each side, across the
    box's span: to the nearest line beyond it that is mostly no data, else to the photo's edge."""
    h, w = nodata.shape
    x0, y0, x1, y1 = (int(np.clip(round(v), 0, m)) for v, m in zip(box, (w, h, w, h), strict=True))
    rows, cols = slice(y0, max(y0 + 1, y1)), slice(x0, max(x0 + 1, x1))
    left = np.flatnonzero(nodata[rows, :x0].mean(axis=0) > 0.5)
    top = np.flatnonzero(nodata[:y0, cols].mean(axis=1) > 0.5)
    right = np.flatnonzero(nodata[rows, x1:].mean(axis=0) > 0.5)
    bottom = np.flatnonzero(nodata[y1:, cols].mean(axis=1) > 0.5)
    return (float(left.max() + 1) if len(left) else 0.0, float(top.max() + 1) if len(top) else 0.0,
            float(x1 + right.min()) if len(right) else float(w), float(y1 + bottom.min()) if len(bottom) else float(h))


def _grown(mask: np.ndarray, by: int) -> np.ndarray:
    import cv2

    return cv2.dilate(mask.astype(np.uint8), np.ones((2 * by + 1, 2 * by + 1), np.uint8)) > 0


__all__ = ["clear_of", "data_edges", "held", "largest_clear", "nodata_mask", "off_wedges"]
