"""What the drawn elements' structure proposes: a type's rows continued into the row begun beside them (`floors`), its
rows and columns crossed (`lattice`), and what is drawn against one type's elements carried to the rest of them
(`companions`). See `facaid.completion` for the scores and how often each is right on CMP."""

from __future__ import annotations

import numpy as np

from facaid.completion.kinds import SIZE_TOLERANCE, Kind, lines
from facaid.completion.proposals import MAX_PROPOSALS, Proposals
from facaid.labels import LABELS
from facaid.segmentation import aligned_lines

MAX_FILL = 16  # two drawn lines at most this many pitches apart are filled between
MAX_TYPES = 200  # with more types than this (no facade has them), companions are not looked for
EXTEND = 1  # rows and columns continue by at most this many pitches beyond the drawn ones
COMPANION_SHARE = 1.0  # a companion is proposed when at least this share of its element's drawn copies have one
COMPANION_MIN = 4  # ... and at least this many have one
COMPANION_TOUCH = 3  # pixels: a companion overlaps its element or lies at most this far from it
GRID_FILL = 0.8  # a crossing of drawn lines scores high only where the type's lattice is this full
FLOOR_MIN_ROW = 2  # a row is continued from a neighbouring one of at least this many elements
FLOOR_STRAYS = 0.5  # ... when at most this many of the begun row's elements per aligned one stray off its columns
COLUMN_TOLERANCE = 0.3  # elements whose left edges agree within this share of the width stand in one column


def _positions(observed: list[float], pitch: float | None, lo: float, hi: float, size: float,
               ) -> list[tuple[float, bool]]:
    """(start, drawn) along a row (column): the drawn elements' starts, the places between two of them a whole
    number of pitches apart (at most `MAX_FILL`), and those beyond them by the pitch while the element still fits
    within [lo, hi]."""
    known = sorted(observed)
    out = [(v, True) for v in known]
    if pitch is None or pitch <= 0:
        return out
    slack = 0.25 * size
    for a, b in zip(known[:-1], known[1:], strict=True):
        steps = round((b - a) / pitch)
        if 2 <= steps <= MAX_FILL and abs(b - a - steps * pitch) <= 0.25 * pitch:
            out += [(a + k * (b - a) / steps, False) for k in range(1, steps)]
    v = known[0] - pitch
    for _ in range(EXTEND):
        if v < lo - slack:
            break
        out.append((v, False))
        v -= pitch
    v = known[-1] + pitch
    for _ in range(EXTEND):
        if v + size > hi + slack:
            break
        out.append((v, False))
        v += pitch
    return sorted(out)


def lattice(t: Kind, props: Proposals) -> None:
    """The type's rows and columns, each continued by the pitch measured along it, crossed: every crossing
    where nothing of the type is drawn is proposed (scored by how many of its two lines were drawn in)."""
    b = t.boxes
    region = props.walls
    x_lo, y_lo = float(region[:, 0].min()), float(region[:, 1].min())
    x_hi, y_hi = float(region[:, 2].max()), float(region[:, 3].max())
    rows, pitches_x = lines(t, "x")
    cols, pitches_y = lines(t, "y")
    px = float(np.median(pitches_x)) if pitches_x else None
    py = float(np.median(pitches_y)) if pitches_y else None
    if px is None and py is None:
        return
    xs = _spans(b[:, 0], b[:, 2], cols, px, x_lo, x_hi, t.width)
    ys = _spans(b[:, 1], b[:, 3], rows, py, y_lo, y_hi, t.height)
    if len(xs) * len(ys) > MAX_PROPOSALS:
        return  # a lattice of thousands of places is no facade's
    regular = len(b) >= GRID_FILL * len(rows) * len(cols)
    for y0, y1, row in ys:
        if props.full:
            return
        for x0, x1, col in xs:
            x_seen, y_seen = col is not None, row is not None
            score = 0.5 + 0.2 * x_seen + 0.2 * y_seen
            if x_seen and y_seen and not regular:  # on CMP such crossings are right one time in ten
                score = 0.75
            reason = "grid" if x_seen and y_seen else ("row" if y_seen else "column" if x_seen else "lattice")
            props.add(t.label, np.array([x0, y0, x1, y1]), score, reason)


def floors(t: Kind, props: Proposals) -> None:
    """Two neighbouring rows of the type, one begun in the other's columns: the fuller one's other columns are
    proposed in the row begun, at its height."""
    b = t.boxes
    rows = sorted(aligned_lines(b[:, 1], b[:, 3]), key=lambda r: float(np.median(b[r, 1])))
    for a, c in zip(rows[:-1], rows[1:], strict=False):
        full, begun = (a, c) if len(a) >= len(c) else (c, a)
        if len(full) < FLOOR_MIN_ROW:
            continue
        aligned = sum(bool((np.abs(b[full, 0] - b[i, 0]) <= COLUMN_TOLERANCE * t.width).any()) for i in begun)
        if aligned == 0 or len(begun) - aligned > FLOOR_STRAYS * aligned:
            continue  # the row begun is laid out otherwise: another floor
        y0, y1 = float(np.median(b[begun, 1])), float(np.median(b[begun, 3]))
        for j in full.tolist():
            props.add(t.label, np.array([b[j, 0], y0, b[j, 2], y1]), 0.9, "floor")


def _spans(lo: np.ndarray, hi: np.ndarray, lines: list[np.ndarray], pitch: float | None, start: float, stop: float,
           size: float) -> list[tuple[float, float, np.ndarray | None]]:
    """(lo, hi, members) of a type's columns (rows): a drawn one spans its members' median edges, the others
    (members None) the type's size from where `_positions` puts them."""
    drawn = {float(np.median(lo[m])): (float(np.median(hi[m])), m) for m in lines}
    return [(v, drawn[v][0], drawn[v][1]) if seen else (v, v + size, None)
            for v, seen in _positions(list(drawn), pitch, start, stop, size)]


def companions(types: list[Kind], props: Proposals) -> None:
    """Elements drawn on or against another type's elements, proposed at the same offset for the rest of them."""
    if len(types) > MAX_TYPES:
        return
    for a in types:
        if len(a.boxes) < COMPANION_MIN or props.full:
            continue
        instances = [box for box in a.boxes] + [box for lab, box, score, _ in list(props.items) if lab == a.label
                                                 and score >= 0.9
                                                 and abs((box[2] - box[0]) - a.width) <= SIZE_TOLERANCE * a.width]
        for s in types:
            if s.label == a.label:
                continue
            box, c = a.boxes[:, None, :], s.boxes[None, :, :]  # (anchors, companions, 4)
            gap_x = np.maximum(box[..., 0] - c[..., 2], c[..., 0] - box[..., 2])
            gap_y = np.maximum(box[..., 1] - c[..., 3], c[..., 1] - box[..., 3])
            touch = ((gap_x <= COMPANION_TOUCH) & (gap_y <= COMPANION_TOUCH)
                     & (c[..., 2] - c[..., 0] <= 1.5 * (box[..., 2] - box[..., 0])))
            has = touch.any(axis=1)  # each anchor's first touching companion
            if has.sum() < COMPANION_MIN or has.mean() < COMPANION_SHARE:
                continue
            first = touch.argmax(axis=1)[has]
            offset = np.median(s.boxes[first] - a.boxes[has], axis=0)
            share = float(has.mean())
            for anchor in instances:
                props.add(s.label, anchor + offset, round(0.3 + 0.5 * share, 3), f"with {LABELS[a.label]}")


__all__ = ["COLUMN_TOLERANCE", "COMPANION_MIN", "EXTEND", "GRID_FILL", "companions", "floors", "lattice"]
