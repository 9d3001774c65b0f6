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

import math

from facaid.cga import MAX_SCALE, default_scale
from facaid.grammar.execute import leaf_array
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PALETTE

# metres in front of (+) or behind (-) the wall plane
DEPTHS: dict[str, float] = {
    "facade": 0.0, "window": -0.12, "door": -0.15, "shop": -0.10, "blind": 0.03, "sill": 0.08,
    "cornice": 0.30, "molding": 0.06, "pillar": 0.12, "balcony": 0.50, "deco": 0.05,
}


def _number(value: float) -> str:
    text = f"{value:.5f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def procedure_mesh(proc: Procedure, scale: float | None = None, mtl_name: str = "facade.mtl") -> tuple[str, str]:
    """The OBJ text and the MTL text (the OBJ names it ``mtl_name``); ``scale`` in metres per pixel."""
    if scale is None:
        scale = default_scale(proc)
    if not (isinstance(scale, (int, float)) and math.isfinite(scale) and 0 < scale <= MAX_SCALE):
        raise ValueError(f"scale must be a number of metres per pixel > 0 and at most {MAX_SCALE:g}, got {scale!r}")
    rows = leaf_array(proc)
    height = round(proc.height)
    obj = ["# relief mesh of a facade, written by FaçAID: metres, x right, y up, z towards the viewer",
           f"mtllib {mtl_name}"]
    vertices = 0
    normals = {n: i + 1 for i, n in enumerate([(0, 0, 1), (0, 0, -1), (1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0)])}
    obj += [f"vn {x} {y} {z}" for x, y, z in normals]
    by_label: dict[int, list] = {}
    for row in rows:
        by_label.setdefault(int(row[0]), []).append(row[1:])
    for label in sorted(by_label):
        name = LABELS[label]
        depth = DEPTHS[name]
        obj += [f"g {name}", f"usemtl {name}"]
        for x0, y0, x1, y1 in by_label[label]:
            left, right = x0 * scale, x1 * scale
            bottom, top = (height - y1) * scale, (height - y0) * scale
            quads = [((left, bottom, depth), (right, bottom, depth), (right, top, depth), (left, top, depth),
                      (0, 0, 1))]
            if depth != 0.0:
                out = 1 if depth > 0 else -1  # sides face out of a protrusion, into a recess
                near, far = 0.0, depth
                quads += [
                    ((left, bottom, near), (left, bottom, far), (left, top, far), (left, top, near), (-out, 0, 0)),
                    ((right, bottom, near), (right, top, near), (right, top, far), (right, bottom, far), (out, 0, 0)),
                    ((left, top, near), (left, top, far), (right, top, far), (right, top, near), (0, out, 0)),
                    ((left, bottom, near), (right, bottom, near), (right, bottom, far), (left, bottom, far),
                     (0, -out, 0)),
                ]
            for *corners, normal in quads:
                if _area_normal(corners, normal) < 0:  # wind each face counter-clockwise seen from its normal
                    corners.reverse()
                obj += [f"v {_number(x)} {_number(y)} {_number(z)}" for x, y, z in corners]
                n = normals[normal]
                obj.append("f " + " ".join(f"{vertices + i + 1}//{n}" for i in range(4)))
                vertices += 4
    mtl = ["# materials of a FaçAID relief mesh: one per label, the palette's colours"]
    for label in sorted(by_label):
        r, g, b = (c / 255 for c in PALETTE[LABELS[label]])
        mtl += [f"newmtl {LABELS[label]}", f"Kd {r:.4f} {g:.4f} {b:.4f}", "Ka 0 0 0", "Ks 0 0 0", "d 1", "illum 1",
                ""]
    return "\n".join(obj) + "\n", "\n".join(mtl)


def _area_normal(corners: list[tuple[float, float, float]], normal: tuple[int, int, int]) -> float:
    """The component along ``normal`` of the quad's (a, b, c) winding normal: > 0 when counter-clockwise seen
    from that side."""
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = corners[:3]
    ux, uy, uz, vx, vy, vz = bx - ax, by - ay, bz - az, cx - ax, cy - ay, cz - az
    cross = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
    return sum(c * n for c, n in zip(cross, normal, strict=True))
