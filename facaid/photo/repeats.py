"""Repeats of what is drawn, read from the photo: the shifts that carry the drawn elements onto look-alikes.

A facade repeats along its rows and columns, floors and bays (Müller et al. 2007; Zhang et al. 2013). The shifts
that make up its lattice are found by voting (after Pauly et al. 2008, "Discovering structural regularity"):

1. The photo is **contrast-normalised** at a working scale (`normalised`): lighting gradients and
   shadows no longer decide what looks alike.
2. Each drawn element, with `CONTEXT` of its size around it, is slid along its own row and its own column; where
   it looks like itself (`VOTE`) it votes for that horizontal or vertical **shift**.
3. Shifts that `SUPPORT` elements or more vote for (within `TOLERANCE` of the image's side) are the facade's
   **repeats**; their sums, one horizontal and one vertical, are repeats too (a window two floors down and one bay
   across).
4. Every drawn element is carried by every repeat to where the photo looks most like it (`JITTER` around), and
   is as alike as the lower of its NCC with its wall and without: what a window's wall shares with the wall
   between two windows does not make that wall a window. `facaid.completion` proposes the carried elements that
   stand in a drawn row or column of their class; `facaid.completion.copies` carries one unit a person selected.

Pillars and moldings are not carried (`CARRIED`): along their length they look like themselves anywhere. The work
of a call is bounded: the photo at `SIDE`, `MAX_VOTERS` voters, `MAX_CARRIES` elements carried by a repeat.
"""

from __future__ import annotations

import numpy as np

from facaid.labels import LABEL_ID
from facaid.photo.appearance import FLAT, Levels

SIDE = 512  # pixels: the photo is read at this longer side (or its own, when smaller)
SIGMA = 0.02  # the neighbourhood of the contrast normalisation, a share of the working side
CONTEXT = 0.25  # share of its size around each element that is matched with it
MARGIN = 3  # ... and at least this many working pixels
VOTE = 0.6  # an element looks like itself here at this NCC or more: a vote for the shift
SUPPORT = 2  # a shift is a repeat when this many elements vote for it
TOLERANCE = 0.01  # votes within this share of the working side are for one shift
MATCH = 0.6  # a carried element is proposed where the photo looks like it at this NCC or more
JITTER = 2  # working pixels a carried element may move to where it looks most like itself
MAX_SHIFTS = 24  # repeats kept at most along each axis, the best supported first
CARRIED = ("window", "blind", "sill", "cornice", "balcony", "door", "deco", "shop")  # classes carried (a pillar or
# a molding runs the facade's height or width: along its length it looks like itself anywhere)
MAX_SUMS = 6  # the best supported repeats of each axis whose sums are repeats too
MAX_ELEMENTS = 400  # drawn elements that vote and are carried at most (the largest)
MAX_VOTERS = 100  # the largest elements vote, at most this many (each slides along a row and a column)
MAX_CARRIES = 20_000  # element-and-repeat pairs tried at most in one call (the largest elements first)
NOISE = 25.0  # grey levels squared added to the local variance: flat wall is not amplified into texture


def normalised(grey: np.ndarray, sigma: float) -> np.ndarray:
    """``grey`` less its local mean, over its local spread (Gaussian neighbourhoods of ``sigma`` pixels)."""
    import cv2

    g = grey.astype(np.float32)
    d = g - cv2.GaussianBlur(g, (0, 0), sigma)
    return d / np.sqrt(cv2.GaussianBlur(d * d, (0, 0), sigma) + NOISE)


def _crop(norm: np.ndarray, box: np.ndarray) -> tuple[np.ndarray, tuple[int, int]] | None:
    """The element's patch with its context (None where cut by the image's edge or flat), and the element's
    offset inside it."""
    x0, y0, x1, y1 = box
    mx, my = max(MARGIN, round(CONTEXT * (x1 - x0))), max(MARGIN, round(CONTEXT * (y1 - y0)))
    a, b, c, d = round(x0) - mx, round(y0) - my, round(x1) + mx, round(y1) + my
    h, w = norm.shape
    if a < 0 or b < 0 or c > w or d > h or c - a < 4 or d - b < 4:
        return None
    patch = norm[b:d, a:c]
    return (patch, (mx, my)) if patch.std() > 1e-3 else None


def _votes(norm: np.ndarray, patch: np.ndarray, at: tuple[int, int], axis: int,
           margin: tuple[int, int]) -> list[tuple[int, float]]:
    """Shifts along ``axis`` (0: x, 1: y) where ``patch`` (whose top-left is ``at``, with ``margin`` of context
    around the element) looks like itself, with their NCC: the peaks of the response along its own row (column),
    none within the element's own size of another (two windows of a pair nearly touch: their contexts overlap)."""
    import cv2

    ph, pw = patch.shape
    x, y = at
    j = JITTER
    if axis == 0:
        strip = norm[max(0, y - j): y + ph + j]
    else:
        strip = norm[:, max(0, x - j): x + pw + j]
    if strip.shape[0] < ph or strip.shape[1] < pw:
        return []
    r = cv2.matchTemplate(strip, patch, cv2.TM_CCOEFF_NORMED)
    profile = r.max(axis=0) if axis == 0 else r.max(axis=1)
    profile = np.where(np.isfinite(profile), profile, -1.0)
    own = x if axis == 0 else y
    size = max(1, pw - 2 * margin[0] if axis == 0 else ph - 2 * margin[1])
    out = []
    taken = np.zeros(len(profile), dtype=bool)
    for i in np.argsort(-profile, kind="stable").tolist():
        if profile[i] < VOTE:
            break
        if abs(i - own) < size or taken[max(0, i - size + 1): i + size].any():
            continue
        taken[i] = True
        out.append((i - own, float(profile[i])))
    return out


def _shifts(votes: list[tuple[int, float, int]], tolerance: float, support: int) -> list[int]:
    """The shifts that ``support`` distinct elements vote for: votes (shift, NCC, element) clustered within
    ``tolerance``, each cluster's median, the best supported first."""
    out = []
    votes = sorted(votes)
    i = 0
    while i < len(votes):
        j = i
        while j + 1 < len(votes) and votes[j + 1][0] - votes[i][0] <= tolerance:
            j += 1
        group = votes[i: j + 1]
        voters = {v[2] for v in group}
        if len(voters) >= support:
            out.append((len(voters), int(np.median([v[0] for v in group]))))
        i = j + 1
    return [s for _, s in sorted(out, key=lambda t: -t[0])[:MAX_SHIFTS]]


class _Reading:
    """The drawn elements on the contrast-normalised photo: their patches, and the shifts they vote for."""

    def __init__(self, levels: Levels, drawn: np.ndarray):
        self.drawn = drawn
        f = min(1.0, SIDE / max(levels.shape))
        small = levels.scaled(f)
        self.flat = bool(small.std() < FLAT)
        self.norm = normalised(small, SIGMA * max(small.shape))
        self.to_work = levels.scale * f  # segmentation pixels to working pixels (x, y, x, y)
        self.boxes = drawn[:, 1:] * self.to_work
        self.crops = [None if self.flat else _crop(self.norm, b) for b in self.boxes]
        self.cores: dict[int, np.ndarray | None] = {}  # each element alone (no context), where it is not flat

    def shifts(self, support: int) -> list[tuple[int, int]]:
        """The repeats (working pixels) that ``support`` drawn elements or more vote for, and their sums."""
        votes: tuple[list, list] = ([], [])
        for k, (b, c) in enumerate(zip(self.boxes[:MAX_VOTERS], self.crops[:MAX_VOTERS], strict=True)):
            if c is None:
                continue
            patch, (mx, my) = c
            at = (round(b[0]) - mx, round(b[1]) - my)
            for axis in (0, 1):
                votes[axis].extend((s, v, k) for s, v in _votes(self.norm, patch, at, axis, (mx, my)))
        tol = TOLERANCE * max(self.norm.shape)
        sx, sy = _shifts(votes[0], tol, support), _shifts(votes[1], tol, support)
        return ([(dx, 0) for dx in sx] + [(0, dy) for dy in sy]
                + [(dx, dy) for dx in sx[:MAX_SUMS] for dy in sy[:MAX_SUMS]])

    def own_shifts(self, k: int) -> list[tuple[int, int]]:
        """Where element ``k`` alone looks like itself along its own row and column (working pixels), exactly, and
        their sums: the places a copy of it stands that the drawn elements' shared repeats (clustered, the best
        supported kept) may have rounded off or left out."""
        if self.crops[k] is None:
            return []
        patch, (mx, my) = self.crops[k]
        at = (round(self.boxes[k, 0]) - mx, round(self.boxes[k, 1]) - my)
        sx = [s for s, _ in _votes(self.norm, patch, at, 0, (mx, my))][:MAX_SHIFTS]
        sy = [s for s, _ in _votes(self.norm, patch, at, 1, (mx, my))][:MAX_SHIFTS]
        return [(dx, 0) for dx in sx] + [(0, dy) for dy in sy] + [(dx, dy) for dx in sx for dy in sy]

    def _core(self, k: int) -> np.ndarray | None:
        """Element ``k``'s patch without its context, None where that is too small or flat: read once, for every
        shift it is carried by."""
        if k not in self.cores:
            patch, (mx, my) = self.crops[k]
            core = patch[my: patch.shape[0] - my, mx: patch.shape[1] - mx]
            self.cores[k] = core if min(core.shape) >= 3 and core.std() > 1e-3 else None
        return self.cores[k]

    def carry(self, k: int, shift: tuple[int, int]) -> tuple[np.ndarray, float] | None:
        """Element ``k`` carried by ``shift`` to where the photo looks most like it (within `JITTER`): (its box in
        the segmentation's pixels, the NCC there), or None where that is off the photo or it has no patch."""
        import cv2

        if self.crops[k] is None:
            return None
        patch, (mx, my) = self.crops[k]
        ph, pw = patch.shape
        h, w = self.norm.shape
        x, y = round(self.boxes[k, 0]) - mx, round(self.boxes[k, 1]) - my
        a, t = x + shift[0] - JITTER, y + shift[1] - JITTER
        if a < 0 or t < 0 or a + pw + 2 * JITTER > w or t + ph + 2 * JITTER > h:
            return None
        r = cv2.matchTemplate(self.norm[t: t + ph + 2 * JITTER, a: a + pw + 2 * JITTER], patch, cv2.TM_CCOEFF_NORMED)
        core = self._core(k)  # the element alone: what its context shares with its neighbours'
        if core is not None:  # the place where both look most like it: the context's best alone may miss the core
            there = self.norm[t + my: t + ph + 2 * JITTER - my, a + mx: a + pw + 2 * JITTER - mx]
            r = np.minimum(r, cv2.matchTemplate(there, core, cv2.TM_CCOEFF_NORMED))
        r = np.where(np.isfinite(r), r, -1.0)
        iy, ix = divmod(int(r.argmax()), r.shape[1])
        sim = float(r[iy, ix])
        dx, dy = (a + ix - x) / self.to_work[0], (t + iy - y) / self.to_work[1]  # in the segmentation's pixels
        return self.drawn[k, 1:] + np.array([dx, dy, dx, dy]), sim


def _carried(drawn: np.ndarray) -> np.ndarray:
    """The rows of ``drawn`` of the `CARRIED` classes, the largest first, at most `MAX_ELEMENTS`."""
    drawn = np.asarray(drawn, dtype=float).reshape(-1, 5)
    drawn = drawn[np.isin(drawn[:, 0], [LABEL_ID[c] for c in CARRIED])]
    area = (drawn[:, 3] - drawn[:, 1]) * (drawn[:, 4] - drawn[:, 2])
    return drawn[np.argsort(-area, kind="stable")[:MAX_ELEMENTS]]


def repeats(levels: Levels, drawn: np.ndarray) -> list[tuple[int, np.ndarray, float]]:
    """(label, box, NCC) of the drawn elements ((n, 5) rows: label, x0, y0, x1, y1 in the segmentation's
    pixels) carried by the photo's repeats to where it looks like them (`MATCH`); see the module's docstring."""
    drawn = _carried(drawn)
    if not len(drawn):
        return []
    reading = _Reading(levels, drawn)
    if reading.flat:
        return []
    out = []
    shifts = reading.shifts(SUPPORT)
    moves = np.array(shifts, dtype=float).reshape(-1, 2) / reading.to_work[:2]  # in the segmentation's pixels
    for k in range(min(len(drawn), MAX_CARRIES // max(1, len(shifts)))):
        same = drawn[drawn[:, 0] == drawn[k, 0], 1:]
        for shift in np.asarray(shifts)[~_onto(drawn[k, 1:], moves, same)].tolist():
            found = reading.carry(k, tuple(shift))
            if found is not None and found[1] >= MATCH:
                out.append((int(drawn[k, 0]), *found))
    return out


def _onto(box: np.ndarray, moves: np.ndarray, same: np.ndarray) -> np.ndarray:
    """Which ``moves`` ((n, 2)) carry ``box`` mostly onto a drawn element of its class (``same``): drawn already."""
    moved = box[None, :] + np.concatenate([moves, moves], axis=1)  # (n, 4)
    ix = np.minimum(moved[:, None, 2], same[None, :, 2]) - np.maximum(moved[:, None, 0], same[None, :, 0])
    iy = np.minimum(moved[:, None, 3], same[None, :, 3]) - np.maximum(moved[:, None, 1], same[None, :, 1])
    shared = (np.clip(ix, 0, None) * np.clip(iy, 0, None)).max(axis=1, initial=0.0)
    return shared > 0.5 * (box[2] - box[0]) * (box[3] - box[1])


Copy = tuple[float, list[tuple[int, np.ndarray]]]  # (NCC, [(label, box)]): one copy of a unit


def unit_copies(levels: Levels, drawn: np.ndarray, unit: np.ndarray) -> list[Copy]:
    """The copies of a unit (``unit``: (m, 5) rows, a window with what is drawn around it, say; ``drawn``: the other
    drawn elements) along the photo's repeats, as (NCC of its largest element there, [(label, box)] of every
    element of the unit carried): each shift that the drawn elements and the unit vote for (one vote is enough: a
    person asked for this unit), where the unit's largest element looks like itself (`MATCH`). Its other elements
    go with it, each to where it looks most like itself nearby."""
    unit = np.asarray(unit, dtype=float).reshape(-1, 5)
    if not len(unit):
        return []
    area = (unit[:, 3] - unit[:, 1]) * (unit[:, 4] - unit[:, 2])
    unit = unit[np.argsort(-area, kind="stable")]
    others = _carried(drawn)
    reading = _Reading(levels, np.concatenate([unit, others]))
    if reading.flat:
        return []
    out = []
    shifts = reading.shifts(1)
    for shift in dict.fromkeys(shifts + reading.own_shifts(0)):  # the shared repeats first, then the unit's own
        head = reading.carry(0, shift)
        if head is None or head[1] < MATCH:
            continue
        moved = head[0] - unit[0, 1:]
        parts = [(int(unit[0, 0]), head[0])]
        for k in range(1, len(unit)):
            found = reading.carry(k, shift)
            parts.append((int(unit[k, 0]), found[0] if found is not None else unit[k, 1:] + moved))
        out.append((head[1], parts))
    return out
