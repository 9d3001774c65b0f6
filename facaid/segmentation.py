"""Segmentations: labelled axis-aligned rectangles on a W x H image.

The JSON contract (the same shape as each line of the CMP annotations):
``{"width": W, "height": H, "rects": [{"label": "window", "x0": .., "y0": .., "x1": .., "y1": ..}, ...]}``
in pixels, origin top-left, half-open boxes with ``0 <= x0 < x1 <= W`` and ``0 <= y0 < y1 <= H``. Rectangles may
overlap; `flatten` resolves overlaps by the paint order of `facaid.labels` and `rasterize` paints a label map.
"""

from __future__ import annotations

import bisect
import json
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np
import orjson

from facaid.labels import BACKGROUND, FACADE, LABEL_ID, LABELS, PRIORITY
from facaid.native.rects import flatten_rows
from facaid.native.rects import rects_json as native_rects_json
from facaid.numbers import finite

MAX_SIDE = 16384  # pixels, either side
MAX_PIXELS = 64_000_000
MAX_RECTS = 20_000


class SegmentationError(ValueError):
    """A segmentation that breaks the contract; the message names the offending field."""


class Rect(NamedTuple):
    label: int  # index into LABELS
    x0: int
    y0: int
    x1: int
    y1: int

    @property
    def area(self) -> int:
        return (self.x1 - self.x0) * (self.y1 - self.y0)


def rect_dicts(rows) -> list[dict[str, Any]]:
    """The contract's rectangles from (label id, x0, y0, x1, y1) rows: `Rect`s, or int rows as lists."""
    return [{"label": LABELS[k], "x0": x0, "y0": y0, "x1": x1, "y1": y1} for k, x0, y0, x1, y1 in rows]


def rects_json(rows: np.ndarray) -> bytes:
    """The JSON of `rect_dicts` for int rows, as compact as orjson writes it (in C where the library builds)."""
    text = native_rects_json(rows)
    return orjson.dumps(rect_dicts(rows.tolist())) if text is None else text


@dataclass(frozen=True)
class Segmentation:
    width: int
    height: int
    rects: tuple[Rect, ...]

    def to_dict(self) -> dict[str, Any]:
        return {"width": self.width, "height": self.height, "rects": rect_dicts(self.rects)}

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), separators=(",", ":"))

    @classmethod
    def from_dict(cls, obj: Any, *, clip: bool = False) -> Segmentation:
        """Validate a decoded JSON object. With ``clip``, rectangles reaching outside the image are clipped
        (and dropped when nothing is left) instead of rejected."""
        return parse_segmentation(obj, clip=clip)

    @classmethod
    def from_array(cls, width: int, height: int, rows: np.ndarray) -> Segmentation:
        """From int rows (label, x0, y0, x1, y1), trusted to be valid (made by this library)."""
        return cls(width, height, tuple(map(Rect._make, rows.tolist())))

    def to_array(self) -> np.ndarray:
        return np.array(self.rects, dtype=np.int64).reshape(-1, 5)

    @classmethod
    def from_json(cls, text: str | bytes, *, clip: bool = False) -> Segmentation:
        try:
            obj = json.loads(text)
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise SegmentationError(f"malformed JSON: {exc}") from None
        return parse_segmentation(obj, clip=clip)


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise SegmentationError(f"{where} must be a number, got {type(value).__name__} {value!r}")
    if not finite(value):
        raise SegmentationError(f"{where} must be finite, got {str(value)[:40]}")
    return value


def _side(obj: dict, key: str) -> int:
    if key not in obj:
        raise SegmentationError(f"missing {key!r}")
    value = _number(obj[key], key)
    if value != int(value):
        raise SegmentationError(f"{key} must be a whole number of pixels, got {value!r}")
    if not 1 <= value <= MAX_SIDE:
        raise SegmentationError(f"{key} must be between 1 and {MAX_SIDE} pixels, got {value!r}")
    return int(value)


def parse_segmentation(obj: Any, *, clip: bool = False) -> Segmentation:
    """Validate a decoded segmentation JSON object and return a `Segmentation`.

    Coordinates may be given as floats; they are rounded to the nearest pixel edge. Extra keys are ignored.
    """
    if not isinstance(obj, dict):
        raise SegmentationError(f"a segmentation must be a JSON object, got {type(obj).__name__}")
    width, height = _side(obj, "width"), _side(obj, "height")
    if width * height > MAX_PIXELS:
        raise SegmentationError(f"image too large: {width}x{height} is over {MAX_PIXELS} pixels")
    rects_in = obj.get("rects")
    if not isinstance(rects_in, list):
        raise SegmentationError(f"'rects' must be a list, got {type(rects_in).__name__}")
    if len(rects_in) > MAX_RECTS:
        raise SegmentationError(f"too many rectangles: {len(rects_in)} (at most {MAX_RECTS})")
    rects = []
    for i, r in enumerate(rects_in):
        where = f"rects[{i}]"
        if not isinstance(r, dict):
            raise SegmentationError(f"{where} must be an object, got {type(r).__name__}")
        label = r.get("label")
        if not isinstance(label, str) or label not in LABEL_ID:
            raise SegmentationError(f"{where}.label {label!r} is not one of {', '.join(LABELS)}")
        coords = []
        for key in ("x0", "y0", "x1", "y1"):
            if key not in r:
                raise SegmentationError(f"{where} is missing {key!r}")
            coords.append(round(_number(r[key], f"{where}.{key}")))
        x0, y0, x1, y1 = coords
        if clip:
            x0, x1 = max(0, x0), min(width, x1)
            y0, y1 = max(0, y0), min(height, y1)
            if x0 >= x1 or y0 >= y1:
                continue
        else:
            if not (0 <= x0 < x1 <= width):
                raise SegmentationError(f"{where} needs 0 <= x0 < x1 <= width={width}, got x0={x0}, x1={x1}")
            if not (0 <= y0 < y1 <= height):
                raise SegmentationError(f"{where} needs 0 <= y0 < y1 <= height={height}, got y0={y0}, y1={y1}")
        rects.append(Rect(LABEL_ID[label], x0, y0, x1, y1))
    return Segmentation(width, height, tuple(rects))


def paint_order(rects: tuple[Rect, ...] | list[Rect]) -> list[Rect]:
    """Rectangles sorted by class priority, bottom first; stable, so equal classes keep their order."""
    return sorted(rects, key=lambda r: PRIORITY[r.label])


def rasterize(seg: Segmentation) -> np.ndarray:
    """Paint the segmentation into a (height, width) uint8 label map; uncovered pixels are background."""
    out = np.zeros((seg.height, seg.width), dtype=np.uint8)
    for r in paint_order(seg.rects):
        out[r.y0 : r.y1, r.x0 : r.x1] = r.label
    return out


def compressed_grid(width: int, height: int, arr: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The label map on the grid of all rectangle edges: (xs, ys, grid) with grid[j, i] the label of
    the cell [xs[i], xs[i+1]) x [ys[j], ys[j+1]). ``arr`` holds rows (label, x0, y0, x1, y1)."""
    arr = arr[np.argsort(np.asarray(PRIORITY)[arr[:, 0]], kind="stable")]  # paint order
    xs = np.unique(np.concatenate([[0, width], arr[:, 1], arr[:, 3]]))
    ys = np.unique(np.concatenate([[0, height], arr[:, 2], arr[:, 4]]))
    ix0, ix1 = np.searchsorted(xs, arr[:, 1]), np.searchsorted(xs, arr[:, 3])
    iy0, iy1 = np.searchsorted(ys, arr[:, 2]), np.searchsorted(ys, arr[:, 4])
    grid = np.zeros((len(ys) - 1, len(xs) - 1), dtype=np.uint8)
    rows, cols = iy1 - iy0, ix1 - ix0
    cells = rows * cols
    total = int(cells.sum())
    if total > 4 * grid.size + 4096:  # much overlap: paint rectangle by rectangle
        for lab, a, b, c, d in zip(arr[:, 0].tolist(), iy0.tolist(), iy1.tolist(), ix0.tolist(), ix1.tolist(),
                                   strict=True):
            grid[a:b, c:d] = lab
        return xs, ys, grid
    # every covered cell at once: each takes the label of the last rectangle painted over it (the highest
    # position in paint order), as painting them in turn would
    owner = np.repeat(np.arange(len(arr)), cells)
    k = np.arange(total) - np.repeat(np.cumsum(cells) - cells, cells)
    r = iy0[owner] + k // cols[owner]
    c = ix0[owner] + k % cols[owner]
    top = np.full(grid.shape, -1, dtype=np.int64)
    np.maximum.at(top, (r, c), owner)
    covered = top >= 0
    grid[covered] = arr[top[covered], 0]
    return xs, ys, grid


def decompose_grid(grid: np.ndarray) -> np.ndarray:
    """Canonical rectangle decomposition of the non-zero cells of a label grid.

    Each row is cut into maximal runs of one label; a run continues the rectangle above it when that
    rectangle has exactly the same columns and label. Returns int64 rows (label, c0, r0, c1, r1) in grid cells.
    """
    rows_n, cols_n = grid.shape
    if rows_n == 0 or cols_n == 0:
        return np.zeros((0, 5), dtype=np.int64)
    start = np.ones(grid.shape, dtype=bool)
    start[:, 1:] = grid[:, 1:] != grid[:, :-1]
    rows, c0 = np.nonzero(start)
    same_row = np.zeros(len(rows), dtype=bool)
    same_row[:-1] = rows[1:] == rows[:-1]
    c1 = np.full(len(c0), cols_n, dtype=np.int64)
    c1[same_row] = c0[1:][same_row[:-1]]
    lab = grid[rows, c0].astype(np.int64)
    keep = lab != 0
    rows, c0, c1, lab = rows[keep], c0[keep], c1[keep], lab[keep]
    if len(lab) == 0:
        return np.zeros((0, 5), dtype=np.int64)
    key = (c0 * (cols_n + 1) + c1) * 16 + lab
    order = np.lexsort((rows, key))
    k, r = key[order], rows[order]
    cont = np.zeros(len(k), dtype=bool)
    cont[1:] = (k[1:] == k[:-1]) & (r[1:] == r[:-1] + 1)
    first = np.flatnonzero(~cont)
    last = np.append(first[1:], len(k)) - 1
    o = order[first]
    return np.stack([lab[o], c0[o], rows[o], c1[o], r[last] + 1], axis=1)


def flatten(seg: Segmentation, *, wall: str = "pieces") -> Segmentation:
    """Resolve overlaps by the paint order and return a canonical set of rectangles, sorted by (y0, x0).

    ``wall="pieces"``: a partition of the non-background pixels; every rectangle has one label and none
    overlap. ``wall="footprint"``: two layers, the building footprint (every non-background pixel) as
    facade rectangles and, on top of it, the non-overlapping element rectangles; painting them in the paint
    order gives the same label map with far fewer rectangles. Both forms are canonical: equal label maps give
    equal outputs.
    """
    return Segmentation.from_array(seg.width, seg.height, flatten_array(seg.width, seg.height, seg.to_array(), wall))


def flatten_array(width: int, height: int, arr: np.ndarray, wall: str = "pieces") -> np.ndarray:
    """`flatten` on int rows (label, x0, y0, x1, y1); returns rows in the same form. Computed in C
    (`facaid.native.rects`) where the library builds, else by `flatten_array_numpy`, the reference."""
    if wall not in ("pieces", "footprint"):
        raise ValueError(f"wall must be 'pieces' or 'footprint', got {wall!r}")
    if len(arr) == 0:
        return np.zeros((0, 5), dtype=np.int64)
    rows = flatten_rows(width, height, arr, wall)
    return flatten_array_numpy(width, height, arr, wall) if rows is None else rows


def flatten_array_numpy(width: int, height: int, arr: np.ndarray, wall: str = "pieces") -> np.ndarray:
    """`flatten_array` in numpy: the label map on the grid of all edges (`compressed_grid`), cut into
    rectangles (`decompose_grid`)."""
    if len(arr) == 0:
        return np.zeros((0, 5), dtype=np.int64)
    xs, ys, grid = compressed_grid(width, height, arr)
    if wall == "pieces":
        cells = decompose_grid(grid)
    else:
        footprint = np.where(grid != BACKGROUND, FACADE, 0).astype(np.uint8)
        elements = np.where(grid > FACADE, grid, 0).astype(np.uint8)
        cells = np.concatenate([decompose_grid(footprint), decompose_grid(elements)])
    out = np.stack([cells[:, 0], xs[cells[:, 1]], ys[cells[:, 2]], xs[cells[:, 3]], ys[cells[:, 4]]], axis=1)
    return out[np.lexsort((out[:, 0], out[:, 1], out[:, 2]))]


def class_areas(label_map: np.ndarray) -> np.ndarray:
    """Pixel count of each of the 12 labels in a label map."""
    return np.bincount(label_map.ravel(), minlength=len(LABELS))[: len(LABELS)]


def aligned_lines(lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Indices of intervals [lo, hi) grouped into lines (rows of windows by their vertical extents, columns by
    their horizontal ones): sorted by centre, an interval joins the line before it
    when it overlaps that line's median interval by at least half its own length."""
    order = np.argsort((lo + hi) / 2, kind="stable")
    los, his = np.asarray(lo, dtype=np.float64).tolist(), np.asarray(hi, dtype=np.float64).tolist()
    lines: list[tuple[list[int], list[float], list[float]]] = []  # members, and their lo and hi kept sorted
    for i in order.tolist():
        if lines:
            members, ends_lo, ends_hi = lines[-1]
            a, b = _sorted_median(ends_lo), _sorted_median(ends_hi)
            if min(b, his[i]) - max(a, los[i]) >= 0.5 * (his[i] - los[i]):
                members.append(i)
                bisect.insort(ends_lo, los[i])
                bisect.insort(ends_hi, his[i])
                continue
        lines.append(([i], [los[i]], [his[i]]))
    return [np.array(m) for m, _, _ in lines]


def _sorted_median(values: list[float]) -> float:
    """The median of sorted values, as `np.median` has it (the mean of the middle two of an even count): a line's
    median kept as it grows, where `np.median` took 25 us a call (2,000 rectangles: 0.3 s)."""
    n = len(values)
    return values[n // 2] if n % 2 else (values[n // 2 - 1] + values[n // 2]) / 2


def region_roots(boxes: np.ndarray) -> np.ndarray:
    """For boxes (N, 4: x0, y0, x1, y1), the index of a representative of each one's connected region, where two
    boxes that share an edge or overlap are connected (touching corners are not)."""
    x0, y0, x1, y1 = boxes.T
    ox = np.minimum(x1[:, None], x1) - np.maximum(x0[:, None], x0)  # overlap along x (0: edges touch)
    oy = np.minimum(y1[:, None], y1) - np.maximum(y0[:, None], y0)
    joined = ((ox >= 0) & (oy > 0)) | ((ox > 0) & (oy >= 0))
    parent = np.arange(len(boxes))
    for i, j in zip(*np.nonzero(np.triu(joined, 1)), strict=True):  # union-find
        while parent[i] != i:
            i = parent[i]
        while parent[j] != j:
            j = parent[j]
        parent[i] = j
    for i in range(len(boxes)):
        while parent[parent[i]] != parent[i]:
            parent[i] = parent[parent[i]]
    return parent


def region_boxes(rows: np.ndarray, labels: tuple[int, ...]) -> np.ndarray:
    """The bounding boxes (M, 4: x0, y0, x1, y1) of the connected regions (`region_roots`) of the rows (N, 5:
    label, x0, y0, x1, y1; pieces of a flattened segmentation) whose label is one of ``labels``."""
    rows = np.asarray(rows, dtype=np.int64).reshape(-1, 5)
    boxes = rows[np.isin(rows[:, 0], labels)][:, 1:]
    if len(boxes) == 0:
        return np.zeros((0, 4), dtype=np.int64)
    roots = region_roots(boxes)
    out = [(b[:, 0].min(), b[:, 1].min(), b[:, 2].max(), b[:, 3].max())
           for b in (boxes[roots == r] for r in np.unique(roots))]
    return np.array(out, dtype=np.int64)
