"""A procedure's elements, one box each: what every export holds (the annotation formats COCO, LabelMe and CVAT;
the 3D, BIM and GIS ones through `facaid.formats.relief`), so that no two formats count its windows differently.

The rectangles a procedure draws (`facaid.grammar.execute.to_segmentation`) tile the image: the wall in pieces
around every element, and an element that spans several tiles (a cornice along a floor, a molding) in one piece per
tile; a window behind a blind shows as the frame of pieces around it. An element is what an annotator draws
instead (`elements`), computed from the label map alone (its picture, labels.png, gives the same boxes:
`label_map_elements`):

- the label map cut into its canonical rectangles (`facaid.segmentation.decompose_grid`: maximal runs of a row,
  joined down while they keep their columns);
- then, again and again until nothing changes, two boxes of one label **merged into their bounding box** where
  they line up along one axis within `TOLERANCE` pixels (their top and bottom edges, or their left and right ones)
  and nothing between them along that axis is painted under their label (`facaid.labels.PAINT_ORDER`): what is
  between is the label itself or something drawn over it (a blind over a window, a window into the cornice above
  it); and each box grown over the boxes of its label within `TOLERANCE` pixels of it all round (a sliver along its
  edge, a box it holds).

Boxes that line up exactly keep the label map: the element's own pixels, and over them what was drawn over them.
Where they are a pixel or two off (a cornice whose pieces in neighbouring tiles end a pixel apart), the merged box
paints those pixels too: at most `TOLERANCE` pixels along its edges (on 70 CMP facades of the dev half,
reconstructed, 0.16 % of the pixels). The annotation formats add **the wall under its elements** (`as_annotated`):
one rectangle per block of the building, what is not background in the fewest rectangles a row-by-row merge finds
(one per step of a stepped outline, as `as_drawn` finds them).
"""

from __future__ import annotations

from bisect import bisect_left, bisect_right, insort
from collections import defaultdict

import numpy as np

from facaid.labels import BACKGROUND, FACADE, LABEL_ID, PRIORITY
from facaid.segmentation import Rect, Segmentation, compressed_grid, decompose_grid, flatten_array, rasterize

TOLERANCE = 2  # pixels: pieces whose edges are this far apart still line up (a cornice's, tile by tile)
MAX_GRID_CELLS = 4_000_000  # past this, the canonical pieces are the elements, unmerged (a tree made to be huge)
_PRIORITY = np.asarray(PRIORITY, dtype=np.int16)


def merge_pieces(rects: list[Rect]) -> list[Rect]:
    """``rects`` with every two of one label that touch along a whole edge (the same top and bottom, one's right
    edge the other's left; or the same across) merged, until no two do."""
    out = list(rects)
    changed = True
    while changed:
        changed = False
        for along_x in (True, False):
            lines: dict[tuple, list[Rect]] = defaultdict(list)
            for r in out:
                lines[(r.label, r.y0, r.y1) if along_x else (r.label, r.x0, r.x1)].append(r)
            merged: list[Rect] = []
            for line in lines.values():
                line.sort(key=lambda r: r.x0 if along_x else r.y0)
                run = line[0]
                for r in line[1:]:
                    if along_x and r.x0 == run.x1:
                        run, changed = Rect(run.label, run.x0, run.y0, r.x1, run.y1), True
                    elif not along_x and r.y0 == run.y1:
                        run, changed = Rect(run.label, run.x0, run.y0, run.x1, r.y1), True
                    else:
                        merged.append(run)
                        run = r
                merged.append(run)
            out = merged
    return sorted(out, key=lambda r: (r.y0, r.x0, r.label))


def as_drawn(seg: Segmentation) -> Segmentation:
    """The segmentation as a person draws it: the wall as one rectangle per block of the building (what is not
    background, in the fewest rectangles a row-by-row merge finds) under its elements, where a flattened
    segmentation (a generated facade's) has it in pieces around each element. Its label map is the same."""
    built = rasterize(seg) != LABEL_ID["background"]
    walls: list[Rect] = []
    open_runs: dict[tuple[int, int], int] = {}  # (x0, x1) of a run of building pixels -> the row its block began
    for y in range(seg.height + 1):
        runs = set()
        if y < seg.height:
            row = np.concatenate([[False], built[y], [False]])
            edges = np.flatnonzero(row[1:] != row[:-1])
            runs = {(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)}
        for run in [r for r in open_runs if r not in runs]:
            walls.append(Rect(LABEL_ID["facade"], run[0], open_runs.pop(run), run[1], y))
        for run in runs - open_runs.keys():
            open_runs[run] = y
    elements = tuple(r for r in seg.rects if r.label != LABEL_ID["facade"])
    return Segmentation(seg.width, seg.height, (*walls, *elements))


# --- the elements ----------------------------------------------------------------------------------------------

def element_array(width: int, height: int, rows: np.ndarray, tolerance: int = TOLERANCE,
                  walls: bool = False) -> np.ndarray:
    """The elements (see the module's docstring) of the label map that ``rows`` (label, x0, y0, x1, y1, painted in
    paint order) make on a ``width`` x ``height`` image: int64 rows (label, x0, y0, x1, y1), sorted by (y0, x0,
    label). The wall and the background are no elements; ``walls``: the wall under them too, first (`as_annotated`)."""
    rows = np.asarray(rows, dtype=np.int64).reshape(-1, 5)
    if len(rows) == 0:
        return np.zeros((0, 5), dtype=np.int64)
    xs = np.unique(np.concatenate([[0, width], rows[:, 1], rows[:, 3]]))
    ys = np.unique(np.concatenate([[0, height], rows[:, 2], rows[:, 4]]))
    if len(xs) * len(ys) > MAX_GRID_CELLS:
        flat = flatten_array(width, height, rows, "footprint")
        return np.concatenate([_sorted(flat[flat[:, 0] == FACADE]) if walls else flat[:0],
                               _sorted(flat[flat[:, 0] > FACADE])])
    return _grid_elements(*_canonical(*compressed_grid(width, height, rows)), tolerance, walls)


def label_map_elements(label_map: np.ndarray, tolerance: int = TOLERANCE) -> np.ndarray:
    """`element_array` of a label map itself (labels.png read back): the same boxes as of the rows that painted it."""
    label_map = np.asarray(label_map)
    h, w = label_map.shape
    xs = np.concatenate([[0], np.flatnonzero((label_map[:, 1:] != label_map[:, :-1]).any(axis=0)) + 1, [w]])
    ys = np.concatenate([[0], np.flatnonzero((label_map[1:] != label_map[:-1]).any(axis=1)) + 1, [h]])
    return _grid_elements(xs, ys, label_map[np.ix_(ys[:-1], xs[:-1])], tolerance)


def elements(seg: Segmentation, tolerance: int = TOLERANCE) -> list[Rect]:
    """The segmentation's elements (see the module's docstring), one box each."""
    return list(map(Rect._make, element_array(seg.width, seg.height, seg.to_array(), tolerance).tolist()))


def as_annotated(seg: Segmentation) -> Segmentation:
    """The segmentation as an annotator draws it: the wall under its `elements`, one box each (the building's
    blocks, merged as elements are: a ragged edge of a pixel or two is no step of its outline)."""
    rows = element_array(seg.width, seg.height, seg.to_array(), walls=True)
    return Segmentation.from_array(seg.width, seg.height, rows)


def written_as(seg: Segmentation, fmt: str) -> Segmentation:
    """A procedure's rectangles as a file of ``fmt`` holds them: an annotation tool's (COCO, LabelMe, CVAT) one box
    per element (`as_annotated`), our own contract (``"segmentation"``) the exact pieces."""
    return seg if fmt == "segmentation" else as_annotated(seg)


def _canonical(xs: np.ndarray, ys: np.ndarray, grid: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grid without the lines that change nothing (a column the same as the one before it): the grid a label
    map of the same pixels gives (`label_map_elements`), whatever rows painted it."""
    cols = np.concatenate([[True], (grid[:, 1:] != grid[:, :-1]).any(axis=0)])
    rows = np.concatenate([[True], (grid[1:] != grid[:-1]).any(axis=1)])
    return (np.append(xs[:-1][cols], xs[-1]), np.append(ys[:-1][rows], ys[-1]), grid[np.ix_(rows, cols)])


def _sorted(rows: np.ndarray) -> np.ndarray:
    return rows[np.lexsort((rows[:, 0], rows[:, 1], rows[:, 2]))] if len(rows) else rows.reshape(0, 5)


def _grid_elements(xs: np.ndarray, ys: np.ndarray, grid: np.ndarray, tolerance: int, walls: bool = False
                   ) -> np.ndarray:
    """The elements of a label map given on a grid: grid[j, i] is the label of [xs[i], xs[i+1]) x [ys[j], ys[j+1]);
    ``walls``: the wall under them first, the building's footprint merged as the elements are."""
    cells = decompose_grid(np.where(grid > FACADE, grid, BACKGROUND).astype(np.uint8))
    priority = _PRIORITY[grid]
    out = []
    if walls:
        footprint = decompose_grid((grid != BACKGROUND).astype(np.uint8))
        out.append(_merged(footprint[:, 1:], FACADE, grid == BACKGROUND, xs, ys, tolerance))
    for label in np.unique(cells[:, 0]).tolist():
        out.append(_merged(cells[cells[:, 0] == label, 1:], label, priority < PRIORITY[label], xs, ys, tolerance))
    if not out:
        return np.zeros((0, 5), dtype=np.int64)
    cell = np.concatenate(out)
    rows = np.stack([cell[:, 0], xs[cell[:, 1]], ys[cell[:, 2]], xs[cell[:, 3]], ys[cell[:, 4]]], axis=1)
    wall = rows[:, 0] == FACADE
    return np.concatenate([_sorted(rows[wall]), _sorted(rows[~wall])])


def _merged(cells: np.ndarray, label: int, under: np.ndarray, xs: np.ndarray, ys: np.ndarray, tolerance: int
            ) -> np.ndarray:
    """Boxes of ``label`` in grid cells merged (`_Merge`), ``under`` the cells painted under the label; as rows
    (label, c0, r0, c1, r1)."""
    below = np.zeros((under.shape[0] + 1, under.shape[1] + 1), dtype=np.int32)
    below[1:, 1:] = under.cumsum(axis=0, dtype=np.int32).cumsum(axis=1, dtype=np.int32)
    boxes = _Merge(cells, xs, ys, below, tolerance).run()
    return np.column_stack([np.full(len(boxes), label), boxes])


class _Merge:
    """The boxes of one label merged (see the module's docstring), in grid cells (c0, r0, c1, r1); ``below``: the
    summed-area table of the cells painted under the label."""

    def __init__(self, cells: np.ndarray, xs: np.ndarray, ys: np.ndarray, below: np.ndarray, tolerance: int):
        self.cells = cells.astype(np.int64).tolist()
        self.xs, self.ys = xs.tolist(), ys.tolist()
        self.px = [[self.xs[c0], self.ys[r0], self.xs[c1], self.ys[r1]] for c0, r0, c1, r1 in self.cells]
        self.alive = [True] * len(self.cells)
        self.below, self.tolerance = below, tolerance

    def run(self) -> np.ndarray:
        changed = True
        while changed:
            changed = self.sweep(0) | self.sweep(1) | self.slivers()
        return np.array([c for c, alive in zip(self.cells, self.alive, strict=True) if alive],
                        dtype=np.int64).reshape(-1, 4)

    def grow(self, i: int, j: int) -> None:
        """Box i becomes the bounding box of boxes i and j; j is gone."""
        ci, cj = self.cells[i], self.cells[j]
        ci[:] = min(ci[0], cj[0]), min(ci[1], cj[1]), max(ci[2], cj[2]), max(ci[3], cj[3])
        self.px[i] = [self.xs[ci[0]], self.ys[ci[1]], self.xs[ci[2]], self.ys[ci[3]]]
        self.alive[j] = False

    def slivers(self) -> bool:
        """Each box merged with the boxes within `TOLERANCE` pixels of it (touching it, a sliver along its edge, a
        piece it holds) where their bounding box, but for a band that wide along its edges, holds nothing painted
        under their label; largest boxes first."""
        live = [i for i, alive in enumerate(self.alive) if alive]
        if len(live) < 2:
            return False
        t = self.tolerance
        px = np.array([self.px[i] for i in live], dtype=np.int64)
        a, b = box_pairs(px + [-t, -t, t, t], px)
        a, b = a[a != b], b[a != b]
        if len(a) == 0:
            return False
        near: dict[int, list[int]] = defaultdict(list)
        for i, j in zip(a.tolist(), b.tolist(), strict=True):
            near[live[i]].append(live[j])
        area = {i: (self.px[i][2] - self.px[i][0]) * (self.px[i][3] - self.px[i][1]) for i in near}
        changed = False
        for i in sorted(near, key=lambda i: (-area[i], i)):
            for j in near[i]:
                if self.alive[i] and self.alive[j] and self.core_clean(i, j):
                    self.grow(i, j)
                    changed = True
        return changed

    def core_clean(self, i: int, j: int) -> bool:
        """Whether the bounding box of boxes i and j, less `TOLERANCE` pixels along each edge, holds nothing
        painted under their label."""
        p, q, t = self.px[i], self.px[j], self.tolerance
        x0, y0 = min(p[0], q[0]) + t, min(p[1], q[1]) + t
        x1, y1 = max(p[2], q[2]) - t, max(p[3], q[3]) - t
        if x0 >= x1 or y0 >= y1:
            return True
        xs, ys = self.xs, self.ys  # the cells the core reaches into
        return self.clean(bisect_right(xs, x0) - 1, bisect_right(ys, y0) - 1, bisect_left(xs, x1),
                          bisect_left(ys, y1))

    def clean(self, c0: int, r0: int, c1: int, r1: int) -> bool:
        s = self.below
        return int(s[r1, c1] - s[r0, c1] - s[r1, c0] + s[r0, c0]) == 0

    def sweep(self, axis: int) -> bool:
        """One pass merging along ``axis`` (0: x, boxes side by side; 1: y, one above the other): each box with
        the nearest that follow it along the axis and line up with it across."""
        a0, p0, p1 = (0, 1, 3) if axis == 0 else (1, 0, 2)
        px, t, alive = self.px, self.tolerance, self.alive
        lines: dict[tuple[int, int], list[tuple[int, int]]] = defaultdict(list)  # (start, end) across -> boxes,
        order = sorted((i for i in range(len(px)) if alive[i]), key=lambda i: (px[i][a0], i))  # (start along, i)
        for i in order:
            lines[(px[i][p0], px[i][p1])].append((px[i][a0], i))
        keys = sorted(lines)
        near_keys = {}  # a line -> those within the tolerance of it
        for key in keys:
            span = keys[bisect_left(keys, (key[0] - t, -1)):bisect_right(keys, (key[0] + t, 1 << 62))]
            near_keys[key] = [k for k in span if abs(k[1] - key[1]) <= t]
        changed = False
        for i in order:
            if not alive[i]:
                continue
            key, start = (px[i][p0], px[i][p1]), px[i][a0]
            near = []
            for k in near_keys[key]:
                line = lines[k]
                found = 0
                for _, j in line[bisect_right(line, (start, i)):]:
                    if alive[j]:
                        near.append(j)
                        found += 1
                        if found == 3:
                            break
            for j in sorted(near, key=lambda j: (px[j][a0], j))[:3]:
                if self.join(i, j, axis):
                    lines[key].remove((start, i))
                    new = (px[i][p0], px[i][p1])
                    if new not in near_keys:
                        near_keys[new] = [k for k in near_keys if abs(k[0] - new[0]) <= t and abs(k[1] - new[1]) <= t]
                        for k in near_keys[new]:
                            near_keys[k].append(new)
                        near_keys[new].append(new)
                    insort(lines[new], (px[i][a0], i))
                    changed = True
                    break
        return changed

    def join(self, i: int, j: int, axis: int) -> bool:
        """Merge box j into box i if nothing between them along ``axis``, over the span they share across it, is
        painted under their label."""
        a0, a1, p0, p1 = (0, 2, 1, 3) if axis == 0 else (1, 3, 0, 2)
        ci, cj = self.cells[i], self.cells[j]
        lo, hi = max(ci[p0], cj[p0]), min(ci[p1], cj[p1])  # the span across that both cover, in cells
        if lo >= hi:
            return False
        start, end = min(ci[a0], cj[a0]), max(ci[a1], cj[a1])
        if not self.clean(*((start, lo, end, hi) if axis == 0 else (lo, start, hi, end))):
            return False
        self.grow(i, j)
        return True


def box_pairs(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The pairs (i, j) of boxes ``a[i]`` and ``b[j]`` (x0, y0, x1, y1) that overlap in an area, without comparing
    every box with every other: each is filed under the squares of a coarse grid it covers, and two boxes are
    compared where they share a square (each pair once: in the square of its overlap's top-left corner)."""
    a, b = np.asarray(a, dtype=np.int64).reshape(-1, 4), np.asarray(b, dtype=np.int64).reshape(-1, 4)
    if len(a) == 0 or len(b) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    both = np.concatenate([a, b])
    low = both[:, :2].min(axis=0)
    extent = int((both[:, 2:].max(axis=0) - low).max()) + 1
    side = max(1, -(-extent // int(np.clip(np.sqrt(len(both)), 1, 256))))  # a square's side, in pixels
    ka, ia = _squares(a, low, side)
    kb, ib = _squares(b, low, side)
    order = np.argsort(kb, kind="stable")
    kb, ib = kb[order], ib[order]
    first, last = np.searchsorted(kb, ka, "left"), np.searchsorted(kb, ka, "right")
    counts = last - first
    i = np.repeat(ia, counts)
    j = ib[np.repeat(first, counts) + np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)]
    square = np.repeat(ka, counts)
    x0, y0 = np.maximum(a[i, 0], b[j, 0]), np.maximum(a[i, 1], b[j, 1])
    keep = (x0 < np.minimum(a[i, 2], b[j, 2])) & (y0 < np.minimum(a[i, 3], b[j, 3]))
    keep &= _key((x0 - low[0]) // side, (y0 - low[1]) // side) == square
    return i[keep], j[keep]


def _key(col: np.ndarray, row: np.ndarray) -> np.ndarray:
    return row * (1 << 20) + col


def _squares(boxes: np.ndarray, low: np.ndarray, side: int) -> tuple[np.ndarray, np.ndarray]:
    """Each box's squares: their keys and the box's index, one pair per square."""
    c0, r0 = (boxes[:, 0] - low[0]) // side, (boxes[:, 1] - low[1]) // side
    c1, r1 = (np.maximum(boxes[:, 2] - 1, boxes[:, 0]) - low[0]) // side, (np.maximum(boxes[:, 3] - 1,
                                                                                      boxes[:, 1]) - low[1]) // side
    cols, rows = c1 - c0 + 1, r1 - r0 + 1
    n = cols * rows
    index = np.repeat(np.arange(len(boxes)), n)
    k = np.arange(n.sum()) - np.repeat(np.cumsum(n) - n, n)
    return _key(c0[index] + k % cols[index], r0[index] + k // cols[index]), index
