"""A procedure as a relief in metres: what the 3D exports (the OBJ mesh, glTF, IFC, CityJSON) are made of.

Every rectangle of the executed procedure (whole pixels, as labels.png paints them) is an element: a box in front of
or behind the wall plane by its label's depth (windows, doors and shop fronts sit back, cornices, sills, moldings,
pillars and balconies stand out, the wall is the plane itself). Background is no element. Units are metres at the
scale of `facaid.formats.cga.default_scale` unless given, x to the right, y up, z towards the viewer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facaid.formats.cga import STOREY_M, checked_scale
from facaid.grammar.execute import execute_with_nodes, leaf_rows
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS

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
    pixels (y down); ``paths``: each row's node in the tree (``root/1/0``: the same for every copy of a repeat)."""

    width: int  # pixels
    height: int
    scale: float  # metres per pixel
    scale_from: str  # where the scale came from, one line
    rows: np.ndarray
    paths: list[str]

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
        """(n, 4) float64 left, right, bottom, top in metres (y up) of ``rows`` (default: all)."""
        r = (self.rows if rows is None else rows)[:, 1:].astype(np.float64)
        return np.stack([r[:, 0], r[:, 2], self.height - r[:, 3], self.height - r[:, 1]], axis=1) * self.scale

    def describe(self) -> str:
        """The scale in one line: ``0.02 m per pixel (a storey 3 m tall): 12.00 m x 9.00 m``."""
        return (f"{self.scale:.6g} m per pixel ({self.scale_from}): {self.width_m:.2f} m x "
                f"{self.height_m:.2f} m")


def procedure_relief(proc: Procedure, scale: float | None = None, scale_from: str = "") -> Relief:
    """The relief of ``proc`` at ``scale`` metres per pixel (default `facaid.formats.cga.default_scale`); ``scale_from``
    says where a given scale came from ("given" if empty). `MeshTooLarge` past `MAX_MESH_RECTS` elements, a
    ValueError for a bad scale."""
    given = scale is not None
    scale = checked_scale(proc, scale)
    source = " ".join((scale_from or ("given" if given else f"a storey {STOREY_M:g} m tall")).split())[:200]
    rows, paths = drawn_leaves(proc)
    if len(rows) > MAX_MESH_RECTS:
        raise MeshTooLarge(f"the procedure draws {len(rows)} rectangles; a mesh is made of at most {MAX_MESH_RECTS}")
    return Relief(round(proc.width), round(proc.height), scale, source, rows, paths)


def drawn_leaves(proc: Procedure) -> tuple[np.ndarray, list[str]]:
    """The rectangles the procedure draws, as labels.png paints them: (n, 5) int64 rows (label id, x0, y0, x1, y1 in
    whole pixels; background and empty leaves left out), and each one's node in the tree (``root/1/0``, the same for
    every copy of a repeated node). They do not overlap: a point of the picture lies in one at most."""
    leaves, nodes = execute_with_nodes(proc)
    rows, index = leaf_rows(proc, leaves)
    path_of = {id(node): path for path, node in proc.nodes()}
    return rows, [path_of[id(nodes[i])] for i in index.tolist()]


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
