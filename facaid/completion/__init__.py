"""Completion: from the elements a person has drawn so far, propose the ones they have not drawn yet.

`complete(segmentation)` reads the structure the drawn elements imply and returns the missing elements as
rectangles of the segmentation contract with a ``score`` in (0, 1] and a ``reason``, best first, none repeating
a drawn one:

1. **Types**: drawn elements of one class and about one size (width and height within `SIZE_TOLERANCE`) are
   one type — the tall windows, the small attic windows, the sills.
2. **Floors**: two neighbouring rows of a type, one begun in the other's columns (at most `FLOOR_STRAYS` of its
   elements per aligned one off them): the fuller row's other columns are proposed in the row begun, at its height
   (score 0.9, reason ``floor``). On CMP's dev half (the simulated annotator below) these are right 408 times in 554.
3. **Lattice**: a type's elements fall into rows (their vertical extents overlapping by half) and columns. Where
   a row (column) has at least `MIN_GAPS` gaps that agree (`PITCH_TOLERANCE`; multiples read as skipped bays),
   its pitch continues the columns (rows) `EXTEND` pitch beyond the drawn ones while they fit in the facade (the
   drawn facade rectangles' bounds, else the image) and fills the whole pitches between them. Every
   crossing of a row and a column where nothing of the type is drawn is a proposal, spanning its drawn row's
   and column's median edges: score 0.9 (reason ``grid``) where both the row and the column were drawn in and the
   lattice is regular (`GRID_FILL` of its crossings drawn), else 0.75 (right 10 times in 89 on CMP's dev half);
   0.7 (``row`` or ``column``) where one was, 0.5 where neither.
4. **Companions**: an element drawn on or against every one of at least `COMPANION_MIN` drawn elements of
   another type (a sill under each window) is proposed at the same offset for the rest of them (``with
   window``; at most 0.8: right 7 times in 70 on CMP's dev half).
5. **The photo** (when given: the image the segmentation is drawn on, resized to its size) proposes: every place
   that looks like a type's drawn elements with the wall around them (`facaid.photo.appearance.search`, NCC at least
   `SEARCH_MATCH`, anywhere in the facade, rows and lattices or not) is proposed at the type's size (score
   `PHOTO_CONFIRMED`, reason ``looks like window``). On photo-like renders of 12 held-out generated facades this
   takes the effort from 0.72 (the structure, checked by the photo) to 0.443. And the drawn elements are carried
   along **the photo's repeats** (`facaid.photo.repeats`: the shifts they vote for, where they look like themselves on
   the contrast-normalised photo) to where they stand in a drawn row or column of their class: at NCC
   `REPEAT_MATCH` by how many of the two are drawn (`COMPANION_EXTRA` more for classes other than windows and
   blinds), scored from `COPY_SCORE` up (reason ``repeat of window``, ``photo`` its NCC). On
   CMP's own photos (dev, every 3rd facade) this takes the effort from 0.793 to 0.74-0.76.
6. **The photo checks** every proposal scored at least `PHOTO_CANDIDATE`, the searched ones too: it is moved to
   the best of 25 nearby places and compared with the drawn elements of its class (`facaid.photo.appearance`: normalized
   cross-correlation of 12 x 12 grey patches); at `PHOTO_MATCH` or more it scores at least `PHOTO_CONFIRMED`,
   below that half its score, and ``photo`` holds the similarity. A proposal the structure is sure of (scored
   `PHOTO_CONFIRMED` or more: a floor's, a full grid's) is only vetoed, below `VETO`: on CMP's own photos real copies
   score 0.72-0.86 (dev, every 3rd facade: effort 0.842 → 0.793, hit rate 0.75 kept; on photo-like renders
   0.443 → 0.471). Where the photo is flat (a rendered label map) it has no say.

Proposals outside the drawn facade rectangles' bounds (the image when none is drawn), cut by the image's edge, over
a drawn element of the same class, mostly under a drawn element of a class that paints over them, or near a
``rejected`` box are left out; those scored below ``min_score`` (`facaid.defaults.DEFAULT_MIN_SCORE`) are not
returned by `complete`. `explained` returns them too, from `DIM_SCORE` up (the places the structure gives and the
photo does not confirm, which the editor shows dimmed for a person to take), and where nothing is proposed says in
words what was tried: how long each kind's rows and columns are, and whether either has a pitch. The figures are of
the simulated annotator (`facaid.evaluation.assist`, `bench/bench_assist.py`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from facaid.completion.kinds import MIN_GAPS as MIN_GAPS  # re-exported: the docstring names them
from facaid.completion.kinds import PITCH_TOLERANCE as PITCH_TOLERANCE
from facaid.completion.kinds import SIZE_TOLERANCE, Kind, kinds, lines, tried
from facaid.defaults import DEFAULT_MIN_SCORE
from facaid.labels import BACKGROUND, FACADE, GLASS, LABELS, PRIORITY
from facaid.photo import appearance, repeats
from facaid.segmentation import Segmentation, aligned_lines, parse_segmentation

MAX_DRAWN = 2_000  # more drawn rectangles than this are refused (a CMP facade has at most a few hundred)
MAX_PROPOSALS = 2_000  # proposals gathered at most in one call
MAX_FILL = 16  # two drawn lines at most this many pitches apart are filled between
MAX_TYPES = 200  # with more types than this (no facade has them), companions are not looked for
MAX_SEARCH_TYPES = 64  # the photo is searched for at most this many types, those drawn most often (CMP: 58 at most)
SAME_PLACE = 0.5  # IoU at which two proposals are the same element
OVERLAP = 0.2  # a proposal whose area lies this much over drawn elements of its class is not made
REJECTED_PLACE = 0.3  # IoU at which a proposal repeats a rejected one
EXTEND = 1  # rows and columns continue by at most this many pitches beyond the drawn ones
COMPANION_SHARE = 1.0  # a companion is proposed when at least this share of its element's drawn copies have one
COMPANION_MIN = 4  # ... and at least this many have one
COMPANION_TOUCH = 3  # pixels: a companion overlaps its element or lies at most this far from it


GRID_FILL = 0.8  # a crossing of drawn lines scores high only where the type's lattice is this full
FLOOR_MIN_ROW = 2  # a row is continued from a neighbouring one of at least this many elements
FLOOR_STRAYS = 0.5  # ... when at most this many of the begun row's elements per aligned one stray off its columns
COLUMN_TOLERANCE = 0.3  # elements whose left edges agree within this share of the width stand in one column


PHOTO_CANDIDATE = 0.7  # proposals scored at least this by the structure are shown to the photo
PHOTO_MATCH = 0.9  # NCC against the drawn examples of the class at which the photo confirms a proposal
PHOTO_CONFIRMED = 0.9  # ... and the score it has at least then
VETO = 0.75  # ... and below this NCC the photo vetoes a proposal the structure is sure of
SEARCH_MATCH = 0.93  # NCC at which a place anywhere in the photo that looks like a type's elements is proposed
REPEATS = True
REPEAT_MATCH = (2.0, 0.8, 0.6)  # NCC a repeat needs standing in neither, one or both of a drawn row and column
COMPANION_EXTRA = 0.1  # ... and this much more for a class other than a window or blind (a sill, a cornice)
ALIGNED = 0.15  # ... in which its edges agree with a drawn element's within this share of its size
COPY_SCORE = 0.85  # the score of a repeat as alike as it needs to be (`REPEAT_MATCH`) ...
COPY_SLOPE = 0.3  # ... and what each unit of NCC above that adds


class RejectedError(ValueError):
    """A rejected rectangle that breaks the segmentation contract; the message names it (``rejected[i]``)."""


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


def _overlap(box: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """The area ``box`` shares with each of ``boxes`` ((n, 4) x0, y0, x1, y1)."""
    ix = np.clip(np.minimum(box[2], boxes[:, 2]) - np.maximum(box[0], boxes[:, 0]), 0, None)
    iy = np.clip(np.minimum(box[3], boxes[:, 3]) - np.maximum(box[1], boxes[:, 1]), 0, None)
    return ix * iy


def _area(boxes: np.ndarray) -> np.ndarray:
    return (boxes[..., 2] - boxes[..., 0]) * (boxes[..., 3] - boxes[..., 1])


def _iou(box: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    inter = _overlap(box, boxes)
    return inter / np.maximum(_area(box) + _area(boxes) - inter, 1e-9)


class Proposals:
    """Proposals gathered with the checks every one must pass."""

    def __init__(self, seg: Segmentation, rows: np.ndarray, rejected: np.ndarray):
        self.width, self.height = seg.width, seg.height
        walls = rows[rows[:, 0] == FACADE, 1:].astype(float)
        self.walls = walls if len(walls) else np.array([[0.0, 0.0, seg.width, seg.height]])
        self.drawn = rows[(rows[:, 0] != FACADE) & (rows[:, 0] != BACKGROUND)]
        self.rejected = rejected
        self.items: list[tuple[int, np.ndarray, float, str]] = []  # label, box, score, reason
        self.boxes = np.zeros((MAX_PROPOSALS, 4))  # the items' boxes and labels, for comparing in one go
        self.labels = np.full(MAX_PROPOSALS, -1)
        self.cache: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.photo: dict[int, float] = {}  # item: the similarity the photo found it at (its repeats)

    @property
    def full(self) -> bool:
        return len(self.items) >= MAX_PROPOSALS

    def inside(self, box: np.ndarray) -> bool:
        """Within the bounds of the drawn facade rectangles (2 px of slack), or the image when none is drawn: a
        wall drawn as one rectangle or, as flattened segmentations have it, as pieces around the elements."""
        slack, w = 2.0, self.walls
        return bool(w[:, 0].min() - slack <= box[0] and w[:, 1].min() - slack <= box[1]
                    and box[2] <= w[:, 2].max() + slack and box[3] <= w[:, 3].max() + slack)

    def _against(self, label: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(drawn boxes of the class, drawn boxes of classes painted over it, rejected boxes of the class)."""
        if label not in self.cache:
            drawn = self.drawn
            above = np.array([PRIORITY[k] > PRIORITY[label] for k in drawn[:, 0].tolist()], dtype=bool)
            rej = self.rejected[self.rejected[:, 0] == label, 1:] if len(self.rejected) else np.zeros((0, 4))
            self.cache[label] = (drawn[drawn[:, 0] == label, 1:].astype(float),
                                 drawn[above, 1:].astype(float).reshape(-1, 4), rej.astype(float))
        return self.cache[label]

    def add(self, label: int, box: np.ndarray, score: float, reason: str, photo: float | None = None) -> bool:
        """Propose ``box`` unless a check refuses it (False); at the place of a proposal made already, the better
        scored of the two stays. ``photo``: the similarity the photo found it at, kept with it."""
        box = np.round(np.asarray(box, dtype=float))
        if (self.full or box[2] - box[0] < 1 or box[3] - box[1] < 1 or box[0] < 0 or box[1] < 0
                or box[2] > self.width or box[3] > self.height or not self.inside(box)):
            return False  # a place cut by the image's edge is no element
        same, above, rej = self._against(label)
        shared = _overlap(box, same)  # over a drawn element of its class, even in part: drawn already
        if shared.sum() > OVERLAP * _area(box) or (shared / np.maximum(_area(same), 1e-9) > 0.5).any():
            return False
        if _overlap(box, above).sum() > 0.6 * _area(box):  # mostly under a drawn element that paints over it
            return False
        if (_iou(box, rej) >= REJECTED_PLACE).any():
            return False
        n = len(self.items)
        mine = np.flatnonzero(self.labels[:n] == label)
        hit = mine[_iou(box, self.boxes[mine]) >= SAME_PLACE]
        if len(hit):
            i = int(hit[0])
            if score > self.items[i][2]:
                self.items[i] = (label, box, score, reason)
                self.boxes[i] = box
                self._photo(i, photo)
            return False
        self.items.append((label, box, score, reason))
        self.boxes[n], self.labels[n] = box, label
        self._photo(n, photo)
        return True

    def _photo(self, i: int, photo: float | None) -> None:
        if photo is None:
            self.photo.pop(i, None)
        else:
            self.photo[i] = round(float(photo), 3)


def _lattice(t: Kind, props: Proposals) -> None:
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


def _floors(t: Kind, props: Proposals) -> None:
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


def _companions(types: list[Kind], props: Proposals) -> None:
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


def _search(levels: appearance.Levels, types: list[Kind], props: Proposals) -> None:
    """Where the photo looks like a type's drawn elements (`facaid.photo.appearance.search`, NCC at least
    `SEARCH_MATCH`), anywhere in the facade: each such place is proposed at the type's size (``looks like``). The
    `MAX_SEARCH_TYPES` types drawn most often are searched for (in their order), so that a call costs at most that
    many searches however many types are drawn."""
    most = sorted(range(len(types)), key=lambda i: -len(types[i].boxes))[:MAX_SEARCH_TYPES]
    for t in (types[i] for i in sorted(most)):
        boxes, _ = appearance.search(levels, t.boxes, (t.width, t.height), SEARCH_MATCH)
        for box in boxes:
            props.add(t.label, box, PHOTO_CONFIRMED, f"looks like {LABELS[t.label]}")


def _repeats(levels: appearance.Levels, props: Proposals) -> None:
    """The drawn elements carried by the photo's repeats (`facaid.photo.repeats`) where it looks like them: proposed
    where they also stand in a drawn row or column of their class (`REPEAT_MATCH`: the alike a copy must be, by how
    many of its row and column are drawn; one in neither is not proposed)."""
    for label, box, sim in repeats.repeats(levels, props.drawn):
        same = props._against(label)[0]
        w, h = box[2] - box[0], box[3] - box[1]
        row = bool(((np.abs(same[:, 1] - box[1]) <= ALIGNED * h) & (np.abs(same[:, 3] - box[3]) <= ALIGNED * h)).any())
        col = bool(((np.abs(same[:, 0] - box[0]) <= ALIGNED * w) & (np.abs(same[:, 2] - box[2]) <= ALIGNED * w)).any())
        need = REPEAT_MATCH[row + col] + (0.0 if label in GLASS else COMPANION_EXTRA)
        if sim >= need:
            props.add(label, box, round(min(1.0, COPY_SCORE + COPY_SLOPE * (sim - need)), 3),
                      f"repeat of {LABELS[label]}", sim)


def _photo_check(levels: appearance.Levels, props: Proposals) -> dict[int, tuple[float, float, np.ndarray]]:
    """{item: (score, similarity, box)} for the proposals the photo has a say on: each is moved to where it looks
    most like the drawn elements of its class (`appearance.refine`); one that looks like them scores at least
    `PHOTO_CONFIRMED`, one that does not half its structural score and stays where the structure put it; a flat
    place or class keeps its score."""
    out: dict[int, tuple[float, float]] = {}
    items = [i for i, item in enumerate(props.items) if item[2] >= PHOTO_CANDIDATE and not item[3].startswith("repeat")]
    for label in sorted({props.items[i][0] for i in items}):
        mine = [i for i in items if props.items[i][0] == label]
        examples = props.drawn[props.drawn[:, 0] == label, 1:]
        boxes, sims = appearance.refine(levels, props.boxes[mine], examples)
        for i, box, sim in zip(mine, boxes, sims.tolist(), strict=True):
            if np.isnan(sim):
                continue
            score = props.items[i][2]
            bar = VETO if score >= PHOTO_CONFIRMED else PHOTO_MATCH  # a sure structure: the photo only vetoes
            if sim < bar:  # not confirmed: where the structure puts it (the best of nearby places is any of them)
                score, box = 0.5 * score, props.boxes[i]
            else:
                score = max(score, PHOTO_CONFIRMED)
            out[i] = (round(float(score), 3), round(float(sim), 3), box)
    return out


def proposals_for(segmentation: Segmentation | dict, rejected: list[dict] | None, min_score: float
                  ) -> tuple[Segmentation, Proposals]:
    """The segmentation and an empty `Proposals` for it, the arguments checked as `complete` says."""
    seg = segmentation if isinstance(segmentation, Segmentation) else parse_segmentation(segmentation)
    rows = seg.to_array()
    if len(rows) > MAX_DRAWN:
        raise ValueError(f"too many rectangles for completion: {len(rows)} (at most {MAX_DRAWN})")
    if not 0 <= min_score <= 1:  # NaN too
        raise ValueError(f"min_score must be in [0, 1], got {min_score}")
    if rejected is not None and not isinstance(rejected, list):
        raise ValueError("rejected must be a list of rectangles")
    rej = np.zeros((0, 5))
    if rejected:  # the contract's rectangles, checked as a segmentation of the same size would be
        try:
            rej = parse_segmentation({"width": seg.width, "height": seg.height, "rects": rejected}).to_array()
        except ValueError as exc:
            raise RejectedError(str(exc).replace("rects", "rejected")) from None
    return seg, Proposals(seg, rows, rej)


def complete(segmentation: Segmentation | dict, photo: Any = None, *, rejected: list[dict] | None = None,
             min_score: float = DEFAULT_MIN_SCORE) -> list[dict]:
    """Proposed missing elements for a partly drawn segmentation (a `Segmentation` or its JSON object): dicts
    ``{label, x0, y0, x1, y1, score}`` in the segmentation contract, best first, none repeating a drawn element;
    ``rejected`` boxes (the same contract) are not proposed again. See the module's docstring. Raises
    `SegmentationError` (a ValueError) naming the field for a bad segmentation, `RejectedError` (a ValueError)
    for a bad rejected box, ValueError for more than `MAX_DRAWN` rectangles or ``min_score`` outside [0, 1]."""
    return explained(segmentation, photo, rejected=rejected, min_score=min_score).proposals


DIM_SCORE = 0.3  # places scored this or more, under ``min_score``, are returned dimmed: the person may take them
MAX_DIMMED = 60


@dataclass
class Completion:
    """What `explained` found: the ``proposals`` (as `complete` returns them), the places scored under
    ``min_score`` but at least `DIM_SCORE` (``dimmed``: the structure proposes them and the photo does not confirm
    them, shown for the person to take), and in words what was ``tried`` where nothing is proposed."""

    proposals: list[dict]
    dimmed: list[dict]
    tried: list[str]


def explained(segmentation: Segmentation | dict, photo: Any = None, *, rejected: list[dict] | None = None,
              min_score: float = DEFAULT_MIN_SCORE) -> Completion:
    """`complete`, with the places under ``min_score`` and what was tried (a `Completion`)."""
    seg, props = proposals_for(segmentation, rejected, min_score)
    types = kinds(props.drawn)
    for t in types:
        _floors(t, props)
    for t in types:
        _lattice(t, props)
    _companions(types, props)
    looks = {}
    if photo is not None:
        levels = appearance.levels(photo, seg.width, seg.height)
        _search(levels, types, props)
        if REPEATS:
            _repeats(levels, props)
        looks = _photo_check(levels, props)
    out = []
    for i, (label, b, score, reason) in enumerate(props.items):
        p = {"label": LABELS[label], "x0": int(b[0]), "y0": int(b[1]), "x1": int(b[2]), "y1": int(b[3]),
             "score": round(float(score), 3), "reason": reason}
        if i in looks:
            p["score"], p["photo"], box = looks[i]
            p.update(x0=int(box[0]), y0=int(box[1]), x1=int(box[2]), y1=int(box[3]))
        elif i in props.photo:
            p["photo"] = props.photo[i]
        out.append(p)
    out.sort(key=lambda p: (-p["score"], p["y0"], p["x0"]))
    kept = [p for p in out if p["score"] >= min_score]
    dimmed = [p for p in out if DIM_SCORE <= p["score"] < min_score][:MAX_DIMMED]
    return Completion(kept, dimmed, [] if kept else tried(types, bool(dimmed)))
