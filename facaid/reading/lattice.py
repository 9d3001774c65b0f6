"""The lattice reader: a real facade's editable procedure, read top-down from its rows and columns of windows.

A person describes a facade as floors of tiles: "five floors of six windows, a shop floor below, the attic above, the
third window of the fourth floor has its blind closed". `read_lattice` reads a segmentation the same way (after
Müller et al. 2007, Riemenschneider et al. 2012 and Zhang et al. 2013), in three steps:

1. **The grid** (`read_grid`). Windows: connected window-or-blind regions of the building (the longest run of
   columns that are mostly not background: a neighbour's strip is left out), but for the strips a balcony or sill
   leaves uncovered (`facaid.editing.windows.whole_windows`); their rows and columns (`window_bands`: bands of
   centres split where the gap is over half the median window height, width; bands whose extents overlap are one;
   a column needs windows in `COLUMN_SUPPORT` of the floors). Floors: horizontal bands that each hold one row of
   windows with its companions, cut between two rows where the label map is most wall, at one offset from their
   windows where the wall allows (`ALIGN`: floors as high as the windows' pitch); the last rows whose bands hold
   doors or shops are the ground floor. Tiles: the columns within the floors, cut the same way; the side margins;
   the attic above.
2. **The typical floor and bay** (`read_floors`). The typical floor is a real one, the medoid of the floors; the
   typical bay the medoid column; the typical tile is where they cross (`facaid.reading.units`). The typical floor
   is that floor as it is: a row of typical tiles with its own cells' deltas, so that a new floor is a copy of it.
   A floor whose own typical tile (its medoid) and whose cell in the typical column both differ is a floor of its
   own tiles (the balcony floor), so that a new bay adds that cell there; the attic and the ground floor are rows
   of their own cells on the same columns, typical where the typical column's is (`_band`).
3. **Exceptions**: every other cell's deltas from what the typical floor lays out there, and the lengths of floors
   and columns off the median by more than `JITTER`. Nothing drawn is priced away.

So `floors` + 1 inserts a copy of the typical floor between the floors, and `bays` + 1 a copy of the typical
column. The result is an ordinary procedure: the pipeline sizes it (`facaid.sizing`) like any other structure.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from facaid.editing.windows import whole_windows
from facaid.grammar.procedure import MAX_COUNT, Node, Override, Procedure, ProcedureError, Size
from facaid.labels import BACKGROUND, FACADE, GLASS, LABEL_ID
from facaid.reading.units import Delta, Deltas, Unit, exact_tree, medoid, resample
from facaid.segmentation import Segmentation, flatten, rasterize, region_boxes

ALIGN = 0.05  # a cut between two bands may move to a line this much less wall to sit at the typical offset
JITTER = 0.08  # a floor or column length off the median by more than this share is its own
COLUMN_SUPPORT = 0.5  # a column of windows needs windows in this share of the floors
DOOR = LABEL_ID["door"]
GROUND_SHARE = 0.05  # a last row of windows whose band is this much door or shop belongs to the ground floor


def window_bands(lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Indices of the boxes [lo, hi) grouped in bands of centres, split where the gap between neighbouring centres
    is over half the median size; bands whose typical extents overlap (wide and narrow windows in one column) are
    one."""
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
    merged = [out[0]]
    for band in out[1:]:
        if np.median(lo[band]) < np.median(hi[merged[-1]]):
            merged[-1] = np.concatenate([merged[-1], band])
        else:
            merged.append(band)
    return merged


def _cut(profile: np.ndarray, lo: int, hi: int, near: float | None = None) -> int:
    """Where to cut between two bands: a line in [lo, hi] whose share of wall (``profile``) is highest, the middle
    of the widest run of such lines; with ``near``, of the lines within `ALIGN` of that share, the one nearest it."""
    lo, hi = int(max(0, lo)), int(min(len(profile), max(lo, hi)))
    if hi <= lo:
        return lo
    seg = profile[lo : hi + 1] if hi < len(profile) else profile[lo:hi]
    best = seg.max()
    if near is not None:
        good = np.flatnonzero(seg >= best - ALIGN)
        return lo + int(good[np.argmin(np.abs(lo + good - near))])
    good = np.flatnonzero(seg >= best - 1e-9)
    runs = np.split(good, np.flatnonzero(np.diff(good) > 1) + 1)
    run = max(runs, key=len)
    return lo + int(run[len(run) // 2])


def _edges(profile: np.ndarray, starts: np.ndarray, ends: np.ndarray, limit: int) -> list[int]:
    """The cuts around bands that start at ``starts`` and end at ``ends`` (sorted): one between each two, each as
    near its band's start less the typical distance of the cuts from their bands as the wall allows (`ALIGN`:
    floors and tiles cut at one offset from their windows are as long as the windows' pitch), and an outer one on
    each side at that distance."""
    inner = [_cut(profile, int(e), int(s)) for e, s in zip(ends[:-1], starts[1:], strict=True)]
    before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    if ALIGN:
        inner = [_cut(profile, int(e), int(s), s - before) for e, s in zip(ends[:-1], starts[1:], strict=True)]
        before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    after = np.median([c - e for e, c in zip(ends[:-1], inner, strict=True)])
    first = int(np.clip(round(starts[0] - before), 0, starts[0]))
    last = int(np.clip(round(ends[-1] + after), ends[-1], limit))
    return [first, *inner, last]


def footprint(label_map: np.ndarray) -> tuple[int, int]:
    """The main building's columns [x0, x1): the longest run of columns that are mostly not background (a
    neighbour's strip beside it, in shadow or cut by the photo, is left out when background parts it off)."""
    building = (label_map != BACKGROUND).mean(axis=0) >= 0.5
    if not building.any():
        return 0, label_map.shape[1]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], building.astype(np.int8), [0]])))
    runs = edges.reshape(-1, 2)
    x0, x1 = max(runs, key=lambda r: r[1] - r[0])
    return int(x0), int(x1)


def _ground_rows(label_map: np.ndarray, ys: list[int]) -> int:
    """How many of the last rows of windows belong to the ground floor: those whose bands hold doors or shops."""
    shopfront = np.isin(label_map, (LABEL_ID["door"], LABEL_ID["shop"])).mean(axis=1)
    n = 0
    for i in range(len(ys) - 2, 0, -1):  # the first row stays a floor
        if shopfront[ys[i] : ys[i + 1]].mean() < GROUND_SHARE:
            break
        n += 1
    return n


@dataclass
class Grid:
    """The floors' cuts ``ys`` (rows + 1 of them) and the tiles' ``xs`` (columns + 1) of a label map."""

    label_map: np.ndarray
    ys: list[int]
    xs: list[int]

    @property
    def rows(self) -> int:
        return len(self.ys) - 1

    @property
    def columns(self) -> int:
        return len(self.xs) - 1

    def cell(self, i: int, j: int) -> np.ndarray:
        return self.label_map[self.ys[i] : self.ys[i + 1], self.xs[j] : self.xs[j + 1]]

    @property
    def heights(self) -> np.ndarray:
        return np.diff(self.ys).astype(float)

    @property
    def widths(self) -> np.ndarray:
        return np.diff(self.xs).astype(float)


def read_grid(label_map: np.ndarray, windows: np.ndarray) -> Grid | None:
    """Step 1 (see the module's docstring): the floors and tiles of the windows' rows and columns, or None where
    there are fewer than two of either."""
    height, width = label_map.shape
    if len(windows) < 4:
        return None
    rows = window_bands(windows[:, 1], windows[:, 3])
    if not 2 <= len(rows) <= MAX_COUNT:
        return None
    wall = label_map == FACADE
    tops = np.array([np.median(windows[r, 1]) for r in rows])
    bottoms = np.array([np.median(windows[r, 3]) for r in rows])
    ys = _edges(wall.mean(axis=1), tops, bottoms, height)
    if any(b <= a for a, b in zip(ys[:-1], ys[1:], strict=True)):
        return None
    n_rows = len(rows) - _ground_rows(label_map, ys)
    ys = ys[: n_rows + 1]
    row_of = np.concatenate([np.full(len(r), i) for i, r in enumerate(rows[:n_rows])])
    upper = windows[np.concatenate(rows[:n_rows])]
    cols = window_bands(upper[:, 0], upper[:, 2])
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
    return Grid(label_map, ys, xs)


def read_lattice(seg: Segmentation, group: tuple[int, int] = (1, 1)) -> Procedure | None:
    """The editable procedure of a segmentation (see the module's docstring), or None where it has no lattice of
    windows (fewer than two rows or two columns). ``group``: (floors, bays) of the grid read as one (`grouped`)."""
    flat = flatten(seg)
    label_map = rasterize(flat)
    height, width = label_map.shape
    grid = grouped(_grid(flat, label_map), group)
    if grid is None:
        return None
    proc = Procedure(width, height, read_floors(grid), {"source": "facaid.lattice"})
    try:
        return Procedure.from_dict(proc.to_dict())
    except ProcedureError:  # a reading past the grammar's limits (more exceptions than a repeat holds): none
        return None


def readings(seg: Segmentation) -> Iterator[tuple[tuple[int, int], Procedure]]:
    """The candidate readings of a segmentation, each with its ``group``: the grid as read, and where they fit it,
    its floors read two by two (a floor with a mezzanine: two rows of windows) and its columns two by two (a bay of
    a pair of windows). The pipeline keeps the most accurate one whose edits pass."""
    flat = flatten(seg)
    label_map = rasterize(flat)
    grid = _grid(flat, label_map)
    for group in GROUPS:
        g = grouped(grid, group)
        if g is not None:
            proc = Procedure(label_map.shape[1], label_map.shape[0], read_floors(g), {"source": "facaid.lattice"})
            try:
                yield group, Procedure.from_dict(proc.to_dict())
            except ProcedureError:
                continue


GROUPS = ((1, 1), (2, 1), (1, 2))  # (floors, bays) read as one: the candidate readings


def grouped(grid: Grid | None, group: tuple[int, int]) -> Grid | None:
    """``grid`` with every ``group[0]`` floors one floor and every ``group[1]`` columns one bay, or None where the
    counts do not divide by them or fewer than two of either would be left."""
    if grid is None:
        return None
    (gy, gx), n, m = group, grid.rows, grid.columns
    if n % gy or m % gx or n // gy < 2 or m // gx < 2:
        return None
    return Grid(grid.label_map, grid.ys[::gy], grid.xs[::gx])


def _grid(flat: Segmentation, label_map: np.ndarray) -> Grid | None:
    """The grid of a flattened segmentation: its windows, but strips, within the main building's footprint."""
    fx0, fx1 = footprint(label_map)
    windows = whole_windows(region_boxes(flat.to_array(), GLASS))  # a strip of a window is no window of the lattice
    centres = (windows[:, 0] + windows[:, 2]) / 2
    return read_grid(label_map, windows[(centres >= fx0) & (centres < fx1)])


def read_floors(grid: Grid) -> Node:
    """Steps 2 and 3 (see the module's docstring): the building as attic, the floors repeat with its exceptions,
    and the ground floor."""
    label_map = grid.label_map
    height, width = label_map.shape
    ys, xs, n_rows, n_cols = grid.ys, grid.xs, grid.rows, grid.columns
    deltas = Deltas(height * width)
    th, tw = int(round(np.median(grid.heights))), int(round(np.median(grid.widths)))
    same = [[resample(grid.cell(i, j), th, tw) for j in range(n_cols)] for i in range(n_rows)]
    floor = medoid(same)  # the typical floor: a real one
    bay = medoid([[same[i][j] for i in range(n_rows)] for j in range(n_cols)])  # the typical column
    th, tw = int(grid.heights[floor]), int(grid.widths[bay])  # a new floor (bay) is as high (wide) as the typical
    tile = Unit(grid.cell(floor, bay), th, tw)
    # the typical floor as it is: typical tiles, and its own cells' deltas (on its row of tiles, so that a new floor
    # has them too); what it lays out in each column is what the other floors' deltas are read against
    own = [deltas.of(tile, grid.cell(floor, j), relabel=False) for j in range(n_cols)]
    row = _row(tile, own, grid.widths, bay)
    laid = [Unit(grid.cell(floor, j), *grid.cell(floor, j).shape) if own[j] else tile for j in range(n_cols)]
    margins = [Unit(label_map[ys[floor] : ys[floor + 1], a:b], th, b - a) if b > a else None
               for a, b in ((0, xs[0]), (xs[-1], width))]
    items: list[tuple[Size, Node]] = []
    if margins[0] is not None:
        items.append((Size("abs", float(xs[0])), margins[0].tree))
    bay_index = len(items)
    items.append((Size("flt", float(xs[-1] - xs[0])), row))
    if margins[1] is not None:
        items.append((Size("abs", float(width - xs[-1])), margins[1].tree))
    typical = Node.split("x", items, role="floor") if len(items) > 1 else _role(row, "floor")
    inside = (0, bay_index) if len(items) > 1 else (0,)
    floors = Node.repeat("y", n_rows, [(Size("flt", float(th)), typical)], role="floors")
    for i in range(n_rows):
        if i == floor:
            continue
        mine = medoid([[cell] for cell in same[i]])  # the floor's own typical tile
        if all(any(node is not None for _, _, node in deltas.of(tile, grid.cell(i, j))) for j in {bay, mine}):
            # its tiles differ alike (the balcony floor), in the typical column too: a floor of its own tiles, the
            # typical column's its typical one, so that a new bay adds that column's cell to it
            unit = Unit(grid.cell(i, bay), th, tw)
            variant = _row(unit, [deltas.of(unit, grid.cell(i, j)) for j in range(n_cols)], grid.widths, bay)
            floors.exceptions.append(Override(i, inside, node=variant))
        else:
            floors.exceptions += [Override(i, (*inside, j, *path), size, node) for j in range(n_cols)
                                  for path, size, node in deltas.of(laid[j], grid.cell(i, j))]
        for m, (unit, (a, b)) in enumerate(zip(margins, ((0, xs[0]), (xs[-1], width)), strict=True)):
            if unit is not None:
                where = (0, 0 if m == 0 else len(items) - 1)
                floors.exceptions += [Override(i, (*where, *path), size, node)
                                      for path, size, node in deltas.of(unit, label_map[ys[i] : ys[i + 1], a:b])]
    floors.exceptions += [Override(i, (0,), size=Size("flt", float(h))) for i, h in enumerate(grid.heights)
                          if abs(h / th - 1) > JITTER]
    floors.exceptions = _merge_paths(floors.exceptions)
    parts: list[tuple[Size, Node]] = []
    if ys[0] > 0:
        parts.append((Size("abs", float(ys[0])), _band(label_map[: ys[0]], xs, bay, grid.widths, "attic", deltas)))
    parts.append((Size("flt", float(ys[-1] - ys[0])), floors))
    if ys[-1] < height:
        parts.append((Size("abs", float(height - ys[-1])),
                      _band(label_map[ys[-1] :], xs, bay, grid.widths, "ground", deltas)))
    return Node.split("y", parts, role="facade") if len(parts) > 1 else floors


def _row(unit: Unit, cells: list[list[Delta]], widths: np.ndarray, bay: int) -> Node:
    """A row of tiles: a repeat of ``unit`` as wide as the typical column ``bay``, with each cell's deltas from it
    and the columns' own widths where they are off that by more than `JITTER`."""
    row = Node.repeat("x", len(cells), [(Size("flt", float(widths[bay])), _role(unit.tree.copy(), "tile"))],
                      role="bay")
    for j, cell in enumerate(cells):
        row.exceptions += [Override(j, (0, *path), size, node) for path, size, node in cell]
    own = [Override(j, (0,), size=Size("flt", float(w))) for j, w in enumerate(widths)
           if abs(w / widths[bay] - 1) > JITTER]
    row.exceptions = _merge_paths(row.exceptions + own)
    return row


def _band(label_map: np.ndarray, xs: list[int], bay: int, tile_w: np.ndarray, role: str, deltas: Deltas) -> Node:
    """The attic or the ground floor on the floors' columns: its margins exact, and between them a row of its own
    cells, the typical column's as its typical tile and each other cell its deltas from it, so that a bay more adds
    the typical column's cell here too and the shops and doors stay over their columns."""
    height, width = label_map.shape
    if height < 2:
        return _role(exact_tree(label_map), role)
    cells = [label_map[:, xs[j] : xs[j + 1]] for j in range(len(xs) - 1)]
    unit = Unit(cells[_typical_cell(cells, bay, int(tile_w[bay]))], height, int(tile_w[bay]))
    row = _row(unit, [deltas.of(unit, cell) for cell in cells], tile_w, bay)
    items: list[tuple[Size, Node]] = []
    if xs[0] > 0:
        items.append((Size("abs", float(xs[0])), exact_tree(label_map[:, : xs[0]])))
    items.append((Size("flt", float(xs[-1] - xs[0])), row))
    if xs[-1] < width:
        items.append((Size("abs", float(width - xs[-1])), exact_tree(label_map[:, xs[-1] :])))
    return Node.split("x", items, role=role) if len(items) > 1 else _role(row, role)


def _typical_cell(cells: list[np.ndarray], bay: int, width: int) -> int:
    """The cell of a band that a new bay repeats: the typical column's, but where it holds a door and others do
    not, the medoid of those without (a new bay beside the entrance is another shop, not a second door)."""
    plain = [j for j, cell in enumerate(cells) if not (cell == DOOR).any()]
    if not plain or len(plain) == len(cells) or bay in plain:
        return bay
    return plain[medoid([[resample(cells[j], cells[j].shape[0], width)] for j in plain])]


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


__all__ = ["COLUMN_SUPPORT", "GROUND_SHARE", "GROUPS", "JITTER", "Grid", "footprint", "grouped",
           "read_floors", "read_grid", "read_lattice", "readings", "window_bands"]
