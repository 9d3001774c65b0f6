"""The kinds of element drawn (one class, about one size), the pitch of a row or column of them, and in words what
completion tried with them (`facaid.completion`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facaid.labels import LABELS
from facaid.segmentation import aligned_lines

SIZE_TOLERANCE = 0.2  # elements of one class whose width and height agree within this share are one type
MIN_GAPS = 2  # a pitch is measured from at least this many gaps that agree
PITCH_TOLERANCE = 0.1  # the gaps of a row (column) agree within this share of the smallest, or it has no pitch


@dataclass
class Kind:
    """Drawn elements of one class and about one size (within `SIZE_TOLERANCE`): the tall windows, the small attic
    windows, the sills."""

    label: int
    boxes: np.ndarray  # (n, 4) float x0, y0, x1, y1 of the drawn elements
    width: float
    height: float


def kinds(rows: np.ndarray) -> list[Kind]:
    """Drawn elements grouped by class and size, the biggest first within a class."""
    out: list[Kind] = []
    for label in np.unique(rows[:, 0]).tolist():
        boxes = rows[rows[:, 0] == label, 1:].astype(float)
        area = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
        groups: list[list[int]] = []
        sizes = np.zeros((0, 2))  # each group's first (largest) member's width and height
        for i in np.argsort(-area, kind="stable").tolist():
            w, h = boxes[i, 2] - boxes[i, 0], boxes[i, 3] - boxes[i, 1]
            fits = np.flatnonzero((np.abs(w - sizes[:, 0]) <= SIZE_TOLERANCE * sizes[:, 0])
                                  & (np.abs(h - sizes[:, 1]) <= SIZE_TOLERANCE * sizes[:, 1]))
            if len(fits):
                groups[fits[0]].append(i)
            else:
                groups.append([i])
                sizes = np.vstack([sizes, [w, h]])
        for g in groups:
            b = boxes[g]
            out.append(Kind(int(label), b, float(np.median(b[:, 2] - b[:, 0])), float(np.median(b[:, 3] - b[:, 1]))))
    return out


def spacing(starts: list[float], size: float) -> float | None:
    """The spacing of a row's (column's) elements: the median gap between neighbours, gaps that are about a
    multiple of the smallest read as that many pitches. None with fewer than `MIN_GAPS` gaps (three elements) or
    gaps that do not agree."""
    s = sorted(starts)
    gaps = [b - a for a, b in zip(s[:-1], s[1:], strict=True) if b - a >= 0.5 * size]
    if len(gaps) < MIN_GAPS:
        return None
    unit = min(gaps)
    steps = [g / max(1, round(g / unit)) for g in gaps]
    if max(steps) - min(steps) > PITCH_TOLERANCE * unit:
        return None  # uneven spacing (pairs of windows, a wider middle bay): no pitch to extend by
    return float(np.median(steps))


def lines(t: Kind, along: str) -> tuple[list[np.ndarray], list[float]]:
    """The kind's rows (``along`` "x": elements side by side) or columns ("y"), as index arrays into its boxes, and
    the pitches of those that have one (`spacing`), in their order."""
    lo, hi, at, size = (1, 3, 0, t.width) if along == "x" else (0, 2, 1, t.height)
    found = aligned_lines(t.boxes[:, lo], t.boxes[:, hi])
    return found, [p for r in found if len(r) >= 2 and (p := spacing(t.boxes[r, at].tolist(), size)) is not None]


def tried(types: list[Kind], dimmed: bool) -> list[str]:
    """In words, for the kinds of element drawn most (at most four): how long their rows and columns are, and
    whether either has a pitch (`spacing`: three in a line, the gaps agreeing), which the structure needs to
    propose; and whether the photo left places unconfirmed."""
    out = []
    for t in sorted(types, key=lambda t: -len(t.boxes))[:4]:
        said = {}
        for what, along in (("row", "x"), ("column", "y")):
            found, steps = lines(t, along)
            longest = max((len(r) for r in found), default=0)
            said[what] = (f"a {what} with a pitch of {steps[0]:.0f} px" if steps else
                          f"no {what} with a pitch (the longest has {longest}; a pitch needs 3 in a {what} whose "
                          f"gaps agree within {100 * PITCH_TOLERANCE:.0f} %)")
        out.append(f"{LABELS[t.label]}s of {t.width:.0f} x {t.height:.0f} px, {len(t.boxes)} drawn: {said['row']}, "
                   f"{said['column']}")
    if dimmed:
        out.append("the places the structure gives that the photo does not confirm are shown dimmed")
    return out
