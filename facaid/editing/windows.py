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


def centre_bands(centres: np.ndarray, sizes: np.ndarray) -> int:
    """How many bands the centres make, split where neighbours are over half the median size apart."""
    if len(centres) == 0:
        return 0
    c = np.sort(centres)
    return int(1 + np.sum(np.diff(c) > 0.5 * np.median(sizes)))


def whole_windows(boxes: np.ndarray) -> np.ndarray:
    """The windows (boxes x0, y0, x1, y1) but the strips of one that a balcony or sill leaves uncovered: those under
    `STRIP` of the median window's height or width."""
    if not len(boxes):
        return boxes
    h, w = boxes[:, 3] - boxes[:, 1], boxes[:, 2] - boxes[:, 0]
    return boxes[(h >= STRIP * np.median(h)) & (w >= STRIP * np.median(w))]


def pitch(centres: np.ndarray, sizes: np.ndarray) -> float | None:
    """The median spacing of the bands of centres (each band at its median centre), None with fewer than 3 bands."""
    if len(centres) == 0:
        return None
    order = np.argsort(centres)
    c = centres[order]
    cuts = np.flatnonzero(np.diff(c) > 0.5 * np.median(sizes)) + 1
    middles = [float(np.median(band)) for band in np.split(c, cuts)]
    return float(np.median(np.diff(middles))) if len(middles) >= 3 else None


def pitches(rows: np.ndarray) -> tuple[float | None, float | None]:
    """(floor pitch, bay pitch): the median spacing of the window rows and of the window columns of a flattened
    segmentation's rows, each None with fewer than three."""
    w = whole_windows(window_boxes(rows))
    return (pitch((w[:, 1] + w[:, 3]) / 2, w[:, 3] - w[:, 1]), pitch((w[:, 0] + w[:, 2]) / 2, w[:, 2] - w[:, 0]))


def lattice(rows: np.ndarray, typical: bool = False) -> tuple[int, int]:
    """(window rows, window columns) of a flattened segmentation's rows. With ``typical``, a window over `WIDE` times
    the median window's height (width) counts in no row (column): a shop window three bays wide is no column."""
    w = window_boxes(rows)
    if len(w) == 0:
        return 0, 0
    h, wd = w[:, 3] - w[:, 1], w[:, 2] - w[:, 0]
    tall = h > WIDE * np.median(h) if typical else np.zeros(len(w), dtype=bool)
    wide = wd > WIDE * np.median(wd) if typical else np.zeros(len(w), dtype=bool)
    return (centre_bands(((w[:, 1] + w[:, 3]) / 2)[~tall], h[~tall]),
            centre_bands(((w[:, 0] + w[:, 2]) / 2)[~wide], wd[~wide]))


def segmentation_lattice(seg: Segmentation) -> tuple[int, int]:
    return lattice(flatten_array(seg.width, seg.height, seg.to_array()))


__all__ = ["centre_bands", "lattice", "pitch", "pitches", "segmentation_lattice", "whole_windows", "window_boxes"]
