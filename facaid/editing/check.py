"""Whether an edit of a count did what a person means, judged from the facade before and after (no annotation).

`floors` + 1 on a facade means: the old facade with one floor more, put in *between* two floors, a floor like
those it already has, every other pixel where it was. Counting rows of window centres passes a facade whose new
floor is a blend of three floors or sits under the shops; looking at the picture does not. So an edit is *clean*
(issue 67) when:

1. the edited label map is the old one with one band inserted (`insertion`: the row where it went in that leaves
   most pixels where they were), not at the image's edge, and around it at least `KEEP` of the old pixels are
   unchanged (`KEEP_BAY` for a bay, whose new column may re-lay the ground floor's shops around its door);
2. the inserted band is a copy of a band of the old facade: at least `COPY` of its pixels equal those of the most
   alike band of its size;
3. it holds windows, and the rows (columns) of windows grow by one, or by as many as it holds (two where a bay is
   a pair of windows, or a floor has a mezzanine; counted as most of its shifts count them, `band_holds`), while
   the columns (rows) stay as they were; a shop window several bays wide is in no column
   (`facaid.reading.windows.WIDE`). Counted apart from the facade, a band may hold a strip of a window or a dormer
   as a row (column) of its own that the facade's count joins to its neighbour: one more is what the issue asks;
4. the doors stay as many as they were: a new bay beside the entrance is another shop, not a second door; but
   where every bay has a door of its own (a row of entrances), a new bay brings one more.

A removal (− 1) is judged as the insertion that would undo it: the old facade is the new one with a band put in.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from facaid.editing.parameters import named_parameters, set_parameter
from facaid.grammar.execute import first_boxes, flat_rows, label_map
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID
from facaid.reading.windows import WIDE, centre_bands, lattice, window_boxes
from facaid.segmentation import region_boxes

KEEP = 0.98  # share of the old pixels a new floor leaves where they were
KEEP_BAY = 0.93  # the same for a new bay column (the ground floor may re-lay its shops around the door)
COPY = 0.90  # share of the new band's pixels that equal the most alike band of the old facade
EDGE = 2  # a band put in within this many pixels of the image's edge is stuck on, not inserted
NEAR = 0.01  # rows that keep this much less than the most kept are as good a place for the band
TRIES = 8  # of those, this many (evenly spaced) are tried for the band's likeness
SAMPLE = (2, 4)  # the band's rows and columns compared in the copy search: every 2nd row, every 4th column
SHIFTS = 8  # the shifts of a new band whose counts of window rows (columns) it holds are compared
DOOR = LABEL_ID["door"]
BACKGROUND = LABEL_ID["background"]
SKY = 0.9  # share of the band above a building beside the one that took a floor that must be sky
EDITS = (("floors", 1), ("floors", -1), ("bays", 1), ("bays", -1))
MORE = (("floors", 1), ("bays", 1))  # the edits a reading is chosen by
_AXIS = {"floors": "y", "bays": "x"}


@dataclass(frozen=True)
class Verdict:
    """What an edit did: whether it is clean, and the figures the rule reads (shares of pixels, 0 to 1)."""

    clean: bool
    reason: str  # in words: what passed, or the first thing that did not
    unchanged: float = 0.0  # of the old pixels, the share where they were
    copy: float = 0.0  # of the band's pixels, the share equal to the most alike old band
    at: int = -1  # where the band went in (px from the top, or the left)

    def to_dict(self) -> dict:
        return asdict(self)


def kept(old: np.ndarray, new: np.ndarray) -> np.ndarray:
    """For each row y of ``old`` (0 to its height), the share of its pixels left where they were if a band of
    ``new.shape[0] - old.shape[0]`` rows went in at y to make ``new`` (of the same width)."""
    h = new.shape[0] - old.shape[0]
    above = np.concatenate([[0], np.cumsum((new[: old.shape[0]] == old).sum(axis=1))])  # rows < y kept
    below = np.concatenate([np.cumsum(((new[h:] == old).sum(axis=1))[::-1])[::-1], [0]])  # rows >= y, moved by h
    return (above + below) / old.size


def insertion(old: np.ndarray, new: np.ndarray, keep: float,
              holds: Callable[[int], int] | None = None) -> tuple[int, float, float]:
    """Where a band went into ``old`` to make ``new``: of the rows away from the edges that keep nearly the most of
    ``old``'s pixels (and at least ``keep``), the one whose band is most alike a band of ``old`` (a band between two
    like floors can go in at any row of them: only some of those cut a floor where the old ones are cut), with the
    share kept and the band's likeness (`best_copy`)."""
    h = new.shape[0] - old.shape[0]
    share = kept(old, new)
    inner = share[EDGE + 1 : len(share) - EDGE - 1]
    if not len(inner):
        at = int(np.argmax(share))
        return at, float(share[at]), 0.0
    near = np.flatnonzero(inner >= max(keep, inner.max() - NEAR)) + EDGE + 1
    if not len(near):
        at = int(np.argmax(share))  # at an edge, or too much changed: judged as it is
        return at, float(share[at]), best_copy(new[at : at + h], old)
    spread = near[np.unique(np.linspace(0, len(near) - 1, min(len(near), TRIES)).round().astype(int))]
    best, unheld = (-1.0, 0.0, 0), None
    for y in sorted(spread.tolist(), key=lambda y: -share[y]):  # the most kept first; a copy found ends it
        found = (best_copy(new[y : y + h], old), float(share[y]), y)
        if found[0] >= COPY and holds is not None and not holds(y):  # a band between two like bays cut through
            unheld = max(unheld or found[1:], found[1:])  # their windows: a copy, but another place may hold one
            continue
        best = max(best, found)
        if best[0] >= COPY:
            break
    if best[0] < COPY and unheld is not None:  # no place holds one: the copy that cuts through them, at the bar
        best = (COPY, *unheld)
    return best[2], best[1], best[0]


def best_copy(band: np.ndarray, old: np.ndarray) -> float:
    """The share of ``band``'s pixels (sampled, `SAMPLE`) equal to those of the most alike band of ``old`` of its
    height (0 where ``old`` is lower than it)."""
    h = band.shape[0]
    if h > old.shape[0] or h == 0:
        return 0.0
    sy, sx = SAMPLE
    sample = band[::sy, ::sx]
    columns = old[:, ::sx]
    starts = np.arange(old.shape[0] - h + 1)
    alike = np.zeros(len(starts), dtype=np.int64)
    for i, row in enumerate(sample):  # row i of the sample against row i * sy of every band of old
        alike += (columns[starts + i * sy] == row).sum(axis=1)
    return float(alike.max() / sample.size)


def band_lattice(windows: np.ndarray, at: int, h: int, axis: str) -> int:
    """How many rows (``axis`` "y") or columns ("x") of windows the band [at, at + h) holds: of ``windows`` (boxes
    x0, y0, x1, y1), those whose centres lie in it, in bands of centres (`centre_bands`); a window over `WIDE` times
    the median's size along the axis is in none."""
    lo, hi = (1, 3) if axis == "y" else (0, 2)
    centres = (windows[:, lo] + windows[:, hi]) / 2
    sizes = windows[:, hi] - windows[:, lo]
    inside = (centres >= at) & (centres < at + h) & (sizes <= WIDE * np.median(sizes) if len(sizes) else True)
    return len(centre_bands(centres[inside], sizes[inside]))


def band_holds(windows: np.ndarray, at: int, h: int, axis: str) -> int:
    """How many rows (columns) of windows a band of ``h`` put in at ``at`` holds: the count most of `SHIFTS` shifts
    of it give, evenly spaced over one band's length from half of it up (`band_lattice`; the fewer of two as common:
    a shift by a whole band is the same band in a repeating facade). A band between two like
    floors may go in from the middle of one row of windows to the middle of the next, and then the count of the
    band as it lies depends on a pixel's rounding: one row, or the two it runs between."""
    counts = [band_lattice(windows, at + s, h, axis) for s in np.linspace(-h / 2, h / 2, SHIFTS + 1)[:-1]]
    values, times = np.unique(counts, return_counts=True)
    return int(values[np.argmax(times)])


def judge_insert(old: np.ndarray, new: np.ndarray, old_lattice: tuple[int, int], new_lattice: tuple[int, int],
                 new_windows: np.ndarray, axis: str, keep: float) -> Verdict:
    """Whether ``new`` is ``old`` with one band inserted along ``axis`` ("y": a floor, "x": a bay) by the module's
    rule. The lattices are (window rows, window columns) of each; ``new_windows`` the windows of ``new`` (boxes)."""
    word = "floor" if axis == "y" else "bay"
    if axis == "x":
        old, new = old.T, new.T
    if new.shape[1] != old.shape[1]:
        return Verdict(False, f"the facade's other side changed too ({old.shape[1]} px to {new.shape[1]} px)")
    h = new.shape[0] - old.shape[0]
    if h <= 0:
        return Verdict(False, f"the facade did not grow by a {word}")
    at, unchanged, copy = insertion(old, new, keep, lambda y: band_lattice(new_windows, y, h, axis))
    figures = {"unchanged": unchanged, "copy": copy, "at": at}
    grows, stays = (0, 1) if axis == "y" else (1, 0)
    if at <= EDGE or at >= old.shape[0] - EDGE:
        return Verdict(False, f"the new {word} is stuck on at the facade's edge, not put in between two", **figures)
    if unchanged < keep:
        return Verdict(False, f"{100 * (1 - unchanged):.1f} % of the facade around the new {word} changed "
                              f"(at most {100 * (1 - keep):.0f} %)", **figures)
    if copy < COPY:
        return Verdict(False, f"the new {word} is like no {word} of the facade (at best {100 * copy:.0f} % alike, "
                              f"{100 * COPY:.0f} % needed)", **figures)
    held = band_holds(new_windows, at, h, axis)
    if not held:
        return Verdict(False, f"the new {word} holds no windows", **figures)
    if new_lattice[grows] - old_lattice[grows] not in (1, held) or new_lattice[stays] != old_lattice[stays]:
        what = ("rows", "columns") if axis == "y" else ("columns", "rows")
        return Verdict(False, f"the windows went from {old_lattice[grows]} {what[0]} and {old_lattice[stays]} "
                              f"{what[1]} to {new_lattice[grows]} and {new_lattice[stays]}", **figures)
    return Verdict(True, f"one {word} like the others put in between two", **figures)


def wings(proc: Procedure) -> tuple[str, list[tuple[int, int]]] | None:
    """The buildings of a facade of wings: the path of the outermost split along x two or more of whose children
    hold a node of role ``facade``, and each child's columns [x0, x1); None for a facade of one building."""
    boxes = first_boxes(proc)
    for path, node in proc.nodes():
        if node.rule != "split" or node.axis != "x" or "!" in path:
            continue
        if (sum(any(n.role == "facade" for _, n in c.walk()) for c in node.children) >= 2
                and all(id(c) in boxes for c in node.children)):
            return path, [(round(boxes[id(c)][0]), round(boxes[id(c)][2])) for c in node.children]
    return None


def judge_wings(old: Procedure, new: Procedure, old_map: np.ndarray, new_map: np.ndarray, old_rows: np.ndarray,
                new_rows: np.ndarray, axis: str, keep: float) -> Verdict | None:
    """The rule on a facade of wings, building by building (None where the facade is one building): the edited
    building is judged by `judge_insert`; every other keeps its pixels, a floor more of its neighbour adding sky
    above it (on top, `SKY` of that band background), a bay more of its neighbour moving it aside."""
    found = wings(old)
    if found is None:
        return None
    path, old_x = found
    node = dict(new.nodes()).get(path)
    boxes = first_boxes(new)
    if node is None or len(node.children) != len(old_x) or any(id(c) not in boxes for c in node.children):
        return None
    new_x = [(round(boxes[id(c)][0]), round(boxes[id(c)][2])) for c in node.children]
    edited: list[Verdict] = []
    for (a0, a1), (b0, b1) in zip(old_x, new_x, strict=True):
        o, n = old_map[:, a0:a1], new_map[:, b0:b1]
        h = n.shape[0] - o.shape[0] if axis == "y" else n.shape[1] - o.shape[1]
        if axis == "y" and h > 0 and n.shape[1] == o.shape[1] and kept(o, n)[0] >= keep \
                and (n[:h] == BACKGROUND).mean() >= SKY:
            continue  # sky above a building beside the one that took the floor
        if axis == "x" and abs(h) <= EDGE and n.shape[0] == o.shape[0]:
            w = min(o.shape[1], n.shape[1])  # a building beside the one that took the bay (a pixel's rounding)
            if (n[:, :w] == o[:, :w]).mean() >= keep:
                continue
        mine, theirs = _strip(old_rows, a0, a1), _strip(new_rows, b0, b1)
        edited.append(judge_insert(o, n, lattice(mine, typical=True), lattice(theirs, typical=True),
                                   window_boxes(theirs), axis, keep))
    if not edited:
        return Verdict(False, "no building of the facade took the edit")
    return next((v for v in edited if not v.clean), edited[0])


def _strip(rows: np.ndarray, x0: int, x1: int) -> np.ndarray:
    """The flattened rows whose centres lie in the columns [x0, x1), moved to start at x0."""
    centres = (rows[:, 1] + rows[:, 3]) / 2
    part = rows[(centres >= x0) & (centres < x1)].copy()
    part[:, [1, 3]] -= x0
    return part


def _pictured(proc: Procedure) -> tuple[np.ndarray, np.ndarray]:
    """The procedure's flattened rows and its label map, executed once."""
    rows = flat_rows(proc)
    return rows, label_map(proc, rows)


def judge(before: Procedure, after: Procedure, name: str, change: int,
          drawn: tuple[np.ndarray, np.ndarray] | None = None) -> Verdict:
    """Whether ``after``, ``before`` with the count ``name`` ("floors" or "bays") changed by ``change`` (+1 or
    -1), is the clean edit of the module's rule. ``drawn``: ``before``'s `_pictured` where it is at hand (the
    unedited facade, judged against each of its edits)."""
    axis = _AXIS[name]
    keep = KEEP if name == "floors" else KEEP_BAY
    old, new = (before, after) if change > 0 else (after, before)
    pictures = (drawn or _pictured(before), _pictured(after))
    (old_rows, old_map), (new_rows, new_map) = pictures if change > 0 else pictures[::-1]
    out = judge_wings(old, new, old_map, new_map, old_rows, new_rows, axis, keep)
    if out is None:
        out = judge_insert(old_map, new_map, lattice(old_rows, typical=True), lattice(new_rows, typical=True),
                           window_boxes(new_rows), axis, keep)
    doors = [len(region_boxes(rows, (DOOR,))) for rows in (old_rows, new_rows)]
    if out.clean and doors[0] != doors[1] and not _door_a_bay(old, name, doors):
        # the entrance stays: a new bay beside it is a shop, not a door
        return Verdict(False, f"the doors went from {doors[change < 0]} to {doors[change > 0]}", out.unchanged,
                       out.copy, out.at)
    if change < 0 and out.clean:
        return Verdict(True, f"one {'floor' if name == 'floors' else 'bay'} like the others taken out",
                       out.unchanged, out.copy, out.at)
    return out


def _door_a_bay(old: Procedure, name: str, doors: list[int]) -> bool:
    """Whether a bay more of ``old`` (the facade with fewer bays) may bring a door more: where every bay of it
    has a door of its own (doors at least as many as bays: a row of houses' or shops' entrances), the new bay is
    one more of them."""
    if name != "bays" or doors[1] != doors[0] + 1:
        return False
    bays = next((p.value for p in named_parameters(old) if p.name == "bays"), None)
    return bays is not None and doors[0] >= bays


def check_edits(proc: Procedure, edits: tuple[tuple[str, int], ...] = EDITS) -> dict[str, Verdict]:
    """`floors` ± 1 and `bays` ± 1 (or those of ``edits``) tried on ``proc`` and judged, keyed "floors+1",
    "floors-1", "bays+1" and "bays-1"; a count the procedure does not have, or cannot change that way, is left out."""
    params = {p.name: p for p in named_parameters(proc)}
    out: dict[str, Verdict] = {}
    drawn = _pictured(proc) if edits else None  # the unedited facade, drawn once for every edit
    for name, change in edits:
        p = params.get(name)
        if p is None or not p.min <= p.value + change <= p.max or p.min == p.max:
            continue
        key = f"{name}{change:+d}"
        try:
            edited = set_parameter(proc, name, p.value + change)
        except ValueError as exc:
            out[key] = Verdict(False, f"{name} {p.value + change:g} cannot be made: {exc}")
            continue
        out[key] = judge(proc, edited, name, change, drawn)
    return out


__all__ = ["COPY", "EDITS", "KEEP", "KEEP_BAY", "MORE", "Verdict", "band_holds", "best_copy", "check_edits",
           "insertion", "judge", "judge_insert", "kept"]
