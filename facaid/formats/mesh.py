"""A procedure as a relief mesh (Wavefront OBJ with its MTL): the facade for a 3D scene.

Every rectangle of the executed procedure (whole pixels, as labels.png paints them) becomes a box in front of or
behind the wall plane by its label's depth: windows, doors and shop fronts sit back, cornices, sills, moldings,
pillars and balconies stand out, and the wall is the plane itself. Each box has its front face and the four sides
that join it to the wall plane (facing out of a protrusion, into a recess: a window's reveals). Background makes
no geometry. Units are metres (the scale of `facaid.formats.cga.default_scale` unless given), x to the right, y up, z
towards the viewer, so the facade stands upright in Blender's and most tools' default OBJ import; one material
per label, in the palette's colours.
"""

from __future__ import annotations

import io

import numpy as np

from facaid.formats.relief import DEPTHS, MAX_MESH_RECTS, NORMALS, MeshTooLarge, box_quads, procedure_relief
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PALETTE

__all__ = ["DEPTHS", "MAX_MESH_RECTS", "MeshTooLarge", "procedure_mesh"]


def procedure_mesh(proc: Procedure, scale: float | None = None, mtl_name: str = "facade.mtl",
                   scale_from: str = "") -> tuple[str, str]:
    """The OBJ text and the MTL text (the OBJ names it ``mtl_name``); ``scale`` in metres per pixel (default
    `facaid.formats.cga.default_scale`), stated in the OBJ's header with ``scale_from``, where it came from."""
    relief = procedure_relief(proc, scale, scale_from)
    rows = relief.rows
    out = io.StringIO()
    out.write("# relief mesh of a facade, written by FaçAID: metres, x right, y up, z towards the viewer\n")
    out.write(f"# scale: {relief.describe()}\n")
    out.write(f"mtllib {mtl_name}\n")
    out.writelines(f"vn {x} {y} {z}\n" for x, y, z in NORMALS)
    labels = sorted(set(rows[:, 0].tolist()))
    vertices = 0
    for label in labels:
        name = LABELS[label]
        quads, normals = box_quads(relief.boxes(rows[rows[:, 0] == label]), DEPTHS[name])
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
