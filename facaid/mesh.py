"""A procedure as a relief mesh (Wavefront OBJ with its MTL): the facade for a 3D scene.

Every rectangle of the executed procedure (whole pixels, as labels.png paints them) becomes a box in front of or
behind the wall plane by its label's depth: windows, doors and shop fronts sit back, cornices, sills, moldings,
pillars and balconies stand out, and the wall is the plane itself. Each box has its front face and the four sides
that join it to the wall plane (facing out of a protrusion, into a recess: a window's reveals). Background makes
no geometry. Units are metres (the scale of `facaid.cga.default_scale` unless given), x to the right, y up, z
towards the viewer, so the facade stands upright in Blender's and most tools' default OBJ import; one material
per label, in the palette's colours.
"""

from __future__ import annotations

import io

import numpy as np

from facaid.cga import STOREY_M, checked_scale
from facaid.grammar.execute import leaf_array
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PALETTE

# metres in front of (+) or behind (-) the wall plane
DEPTHS: dict[str, float] = {
    "facade": 0.0, "window": -0.12, "door": -0.15, "shop": -0.10, "blind": 0.03, "sill": 0.08,
    "cornice": 0.30, "molding": 0.06, "pillar": 0.12, "balcony": 0.50, "deco": 0.05,
}


MAX_MESH_RECTS = 20_000  # real facades draw a few hundred; 20,000 make an 8 MB OBJ in about half a second


class MeshTooLarge(ValueError):
    """The procedure draws more rectangles than a mesh is made of."""


NORMALS = ((0, 0, 1), (-1, 0, 0), (1, 0, 0), (0, 1, 0), (0, -1, 0))  # front, left, right, top, bottom


def _quads(boxes: np.ndarray, depth: float) -> tuple[np.ndarray, list[int]]:
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
        if len(out) and _area_normal(out[0, j], NORMALS[n]) < 0:
            out[:, j] = out[:, j, ::-1]
    return out, normals


def procedure_mesh(proc: Procedure, scale: float | None = None, mtl_name: str = "facade.mtl",
                   scale_from: str = "") -> tuple[str, str]:
    """The OBJ text and the MTL text (the OBJ names it ``mtl_name``); ``scale`` in metres per pixel (default
    `facaid.cga.default_scale`), stated in the OBJ's header with ``scale_from``, where it came from."""
    given = scale is not None
    scale = checked_scale(proc, scale)
    source = " ".join((scale_from or ("given" if given else f"a storey {STOREY_M:g} m tall")).split())[:200]
    rows = leaf_array(proc)
    if len(rows) > MAX_MESH_RECTS:
        raise MeshTooLarge(f"the procedure draws {len(rows)} rectangles; a mesh is made of at most {MAX_MESH_RECTS}")
    height = round(proc.height)
    out = io.StringIO()
    out.write("# relief mesh of a facade, written by FaçAID: metres, x right, y up, z towards the viewer\n")
    out.write(f"# scale: {scale:.6g} m per pixel ({source}): {proc.width * scale:.2f} m x "
              f"{proc.height * scale:.2f} m\n")
    out.write(f"mtllib {mtl_name}\n")
    out.writelines(f"vn {x} {y} {z}\n" for x, y, z in NORMALS)
    labels = sorted(set(rows[:, 0].tolist()))
    vertices = 0
    for label in labels:
        name = LABELS[label]
        mine = rows[rows[:, 0] == label, 1:].astype(np.float64)
        boxes = np.stack([mine[:, 0], mine[:, 2], height - mine[:, 3], height - mine[:, 1]], axis=1) * scale
        quads, normals = _quads(boxes, DEPTHS[name])
        m, k = quads.shape[:2]
        out.write(f"g {name}\nusemtl {name}\n")
        np.savetxt(out, quads.reshape(-1, 3), fmt="v %.4f %.4f %.4f")
        first = vertices + 1 + 4 * np.arange(m * k)  # each quad's first vertex, 1-based
        normal = np.tile(np.array(normals) + 1, m)
        faces = np.stack([first, normal, first + 1, normal, first + 2, normal, first + 3, normal], axis=1)
        np.savetxt(out, faces, fmt="f %d//%d %d//%d %d//%d %d//%d")
        vertices += 4 * m * k
    mtl = ["# materials of a FaçAID relief mesh: one per label, the palette's colours"]
    for label in labels:
        r, g, b = (c / 255 for c in PALETTE[LABELS[label]])
        mtl += [f"newmtl {LABELS[label]}", f"Kd {r:.4f} {g:.4f} {b:.4f}", "Ka 0 0 0", "Ks 0 0 0", "d 1", "illum 1",
                ""]
    return out.getvalue(), "\n".join(mtl)


def _area_normal(corners: np.ndarray, normal: tuple[int, int, int]) -> float:
    """The component along ``normal`` of the quad's (a, b, c) winding normal: > 0 when counter-clockwise seen
    from that side."""
    a, b, c = corners[:3]
    return float(np.dot(np.cross(b - a, c - a), normal))
