"""The relief mesh: read back as OBJ, its front faces, seen from the front, paint the label map of the elements the
annotations hold (one object each), every face is wound as its normal says, and a recess's sides face into it."""

import numpy as np
import pytest
from format_helpers import window_grid

from facaid.formats.annotation import as_annotated
from facaid.formats.mesh import DEPTHS, procedure_mesh
from facaid.formats.relief import procedure_relief
from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
from facaid.labels import FACADE, LABEL_ID, LABELS, PALETTE
from facaid.segmentation import rasterize


def read_obj(text: str) -> tuple[np.ndarray, np.ndarray, list[tuple[str, list[int], int]], str]:
    """Vertices, normals, faces (material, 0-based vertex indices, 0-based normal index) and the mtllib."""
    vertices, normals, faces, material, mtllib = [], [], [], None, None
    objects = read_obj.objects = []  # the objects' names, in order
    for line in text.splitlines():
        parts = line.split()
        if not parts or parts[0] in ("#", "g"):
            continue
        if parts[0] == "o":
            objects.append(parts[1])
            continue
        if parts[0] == "v":
            vertices.append([float(p) for p in parts[1:]])
        elif parts[0] == "vn":
            normals.append([float(p) for p in parts[1:]])
        elif parts[0] == "usemtl":
            material = parts[1]
        elif parts[0] == "mtllib":
            mtllib = parts[1]
        elif parts[0] == "f":
            refs = [p.split("//") for p in parts[1:]]
            assert len({n for _, n in refs}) == 1
            faces.append((material, [int(v) - 1 for v, _ in refs], int(refs[0][1]) - 1))
        else:
            raise AssertionError(f"unexpected OBJ line {line!r}")
    return np.array(vertices), np.array(normals), faces, mtllib


def check_mesh(proc, scale: float) -> None:
    obj, mtl = procedure_mesh(proc, scale)
    vertices, normals, faces, mtllib = read_obj(obj)
    assert mtllib == "facade.mtl"
    w, h = round(proc.width), round(proc.height)
    fronts = []  # (depth, label, y0, y1, x0, x1)
    for material, corners, n in faces:
        quad = vertices[corners]
        normal = normals[n]
        winding = np.cross(quad[1] - quad[0], quad[2] - quad[0])
        assert np.dot(winding, normal) > 0, (material, quad)  # counter-clockwise seen from its normal
        assert np.allclose((quad - quad[0]) @ normal, 0)  # flat, across the normal
        if tuple(normal) == (0, 0, 1):
            assert np.allclose(quad[:, 2], DEPTHS[material])
            x0, x1 = np.rint(quad[:, 0].min() / scale).astype(int), np.rint(quad[:, 0].max() / scale).astype(int)
            y0, y1 = (np.rint(h - quad[:, 1].max() / scale).astype(int),
                      np.rint(h - quad[:, 1].min() / scale).astype(int))
            fronts.append((DEPTHS[material], LABEL_ID[material], y0, y1, x0, x1))
            centre = quad.mean(axis=0)
        else:  # a side (after its front) joins the wall plane to the front at the label's depth, facing out of a
            # protrusion and into a recess
            depth = DEPTHS[material]
            assert sorted(set(np.round(quad[:, 2], 6))) == sorted({0.0, depth})
            away = np.dot(normal, quad.mean(axis=0) - centre)
            assert not normal[2] and (away > 0 if depth > 0 else away < 0), (material, quad, normal)
    painted = np.zeros((h, w), dtype=np.uint8)
    for depth in sorted({f[0] for f in fronts}):  # seen from the front, the nearest hides what is behind it
        layer = np.zeros((h, w), dtype=np.uint8)
        for _, label, y0, y1, x0, x1 in (f for f in fronts if f[0] == depth):
            assert not layer[y0:y1, x0:x1].any(), "front faces at one depth overlap"
            layer[y0:y1, x0:x1] = label
        painted = np.where(layer > 0, layer, painted)
    assert np.array_equal(painted, rasterize(as_annotated(to_segmentation(proc))))
    relief = procedure_relief(proc, scale)
    assert len(fronts) == len(relief.parts)
    found = [name for name in read_obj.objects if name != "facade"]
    assert sorted(found) == sorted(f"{LABELS[r[0]]}_{i}" for i, r in enumerate(relief.rows.tolist()) if r[0] != FACADE)
    assert found == [e for e in found if e.rsplit("_", 1)[0] in LABEL_ID]
    for name in {m for m, _, _ in faces}:
        r, g, b = PALETTE[name]
        assert f"newmtl {name}\nKd {r / 255:.4f} {g / 255:.4f} {b / 255:.4f}" in mtl


@pytest.mark.parametrize("seed", [2, 3, 7, 12])
def test_front_faces_paint_the_label_map(seed):
    proc = generate(seed).procedure
    check_mesh(proc, 0.02)


def test_a_recess_has_reveals_facing_into_it_and_a_protrusion_sides_facing_out():
    from facaid.grammar.nodes import Node, Size
    from facaid.grammar.procedure import Procedure

    root = Node.split("x", [(Size("abs", 10), Node.leaf("facade")), (Size("abs", 10), Node.leaf("window")),
                            (Size("abs", 10), Node.leaf("cornice")), (Size("flt", 1), Node.leaf("facade"))])
    proc = Procedure(width=40, height=10, root=root)
    obj, _ = procedure_mesh(proc, 0.1)
    vertices, normals, faces, _ = read_obj(obj)
    sides = {}
    for material, corners, n in faces:
        quad = vertices[corners]
        if abs(normals[n][0]) == 1:  # the left and right sides
            sides[(material, round(float(quad[0, 0]), 6))] = normals[n][0]
    # the window spans x 1..2 m: its left reveal at 1 faces right (into the hole), its right one at 2 faces left;
    # the cornice spans 2..3 m: its left side at 2 faces left, its right one at 3 faces right
    assert sides == {("window", 1.0): 1, ("window", 2.0): -1, ("cornice", 2.0): -1, ("cornice", 3.0): 1}
    check_mesh(proc, 0.1)


@pytest.mark.parametrize("bad", [0, -1, float("nan"), 1e6])
def test_a_bad_scale_is_refused(bad):
    with pytest.raises(ValueError, match="scale must be a number of metres per pixel"):
        procedure_mesh(generate(3).procedure, bad)


def test_cli_writes_the_obj_and_its_materials(tmp_path, capsys):
    from facaid.cli import main

    proc = generate(3).procedure
    path = tmp_path / "p.json"
    path.write_text(proc.to_json())
    assert main(["mesh", str(path), "--out", str(tmp_path / "house.obj"), "--metres-per-pixel", "0.02"]) == 0
    assert "house.obj" in capsys.readouterr().out
    obj, mtl = procedure_mesh(proc, 0.02, mtl_name="house.mtl")
    assert (tmp_path / "house.obj").read_text() == obj and (tmp_path / "house.mtl").read_text() == mtl
    assert main(["mesh", str(path), "--out", str(tmp_path / "house.png")]) == 2
    assert "ends in .obj" in capsys.readouterr().err


def test_a_procedure_of_too_many_rectangles_is_refused_with_its_count():
    from facaid.formats.mesh import MAX_MESH_RECTS, MeshTooLarge

    proc = window_grid(200, 60)
    with pytest.raises(MeshTooLarge, match=f"draws 24000 rectangles; a mesh is made of at most {MAX_MESH_RECTS}"):
        procedure_mesh(proc, 0.01)
