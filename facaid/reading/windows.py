"""A facade's windows as a person counts them: connected window-or-blind regions (a window cut into pieces by its
blind or sill counts once), in rows and columns.

Window rows are the bands of window centres along y, split where the gap between neighbouring centres exceeds half
the median window height; columns the same along x with the width.
"""

from __future__ import annotations

import numpy as np

from facaid.labels import GLASS
from facaid.segmentation import Segmentation, flatten_array, region_boxes

WIDE = 2.0  # a window over this many times the median window's width (height) is in no column (row) of them
STRIP = 0.35  # a window region under this share of the median window's height or width is a strip of one


def window_boxes(rows: np.ndarray) -> np.ndarray:
    """The windows of a flattened segmentation's rows (N, 5: label, x0, y0, x1, y1; a partition of the label map):
    the bounding boxes (M, 4) of the connected regions of its window and blind pieces."""
    return region_boxes(rows, GLASS)


def centre_bands(centres: np.ndarray, sizes: np.ndarray) -> list[np.ndarray]:
    """The indices of ``centres`` grouped in bands, in order along the axis: split where neighbouring centres are
    over half the median size apart. The one band helper of the windows' rows and columns: counted here (`lattice`,
    `window_pitch`, the edit check) and read as floors and tiles (`facaid.reading.grid.window_bands`)."""
    if len(centres) == 0:
        return []
    order = np.argsort(centres, kind="stable")
    return np.split(order, np.flatnonzero(np.diff(centres[order]) > 0.5 * np.median(sizes)) + 1)


def whole_windows(boxes: np.ndarray) -> np.ndarray:
    """The windows (boxes x0, y0, x1, y1) but the strips of one that a balcony or sill leaves uncovered: those under
    `STRIP` of the median window's height or width."""
    if not len(boxes):
        return boxes
    h, w = boxes[:, 3] - boxes[:, 1], boxes[:, 2] - boxes[:, 0]
    return boxes[(h >= STRIP * np.median(h)) & (w >= STRIP * np.median(w))]


def window_pitch(windows: np.ndarray, axis: str) -> float | None:
    """The pitch of ``windows`` (boxes x0, y0, x1, y1) along ``axis`` ("y": the floors', "x": the bays'): the median
    distance from a window's centre to the nearest one's beyond it in its column ("y") or row ("x": overlapping it
    across the axis by half the narrower one at least). A person measures a floor from a window to the one above
    it: the rows of two buildings of different floors beside each other, or a dormer over a column, are no pitch
    of either. None where the windows make fewer than three rows (columns) or fewer than two such pairs."""
    lo, hi, across_lo, across_hi = (1, 3, 0, 2) if axis == "y" else (0, 2, 1, 3)
    if len(windows) == 0:
        return None
    centres, sizes = (windows[:, lo] + windows[:, hi]) / 2, windows[:, hi] - windows[:, lo]
    if len(centre_bands(centres, sizes)) < 3:
        return None
    across = windows[:, across_hi] - windows[:, across_lo]
    steps = []
    for i in range(len(windows)):
        overlap = np.minimum(windows[:, across_hi], windows[i, across_hi]) - np.maximum(windows[:, across_lo],
                                                                                       windows[i, across_lo])
        beyond = (overlap >= 0.5 * np.minimum(across, across[i])) & (centres > centres[i] + 0.5 * sizes[i])
        if beyond.any():
            steps.append(float((centres[beyond] - centres[i]).min()))
    return float(np.median(steps)) if len(steps) >= 2 else None


def pitches(rows: np.ndarray) -> tuple[float | None, float | None]:
    """(floor pitch, bay pitch) of a flattened segmentation's rows: `window_pitch` of its whole windows along y and
    x."""
    w = whole_windows(window_boxes(rows))
    return window_pitch(w, "y"), window_pitch(w, "x")


def lattice(rows: np.ndarray, typical: bool = False) -> tuple[int, int]:
    """(window rows, window columns) of a flattened segmentation's rows. With ``typical``, a window over `WIDE` times
    the median window's height (width) counts in no row (column): a shop window three bays wide is no column."""
    w = window_boxes(rows)
    if len(w) == 0:
        return 0, 0
    h, wd = w[:, 3] - w[:, 1], w[:, 2] - w[:, 0]
    tall = h > WIDE * np.median(h) if typical else np.zeros(len(w), dtype=bool)
    wide = wd > WIDE * np.median(wd) if typical else np.zeros(len(w), dtype=bool)
    return (len(centre_bands(((w[:, 1] + w[:, 3]) / 2)[~tall], h[~tall])),
            len(centre_bands(((w[:, 0] + w[:, 2]) / 2)[~wide], wd[~wide])))


def segmentation_lattice(seg: Segmentation) -> tuple[int, int]:
    return lattice(flatten_array(seg.width, seg.height, seg.to_array()))


__all__ = ["centre_bands", "lattice", "pitches", "window_pitch", "segmentation_lattice",
           "whole_windows", "window_boxes"]
