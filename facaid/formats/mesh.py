"""A procedure as a relief mesh (Wavefront OBJ with its MTL): the facade for a 3D scene.

Every element of the relief (`facaid.formats.relief`: the elements the annotations hold, one box each, and the
pieces of wall) is a box in front of or behind the wall plane by its label's depth: windows, doors and shop fronts
sit back, cornices, sills, moldings, pillars and balconies stand out, and the wall is the plane itself. Each box
has its front face and the four sides that join it to the wall plane (facing out of a protrusion, into a recess: a
window's reveals). Each element is an object (``o window_12``), the wall one more (``o facade``). Background makes
no geometry. Units are metres (the scale of `facaid.formats.cga.default_scale` unless given), x to the right, y up, z
towards the viewer, so the facade stands upright in Blender's and most tools' default OBJ import; one material
per label, in the palette's colours.
"""

from __future__ import annotations

import io

import numpy as np

from facaid.formats.relief import DEPTHS, MAX_MESH_RECTS, NORMALS, MeshTooLarge, box_quads, procedure_relief
from facaid.grammar.procedure import Procedure
from facaid.labels import FACADE, LABELS, PALETTE

__all__ = ["DEPTHS", "MAX_MESH_RECTS", "MeshTooLarge", "procedure_mesh"]


def procedure_mesh(proc: Procedure, scale: float | None = None, mtl_name: str = "facade.mtl",
                   scale_from: str = "") -> tuple[str, str]:
    """The OBJ text and the MTL text (the OBJ names it ``mtl_name``); ``scale`` in metres per pixel (default
    `facaid.formats.cga.default_scale`), stated in the OBJ's header with ``scale_from``, where it came from. Each
    element is an object of its own (``o window_12``: its label and its row in the relief, as glTF numbers its
    nodes), the wall's pieces one object per label (``o facade``), each in its label's material."""
    relief = procedure_relief(proc, scale, scale_from)
    rows, parts = relief.rows, relief.parts
    out = io.StringIO()
    out.write("# relief mesh of a facade, written by FaçAID: metres, x right, y up, z towards the viewer\n")
    out.write(f"# scale: {relief.describe()}\n")
    out.write(f"mtllib {mtl_name}\n")
    out.writelines(f"vn {x} {y} {z}\n" for x, y, z in NORMALS)
    labels = sorted(set(rows[:, 0].tolist()))
    vertices = 0
    for label in labels:
        name = LABELS[label]
        mine = parts[rows[parts[:, 0], 0] == label]
        quads, normals = box_quads(relief.boxes(mine), DEPTHS[name])
        m, k = quads.shape[:2]
        first = vertices + 1 + 4 * np.arange(m * k)  # each quad's first vertex, 1-based
        normal = np.tile(np.array(normals) + 1, m)
        faces = np.stack([first, normal, first + 1, normal, first + 2, normal, first + 3, normal], axis=1)
        v = _lines(quads.reshape(m, -1, 3).reshape(m, -1), "v %.4f %.4f %.4f", 4 * k)
        f = _lines(faces.reshape(m, -1), "f %d//%d %d//%d %d//%d %d//%d", k)
        if label == FACADE:
            out.write(f"o {name}\nusemtl {name}\n" + "".join(v) + "".join(f))
        else:
            heads = [f"o {name}_{row}\nusemtl {name}\n" for row in mine[:, 0].tolist()]
            starts = np.flatnonzero(np.r_[True, mine[1:, 0] != mine[:-1, 0]])  # an element's first part
            head = dict(zip(starts.tolist(), (heads[i] for i in starts.tolist()), strict=True))
            out.write("".join(head.get(i, "") + v[i] + f[i] for i in range(m)))
        vertices += 4 * m * k
    mtl = ["# materials of a FaçAID relief mesh: one per label, the palette's colours"]
    for label in labels:
        r, g, b = (c / 255 for c in PALETTE[LABELS[label]])
        mtl += [f"newmtl {LABELS[label]}", f"Kd {r:.4f} {g:.4f} {b:.4f}", "Ka 0 0 0", "Ks 0 0 0", "d 1", "illum 1",
                ""]
    return out.getvalue(), "\n".join(mtl)


def _lines(values: np.ndarray, line: str, per_row: int) -> list[str]:
    """Each row of ``values`` as ``per_row`` lines of the format ``line`` (joined, one string per row)."""
    if len(values) == 0:
        return []
    text = io.StringIO()
    np.savetxt(text, values.reshape(len(values) * per_row, -1), fmt=line)
    lines = text.getvalue().splitlines(keepends=True)
    return ["".join(lines[i:i + per_row]) for i in range(0, len(lines), per_row)]
