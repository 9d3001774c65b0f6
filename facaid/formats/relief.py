"""A procedure as a relief in metres: what the 3D exports (the OBJ mesh, glTF, IFC, CityJSON) are made of.

Its elements are those of the annotation formats (`facaid.formats.annotation.element_array`: one box per window,
door, cornice, ..., its pieces merged), so that every export holds the same windows and doors; the wall is the rest
of the building, in pieces. Each is a box in front of or behind the wall plane by its label's depth (windows, doors
and shop fronts sit back, cornices, sills, moldings, pillars and balconies stand out, the wall is the plane itself),
drawn as its box (its ``parts``) but where an element painted over it (`facaid.labels.PAINT_ORDER`; of one label,
the later one) would sit behind it: there it is left open, so that the relief seen from the front shows what the
annotations paint (a cornice over the top of a window: the window shows through; a window behind its blind: the
window's whole box, the blind in front). Background is no element. Units are metres at the scale of
`facaid.formats.cga.default_scale` unless given, x to the right, y up, z towards the viewer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facaid.formats.annotation import box_pairs, element_array
from facaid.formats.cga import STOREY_M, checked_scale
from facaid.grammar.execute import execute_with_nodes, leaf_rows
from facaid.grammar.procedure import Procedure
from facaid.labels import FACADE, LABELS, PRIORITY
from facaid.segmentation import decompose_grid, flatten_array

# metres in front of (+) or behind (-) the wall plane
DEPTHS: dict[str, float] = {
    "facade": 0.0, "window": -0.12, "door": -0.15, "shop": -0.10, "blind": 0.03, "sill": 0.08,
    "cornice": 0.30, "molding": 0.06, "pillar": 0.12, "balcony": 0.50, "deco": 0.05,
}

MAX_MESH_RECTS = 20_000  # real facades draw a few hundred; 20,000 make an 8 MB OBJ in about half a second


class MeshTooLarge(ValueError):
    """The procedure draws more rectangles than a 3D export is made of."""


@dataclass(frozen=True)
class Relief:
    """The elements of a procedure at a scale. ``rows``: (n, 5) int64 label id, x0, y0, x1, y1 in the procedure's
    pixels (y down), the elements and the pieces of wall, sorted by (y0, x0, label); ``paths``: each row's node in
    the tree, that of the leaf that draws the most of it (``root/1/0``: the same for every copy of a repeat, so for
    each tile's piece of a cornice); ``parts``: (m, 5) int64 row index, x0, y0, x1, y1: the boxes each row is drawn
    as (its own box, or its pieces around what it is left open for), ordered by row."""

    width: int  # pixels
    height: int
    scale: float  # metres per pixel
    scale_from: str  # where the scale came from, one line
    rows: np.ndarray
    paths: list[str]
    parts: np.ndarray

    @property
    def width_m(self) -> float:
        return self.width * self.scale

    @property
    def height_m(self) -> float:
        return self.height * self.scale

    def labels(self) -> list[str]:
        """The labels of the rows, in row order."""
        return [LABELS[i] for i in self.rows[:, 0].tolist()]

    def boxes(self, rows: np.ndarray | None = None) -> np.ndarray:
        """(n, 4) float64 left, right, bottom, top in metres (y up) of ``rows`` (default: all; or ``parts``)."""
        r = (self.rows if rows is None else rows)[:, 1:].astype(np.float64)
        return np.stack([r[:, 0], r[:, 2], self.height - r[:, 3], self.height - r[:, 1]], axis=1) * self.scale

    def parts_of(self, i: int) -> np.ndarray:
        """The parts of row ``i``, (k, 5) as in ``parts``."""
        lo, hi = np.searchsorted(self.parts[:, 0], [i, i + 1])
        return self.parts[lo:hi]

    def describe(self) -> str:
        """The scale in one line: ``0.02 m per pixel (a storey 3 m tall): 12.00 m x 9.00 m``."""
        return (f"{self.scale:.6g} m per pixel ({self.scale_from}): {self.width_m:.2f} m x "
                f"{self.height_m:.2f} m")


def procedure_relief(proc: Procedure, scale: float | None = None, scale_from: str = "") -> Relief:
    """The relief of ``proc`` at ``scale`` metres per pixel (default `facaid.formats.cga.default_scale`); ``scale_from``
    says where a given scale came from ("given" if empty). `MeshTooLarge` past `MAX_MESH_RECTS` rectangles drawn, a
    ValueError for a bad scale."""
    given = scale is not None
    scale = checked_scale(proc, scale)
    source = " ".join((scale_from or ("given" if given else f"a storey {STOREY_M:g} m tall")).split())[:200]
    leaves, paths = drawn_leaves(proc)
    if len(leaves) > MAX_MESH_RECTS:
        raise MeshTooLarge(f"the procedure draws {len(leaves)} rectangles; a mesh is made of at most {MAX_MESH_RECTS}")
    width, height = round(proc.width), round(proc.height)
    elements = element_array(width, height, leaves)
    footprint = flatten_array(width, height, leaves, "footprint")
    drawn = flatten_array(width, height, np.concatenate([footprint[footprint[:, 0] == FACADE], elements]), "pieces")
    rows = np.concatenate([drawn[drawn[:, 0] == FACADE], elements])
    order = np.lexsort((rows[:, 0], rows[:, 1], rows[:, 2]))  # elements keep their order: of one label, the later
    rows = rows[order]  # one is painted over the earlier
    leaf = _largest_leaf(rows, leaves)
    return Relief(width, height, scale, source, rows, [paths[i] for i in leaf.tolist()], _parts(rows))


def drawn_leaves(proc: Procedure) -> tuple[np.ndarray, list[str]]:
    """The rectangles the procedure draws, as labels.png paints them: (n, 5) int64 rows (label id, x0, y0, x1, y1 in
    whole pixels; background and empty leaves left out), and each one's node in the tree (``root/1/0``, the same for
    every copy of a repeated node). They do not overlap: a point of the picture lies in one at most."""
    leaves, nodes = execute_with_nodes(proc)
    rows, index = leaf_rows(proc, leaves)
    path_of = {id(node): path for path, node in proc.nodes()}
    return rows, [path_of[id(nodes[i])] for i in index.tolist()]


_DEPTH = np.array([DEPTHS.get(name, 0.0) for name in LABELS])
_PRIORITY = np.asarray(PRIORITY)


def _largest_leaf(rows: np.ndarray, leaves: np.ndarray) -> np.ndarray:
    """For each row, the index of the leaf of its label that draws the most of it."""
    i, j = box_pairs(rows[:, 1:], leaves[:, 1:])
    keep = rows[i, 0] == leaves[j, 0]
    i, j = i[keep], j[keep]
    w = np.minimum(rows[i, 3], leaves[j, 3]) - np.maximum(rows[i, 1], leaves[j, 1])
    h = np.minimum(rows[i, 4], leaves[j, 4]) - np.maximum(rows[i, 2], leaves[j, 2])
    order = np.lexsort((j, -(w * h), i))  # each row's largest first, then the first such leaf
    i, j = i[order], j[order]
    first = np.r_[True, i[1:] != i[:-1]]
    out = np.zeros(len(rows), dtype=np.int64)
    out[i[first]] = j[first]
    return out


def _parts(rows: np.ndarray) -> np.ndarray:
    """Each row's parts (see `Relief`): its box, less the boxes that overlap it, are painted over it (a higher
    paint priority; of one label, a later row) and sit no further forward than it."""
    depth, priority = _DEPTH[rows[:, 0]], _PRIORITY[rows[:, 0]]
    i, j = box_pairs(rows[:, 1:], rows[:, 1:])
    cut = ((priority[j] > priority[i]) | ((priority[j] == priority[i]) & (j > i))) & (depth[j] <= depth[i])
    holes: dict[int, list[int]] = {}
    for row, hole in zip(i[cut].tolist(), j[cut].tolist(), strict=True):
        holes.setdefault(row, []).append(hole)
    out = [np.column_stack([np.arange(len(rows)), rows[:, 1:]])[[r for r in range(len(rows)) if r not in holes]]]
    for row, over in holes.items():
        x0, y0, x1, y1 = rows[row, 1:]
        box = np.clip(rows[over, 1:], [x0, y0, x0, y0], [x1, y1, x1, y1])
        xs, ys = np.unique(np.r_[x0, x1, box[:, 0], box[:, 2]]), np.unique(np.r_[y0, y1, box[:, 1], box[:, 3]])
        shut = np.ones((len(ys) - 1, len(xs) - 1), dtype=np.uint8)
        for hx0, hy0, hx1, hy1 in box.tolist():
            r0, r1, c0, c1 = np.searchsorted(ys, [hy0, hy1]).tolist() + np.searchsorted(xs, [hx0, hx1]).tolist()
            shut[r0:r1, c0:c1] = 0
        cells = decompose_grid(shut)
        if len(cells) == 0:  # all of it under what is painted over it (a sliver): drawn whole, not lost
            out.append(np.array([[row, x0, y0, x1, y1]]))
            continue
        out.append(np.stack([np.full(len(cells), row), xs[cells[:, 1]], ys[cells[:, 2]], xs[cells[:, 3]],
                             ys[cells[:, 4]]], axis=1))
    parts = np.concatenate(out).astype(np.int64)
    return parts[np.argsort(parts[:, 0], kind="stable")]


NORMALS = ((0, 0, 1), (-1, 0, 0), (1, 0, 0), (0, 1, 0), (0, -1, 0))  # front, left, right, top, bottom


def box_quads(boxes: np.ndarray, depth: float) -> tuple[np.ndarray, list[int]]:
    """The quads of boxes (left, right, bottom, top in metres) at ``depth``: (m, k, 4, 3) corners, each quad wound
    counter-clockwise seen from its normal, and the index in `NORMALS` of each of the k quads (the front; with a
    depth, the four sides, facing out of a protrusion and into a recess)."""
    left, right, bottom, top = (boxes[:, i] for i in range(4))
    near, far = np.zeros_like(left), np.full_like(left, depth)

    def quad(*corners) -> np.ndarray:
        return np.stack([np.stack(c, axis=-1) for c in corners], axis=1)  # (m, 4, 3)

    quads = [quad((left, bottom, far), (right, bottom, far), (right, top, far), (left, top, far))]
    normals = [0]
    if depth != 0.0:
        quads += [quad((left, bottom, near), (left, bottom, far), (left, top, far), (left, top, near)),
                  quad((right, bottom, near), (right, top, near), (right, top, far), (right, bottom, far)),
                  quad((left, top, near), (left, top, far), (right, top, far), (right, top, near)),
                  quad((left, bottom, near), (right, bottom, near), (right, bottom, far), (left, bottom, far))]
        normals += [1, 2, 3, 4] if depth > 0 else [2, 1, 4, 3]  # a recess's sides face into it
    out = np.stack(quads, axis=1)  # (m, k, 4, 3)
    for j, n in enumerate(normals):  # wind each kind of quad counter-clockwise seen from its normal
        if len(out) and area_normal(out[0, j], NORMALS[n]) < 0:
            out[:, j] = out[:, j, ::-1]
    return out, normals


def area_normal(corners: np.ndarray, normal: tuple[int, int, int]) -> float:
    """The component along ``normal`` of the quad's (a, b, c) winding normal: > 0 when counter-clockwise seen
    from that side."""
    a, b, c = corners[:3]
    return float(np.dot(np.cross(b - a, c - a), normal))
