"""The lattice reader: a real facade's editable procedure, read top-down from its rows and columns of windows.

A person describes a facade as floors of tiles: "five floors of six windows, a shop floor below, the attic above, the
third window of the fourth floor has its blind closed". `read_lattice` reads a segmentation the same way (after
Müller et al. 2007, Riemenschneider et al. 2012 and Zhang et al. 2013):

1. **Windows**: connected window-or-blind regions of the building (the longest run of columns that are mostly not
   background: a neighbour's strip is left out), but for the strips a balcony or sill leaves uncovered (`WHOLE`),
   their **rows** and **columns** (bands of centres split where the gap is over half the median window height, width;
   bands whose extents overlap are one; a column needs windows in `COLUMN_SUPPORT` of the floors).
2. **Floors**: horizontal bands that each hold one row of windows with its companions, cut between two rows where the
   label map is most wall; the last rows whose bands hold doors or shops are the **ground** floor. **Tiles**: the
   columns within the floors, cut the same way; the side margins; the **attic** above the first floor. The attic and
   the ground floor are rows on the same columns, so a bay more adds one to them too.
3. **Typical copies**: the tiles of the grid resampled to the median tile and voted pixel by pixel, the majority
   tidied as a person draws (each element a box, slivers left out) and written as an exact tree: one subtree that
   every copy of the repeats shares. Floors and columns whose lengths are within `JITTER` of the median share it.
4. **Exceptions** (`facaid.grammar.procedure.Override`), each a delta of the typical copy that must earn its leaves
   (`LEAF_GAIN`): a column that differs alike on every floor gets its own tile (on the row's repeat, so a new floor
   has it too), a floor whose tiles differ alike (the balcony floor) its own row of them, and a copy its deltas:
   sizes where its tree has the typical shape but lays out differently by more than a hand's jitter (no leaf), leaves
   it paints with another label (a closed blind: one leaf; a missing sill: none), or its own tree. Pixels within
   `EDGE` of an edge count for nothing: a hand's jitter is restored, not copied.

The result is an ordinary procedure: the pipeline sizes it (`facaid.sizing`) like any other structure.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.decompose import tree_of_label_map
from facaid.grammar.execute import execute
from facaid.grammar.procedure import MAX_COUNT, Node, Override, Procedure, ProcedureError, Size
from facaid.grammar.shapes import elements, leaf_paths, shape
from facaid.labels import BACKGROUND, FACADE, GLASS, LABEL_ID, LABELS, PRIORITY
from facaid.metrics import near_edges
from facaid.segmentation import Segmentation, decompose_grid, flatten, rasterize, region_boxes

ONE_OFF = 1.0  # a delta of one copy (not a column's, not a floor's) pays this many times a leaf's price
DELETE = 0.0  # an element left out of a copy pays this share of a leaf (an annotator may have missed it)
JITTER = 0.08  # a floor or column length off the median by more than this share is its own
LEAF_GAIN = 0.0002  # an exception's leaf must put right this share of the image's pixels
EXCEPTIONS = True  # False: the typical copies only (with their own lengths), for measuring
WHOLE = 0.35  # a window region smaller than this share of the median window's height or width is a strip of one
COLUMN_SUPPORT = 0.5  # a column of windows needs windows in this share of the floors
GROUND_SHARE = 0.05  # a last row of windows whose band is this much door or shop belongs to the ground floor
EDGE = 0.06  # a copy that differs only this close (a share of the unit's side) to an edge differs by jitter
MIN_AREA = 0.01  # regions and leaves under this share of a unit are not read as parts of it
SLIVER = 0.05  # an element region thinner than this share of the unit's shorter side is left out


def _bands(lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Indices of the boxes [lo, hi) grouped in bands of centres, split where the gap between neighbouring centres
    is over half the median size."""
    centres = (lo + hi) / 2
    order = np.argsort(centres, kind="stable")
    gap = 0.5 * np.median(hi - lo)
    out, current = [], [order[0]]
    for a, b in zip(order[:-1], order[1:], strict=True):
        if centres[b] - centres[a] > gap:
            out.append(np.array(current))
            current = []
        current.append(b)
    out.append(np.array(current))
    # bands whose typical extents overlap (wide and narrow windows in one column) are one
    merged = [out[0]]
    for band in out[1:]:
        if np.median(lo[band]) < np.median(hi[merged[-1]]):
            merged[-1] = np.concatenate([merged[-1], band])
        else:
            merged.append(band)
    return merged


def _cut(profile: np.ndarray, lo: int, hi: int) -> int:
    """Where to cut between two bands: the line in [lo, hi] whose share of wall (``profile``) is highest, the
    middle of the widest run of such lines."""
    lo, hi = int(max(0, lo)), int(min(len(profile), max(lo, hi)))
    if hi <= lo:
        return lo
    seg = profile[lo : hi + 1] if hi < len(profile) else profile[lo:hi]
    best = seg.max()
    good = np.flatnonzero(seg >= best - 1e-9)
    runs = np.split(good, np.flatnonzero(np.diff(good) > 1) + 1)
    run = max(runs, key=len)
    return lo + int(run[len(run) // 2])


def _edges(profile: np.ndarray, starts: np.ndarray, ends: np.ndarray, limit: int) -> list[int]:
    """The cuts around bands that start at ``starts`` and end at ``ends`` (sorted): one between each two, and an
    outer one on each side at the typical distance of the inner cuts from their bands."""
    inner = [_cut(profile, int(e), int(s)) for e, s in zip(ends[:-1], starts[1:], strict=True)]
    before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    after = np.median([c - e for e, c in zip(ends[:-1], inner, strict=True)])
    first = int(np.clip(round(starts[0] - before), 0, starts[0]))
    last = int(np.clip(round(ends[-1] + after), ends[-1], limit))
    return [first, *inner, last]


def _resample(crop: np.ndarray, h: int, w: int) -> np.ndarray:
    """``crop`` resampled to h x w by its nearest pixels."""
    ys = np.minimum((np.arange(h) + 0.5) * crop.shape[0] / h, crop.shape[0] - 1).astype(np.int64)
    xs = np.minimum((np.arange(w) + 0.5) * crop.shape[1] / w, crop.shape[1] - 1).astype(np.int64)
    return crop[ys][:, xs]


def _vote(crops: list[np.ndarray]) -> np.ndarray:
    """The label each pixel has in most of the crops (all of one shape)."""
    stack = np.stack(crops)
    counts = np.stack([(stack == c).sum(axis=0) for c in range(len(LABELS))])
    return counts.argmax(axis=0).astype(np.uint8)


def _tidy(label_map: np.ndarray) -> np.ndarray:
    """A voted map as a person would draw it: each element's connected region as its bounding box, painted in the
    paint order on the commonest of wall and background, the regions under `MIN_AREA` of the map left out."""
    h, w = label_map.shape
    ground = FACADE if (label_map == FACADE).sum() >= (label_map == BACKGROUND).sum() else BACKGROUND
    out = np.full((h, w), ground, dtype=np.uint8)
    rows = decompose_grid(label_map.astype(np.int64) + 1)  # + 1: background is a region too
    rows[:, 0] -= 1
    for label in sorted({int(v) for v in rows[:, 0]}, key=lambda v: PRIORITY[v]):
        if label == ground:
            continue
        for x0, y0, x1, y1 in region_boxes(rows, (label,)):
            if (x1 - x0) * (y1 - y0) >= MIN_AREA * h * w:
                out[y0:y1, x0:x1] = label
    # what a later element left of an earlier one (a strip of window under a balcony): a sliver, wall again
    painted = decompose_grid(out.astype(np.int64) + 1)
    painted[:, 0] -= 1
    glass = region_boxes(painted, GLASS)  # windows with their blinds, as the lattice sees them
    whole = (glass[:, 2:] - glass[:, :2]).max(axis=0) if len(glass) else np.zeros(2)
    for label in {int(v) for v in painted[:, 0]} - {ground}:
        for x0, y0, x1, y1 in region_boxes(painted, (label,)):
            small = (x1 - x0) * (y1 - y0) < MIN_AREA * h * w or min(x1 - x0, y1 - y0) < SLIVER * min(h, w)
            if label in GLASS:  # and a strip of a window is not a window of its own
                small = small or (x1 - x0) < WHOLE * whole[0] or (y1 - y0) < WHOLE * whole[1]
            if small:
                region = out[y0:y1, x0:x1]
                region[region == label] = ground
    return out


def _windows(node: Node) -> Node:
    """The tree with its window leaves in the role ``window``, so that the window size is a named parameter."""
    for _, n in node.walk():
        if n.rule == "leaf" and n.label == "window":
            n.role = "window"
    return node


class _Unit:
    """A typical unit (a tile, a margin, a column's own tile): the tidied majority of its copies, resampled to one
    size, and the exact tree of that map."""

    def __init__(self, crops: list[np.ndarray], h: int, w: int):
        self.h, self.w = h, w
        self.map = _tidy(_vote([_resample(c, h, w) for c in crops]))
        self.tree = _windows(tree_of_label_map(self.map))
        boxes = execute(Procedure(w, h, self.tree))
        self.leaves = [(path, leaf, box[1:]) for (path, leaf), box in zip(leaf_paths(self.tree), boxes,
                                                                          strict=True)]

    def wrong(self, crop: np.ndarray) -> int:
        """The pixels of ``crop`` the typical unit, laid out on it, gets wrong away from ``crop``'s edges (where
        a hand-drawn edge may be off: jitter that the typical copy restores, not a difference)."""
        return _off(_resample(self.map, *crop.shape), crop)


def _jitter_band(crop: np.ndarray) -> np.ndarray:
    """The pixels of ``crop`` within `EDGE` of its shorter side of an edge: where a hand's jitter is forgiven."""
    r = max(1, round(EDGE * min(crop.shape)))
    return near_edges(crop, r, r)


def _off(drawn: np.ndarray, crop: np.ndarray) -> int:
    return int(((drawn != crop) & ~_jitter_band(crop)).sum())


def _resized(reference: Node, own: Node, jitter: float, path: tuple[int, ...] = ()) -> list[tuple[tuple, Size]]:
    """The sizes of ``own`` (a tree of ``reference``'s shape) that differ from the reference's by more than
    ``jitter`` pixels, by child path; a split's only floating child takes what is left whatever its value."""
    out = []
    floating = sum(1 for s in reference.sizes if s.mode == "flt")
    for i, (a, b) in enumerate(zip(reference.sizes, own.sizes, strict=True)):
        if (a.mode != b.mode or abs(a.value - b.value) > jitter) and not (a.mode == b.mode == "flt" and floating == 1):
            out.append(((*path, i), b))
    for i, (a, b) in enumerate(zip(reference.children, own.children, strict=True)):
        if a.rule != "leaf":
            out.extend(_resized(a, b, jitter, (*path, i)))
    return out


class _Choice:
    """Exceptions that each buy pixels with leaves: kept where a leaf buys at least `LEAF_GAIN` of the image."""

    def __init__(self, area: int):
        self.least = LEAF_GAIN * area

    def own(self, reference: _Unit, crop: np.ndarray) -> list[tuple[tuple[int, ...], Size | None, Node | None]]:
        """What makes ``reference`` into ``crop``, as (path inside the unit, size, node) deltas: where ``crop``'s
        own tree has the reference's shape, the sizes it lays out differently by more than a hand's jitter (they
        cost no leaf); else the reference's leaves that ``crop`` paints mostly with another label, relabelled, or
        ``crop``'s own tree, whichever puts more right for its leaves (`net`); else nothing."""
        if not EXCEPTIONS:
            return []
        tidy = _tidy(crop)
        node = tree_of_label_map(tidy)
        if shape(node) == shape(reference.tree):
            jitter = max(1.0, EDGE * min(crop.shape))
            return [(path, size, None) for path, size in _resized(reference.tree, node, jitter)]
        drawn = _resample(reference.map, *crop.shape)
        steady = ~_jitter_band(crop)
        before = int(((drawn != crop) & steady).sum())
        if not before:
            return []
        # leaves of the reference that this copy paints mostly with another label: relabelled, a leaf each
        relabels, cost = [], 0
        sy, sx = crop.shape[0] / reference.h, crop.shape[1] / reference.w
        for path, leaf, (x0, y0, x1, y1) in reference.leaves:
            a, b, c, d = round(x0 * sx), round(y0 * sy), round(x1 * sx), round(y1 * sy)
            if min(c - a, d - b) < SLIVER * min(crop.shape) or (c - a) * (d - b) < MIN_AREA * crop.size:
                continue  # a sliver of the unit relabelled would be an element of its own
            counts = np.bincount(crop[b:d, a:c][steady[b:d, a:c]], minlength=len(LABELS))
            best, own = int(counts.argmax()), LABEL_ID[leaf.label]
            price = ONE_OFF * (1 if best not in (FACADE, BACKGROUND) else DELETE)
            if best != own and self.worth(counts[best] - counts[own], price):
                relabels.append((path, None, Node.leaf(LABELS[best])))
                drawn[b:d, a:c] = best
                cost += price
        relabelled = before - int(((drawn != crop) & steady).sum())
        whole = before - _off(tidy, crop)
        if self.net(whole, ONE_OFF * max(DELETE, elements(node))) > max(0.0, self.net(relabelled, cost)):
            return [((), None, node)]
        return relabels if self.net(relabelled, cost) > 0 else []

    def worth(self, gain: float, cost: int) -> bool:
        return gain > 0 and gain >= self.least * cost

    def net(self, gain: float, cost: int) -> float:
        """Pixels put right less what the leaves cost (each `LEAF_GAIN` of the image): above 0, worth it."""
        return gain - self.least * cost if gain > 0 else 0.0


def _footprint(label_map: np.ndarray) -> tuple[int, int]:
    """The main building's columns [x0, x1): the longest run of columns that are mostly not background (a
    neighbour's strip beside it, in shadow or cut by the photo, is left out when background parts it off)."""
    building = (label_map != BACKGROUND).mean(axis=0) >= 0.5
    if not building.any():
        return 0, label_map.shape[1]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], building.astype(np.int8), [0]])))
    runs = edges.reshape(-1, 2)
    x0, x1 = max(runs, key=lambda r: r[1] - r[0])
    return int(x0), int(x1)


def read_lattice(seg: Segmentation) -> Procedure | None:
    """The editable procedure of a segmentation (see the module's docstring), or None where it has no lattice of
    windows (fewer than two rows or two columns)."""
    flat = flatten(seg)
    label_map = rasterize(flat)
    height, width = label_map.shape
    fx0, fx1 = _footprint(label_map)
    windows = region_boxes(flat.to_array(), GLASS)
    if len(windows):  # the strips of a window a balcony or a sill left uncovered are not windows of the lattice
        h, w = windows[:, 3] - windows[:, 1], windows[:, 2] - windows[:, 0]
        windows = windows[(h >= WHOLE * np.median(h)) & (w >= WHOLE * np.median(w))]
    centres = (windows[:, 0] + windows[:, 2]) / 2
    windows = windows[(centres >= fx0) & (centres < fx1)] - np.array([fx0, 0, fx0, 0])
    main = _read_main(label_map, windows + np.array([fx0, 0, fx0, 0]))
    if main is None:
        return None
    proc = Procedure(width, height, main, {"source": "facaid.lattice"})
    try:
        return Procedure.from_dict(proc.to_dict())
    except ProcedureError:  # a reading past the grammar's limits (more exceptions than a repeat holds): none
        return None


def _ground_rows(label_map: np.ndarray, ys: list[int]) -> int:
    """How many of the last rows of windows belong to the ground floor: those whose bands hold doors or shops."""
    shopfront = np.isin(label_map, (LABEL_ID["door"], LABEL_ID["shop"])).mean(axis=1)
    n = 0
    for i in range(len(ys) - 2, 0, -1):  # the first row stays a floor
        if shopfront[ys[i] : ys[i + 1]].mean() < GROUND_SHARE:
            break
        n += 1
    return n


def _read_main(label_map: np.ndarray, windows: np.ndarray) -> Node | None:
    """The building: attic, the floors repeat with its exceptions, ground floor (see the module's docstring)."""
    height, width = label_map.shape
    if len(windows) < 4:
        return None
    rows = _bands(windows[:, 1], windows[:, 3])
    if not 2 <= len(rows) <= MAX_COUNT:
        return None
    wall = label_map == FACADE
    # floors: a cut between each two rows where the map's lines are most wall
    tops = np.array([np.median(windows[r, 1]) for r in rows])
    bottoms = np.array([np.median(windows[r, 3]) for r in rows])
    ys = _edges(wall.mean(axis=1), tops, bottoms, height)
    if any(b <= a for a, b in zip(ys[:-1], ys[1:], strict=True)):
        return None
    n_rows = len(rows) - _ground_rows(label_map, ys)
    ys = ys[: n_rows + 1]
    row_of = np.concatenate([np.full(len(r), i) for i, r in enumerate(rows[:n_rows])])
    upper = windows[np.concatenate(rows[:n_rows])]
    cols = _bands(upper[:, 0], upper[:, 2])
    # columns are those most floors have a window in; the others' windows are content of their neighbours' tiles
    # (a floor whose windows sit half a bay over does not halve every tile)
    support = [len(set(row_of[c].tolist())) / n_rows for c in cols]
    strong = [c for c, share in zip(cols, support, strict=True) if share >= COLUMN_SUPPORT]
    if len(strong) >= 2:
        cols = strong
    if not 2 <= len(cols) <= MAX_COUNT:
        return None
    lefts = np.array([np.median(upper[c, 0]) for c in cols])
    rights = np.array([np.median(upper[c, 2]) for c in cols])
    xs = _edges(wall[ys[0] : ys[-1]].mean(axis=0), lefts, rights, width)
    if any(b <= a for a, b in zip(xs[:-1], xs[1:], strict=True)):
        return None
    choice = _Choice(height * width)
    floor_h, tile_w = np.diff(ys).astype(float), np.diff(xs).astype(float)
    th, tw = int(round(np.median(floor_h))), int(round(np.median(tile_w)))
    n_cols = len(cols)
    cells = [[label_map[ys[i] : ys[i + 1], xs[j] : xs[j + 1]] for j in range(n_cols)] for i in range(n_rows)]
    tile = _Unit([c for row in cells for c in row], th, tw)
    # a column that differs alike on every floor gets its own tile, which every floor (a new one too) has
    bays = Node.repeat("x", n_cols, [(Size("flt", float(np.median(tile_w))), _role(tile.tree, "tile"))], role="bay")
    reference = []
    for j in range(n_cols):
        column = _Unit([cells[i][j] for i in range(n_rows)], th, tw)
        gain = sum(tile.wrong(cells[i][j]) - column.wrong(cells[i][j]) for i in range(n_rows))
        if n_rows > 1 and EXCEPTIONS and choice.worth(gain, elements(column.tree)):
            bays.exceptions.append(Override(j, (0,), node=column.tree))
            reference.append(column)
        else:
            reference.append(tile)
    bays.exceptions += _widths(tile_w)
    bays.exceptions = _merge_paths(bays.exceptions)
    margins = [_Unit([label_map[ys[i] : ys[i + 1], a:b] for i in range(n_rows)], th, b - a) if b > a else None
               for a, b in ((0, xs[0]), (xs[-1], width))]
    items: list[tuple[Size, Node]] = []
    if margins[0] is not None:
        items.append((Size("abs", float(xs[0])), margins[0].tree))
    bay_index = len(items)
    items.append((Size("flt", float(xs[-1] - xs[0])), bays))
    if margins[1] is not None:
        items.append((Size("abs", float(width - xs[-1])), margins[1].tree))
    floor = Node.split("x", items, role="floor") if len(items) > 1 else _role(bays, "floor")
    inside = (0, bay_index) if len(items) > 1 else (0,)
    floors = Node.repeat("y", n_rows, [(Size("flt", float(np.median(floor_h))), floor)], role="floors")
    for i in range(n_rows):
        # a floor whose tiles differ alike (balconies on this one) gets its own row of them
        row = _Unit(cells[i], th, tw)
        gain = sum(reference[j].wrong(cells[i][j]) - row.wrong(cells[i][j]) for j in range(n_cols))
        refs = reference
        if n_cols > 1 and n_rows > 1 and EXCEPTIONS and choice.worth(gain, elements(row.tree)):
            variant = Node.repeat("x", n_cols, [(bays.sizes[0], _role(row.tree, "tile"))], role=bays.role)
            variant.exceptions = _widths(tile_w)
            floors.exceptions.append(Override(i, inside, node=variant))
            refs = [row] * n_cols
        for j in range(n_cols):
            floors.exceptions += [Override(i, (*inside, j, *path), size, node)
                                  for path, size, node in choice.own(refs[j], cells[i][j])]
        for m, (unit, (a, b)) in enumerate(zip(margins, ((0, xs[0]), (xs[-1], width)), strict=True)):
            if unit is not None:
                where = (0, 0 if m == 0 else len(items) - 1)
                floors.exceptions += [Override(i, (*where, *path), size, node)
                                      for path, size, node in choice.own(unit, label_map[ys[i] : ys[i + 1], a:b])]
    floors.exceptions += [Override(i, (0,), size=Size("flt", float(h))) for i, h in enumerate(floor_h)
                          if abs(h / np.median(floor_h) - 1) > JITTER]
    floors.exceptions = _merge_paths(floors.exceptions)
    parts: list[tuple[Size, Node]] = []
    if ys[0] > 0:
        parts.append((Size("abs", float(ys[0])), _band(label_map[: ys[0]], xs, tile_w, "attic", choice)))
    parts.append((Size("flt", float(ys[-1] - ys[0])), floors))
    if ys[-1] < height:
        parts.append((Size("abs", float(height - ys[-1])), _band(label_map[ys[-1] :], xs, tile_w, "ground", choice)))
    return Node.split("y", parts, role="facade") if len(parts) > 1 else floors


def _widths(tile_w: np.ndarray) -> list[Override]:
    """The columns whose width is off the median by more than `JITTER`: their own widths."""
    typical = np.median(tile_w)
    return [Override(j, (0,), size=Size("flt", float(w))) for j, w in enumerate(tile_w)
            if abs(w / typical - 1) > JITTER]


def _band(label_map: np.ndarray, xs: list[int], tile_w: np.ndarray, role: str, choice: _Choice) -> Node:
    """The attic or the ground floor on the floors' columns: its margins exact, and between them a row of its own
    tiles, one per column, typical where they look alike and each its own elsewhere, so that a bay more adds one
    here too and its shops and doors stay over their columns."""
    height, width = label_map.shape
    if height < 2:
        return _role(tree_of_label_map(label_map), role)
    cells = [label_map[:, xs[j] : xs[j + 1]] for j in range(len(xs) - 1)]
    unit = _Unit(cells, height, int(round(np.median(tile_w))))
    row = Node.repeat("x", len(cells), [(Size("flt", float(np.median(tile_w))), _role(unit.tree, "tile"))],
                      role="bay")
    for j, cell in enumerate(cells):
        row.exceptions += [Override(j, (0, *path), size, node) for path, size, node in choice.own(unit, cell)]
    row.exceptions = _merge_paths(row.exceptions + _widths(tile_w))
    items: list[tuple[Size, Node]] = []
    if xs[0] > 0:
        items.append((Size("abs", float(xs[0])), tree_of_label_map(label_map[:, : xs[0]])))
    items.append((Size("flt", float(xs[-1] - xs[0])), row))
    if xs[-1] < width:
        items.append((Size("abs", float(width - xs[-1])), tree_of_label_map(label_map[:, xs[-1] :])))
    return Node.split("x", items, role=role) if len(items) > 1 else _role(row, role)


def _merge_paths(deltas: list[Override]) -> list[Override]:
    """One override per (copy, path): a size and a node at the same place become one."""
    out: dict[tuple, Override] = {}
    for o in deltas:
        key = (o.copy, o.path)
        if key in out:
            prev = out[key]
            o = Override(o.copy, o.path, o.size or prev.size, o.node or prev.node)
        out[key] = o
    return list(out.values())


def _role(node: Node, role: str) -> Node:
    """``node`` with ``role``; a leaf keeps its own (a role on a leaf names it), so it goes on a one-child split."""
    if node.rule == "leaf":
        return Node.split("y", [(Size("flt", 1.0), node)], role=role)
    node.role = role
    return node


__all__ = ["COLUMN_SUPPORT", "DELETE", "EDGE", "JITTER", "LEAF_GAIN", "MIN_AREA", "ONE_OFF", "SLIVER", "WHOLE",
           "read_lattice"]
