"""`facaid export PROC.json --out FILE`: the format from the extension, each file read back by a reader of its
own format, and bad input refused with an error and exit code 2."""

import io
import json
import xml.etree.ElementTree as ET

import ifcopenshell
import pytest
import trimesh
from format_helpers import window_grid
from PIL import Image

from facaid.cli import main
from facaid.formats.annotation import as_annotated, elements
from facaid.formats.exports import EXPORTS, export_for
from facaid.formats.interchange import read as read_annotations
from facaid.formats.relief import procedure_relief
from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID
from facaid.segmentation import rasterize


@pytest.fixture(scope="module")
def proc():
    return generate(3).procedure


@pytest.fixture
def source(tmp_path, proc):
    path = tmp_path / "p.json"
    path.write_text(proc.to_json())
    return path


def read_back(path, proc):
    """The number of elements each format's reader finds in the file (labelled rectangles, nodes, windows)."""
    name = path.name
    if name.endswith((".segmentation.json", ".coco.json", ".labelme.json", ".cvat.xml")):
        return len(read_annotations(path.read_bytes(), size=(round(proc.width), round(proc.height))).rects)
    if name.endswith(".city.json"):
        doc = json.loads(path.read_text())
        return sum(s["type"] == "Window" for s in doc["CityObjects"]["facade"]["geometry"][0]["semantics"]["surfaces"])
    if name.endswith(".json"):
        return len(to_segmentation(Procedure.from_json(path.read_text())).rects)
    if name.endswith(".png"):
        return Image.open(path).size
    if name.endswith(".svg"):
        return sum(1 for e in ET.parse(path).iter() if e.tag.endswith("rect")) - 1  # the background's
    if name.endswith(".cga"):
        return path.read_text().count("-->")
    if name.endswith(".obj"):
        return trimesh.load(path, force="scene").geometry.keys() >= {"window"} and path.with_suffix(".mtl").is_file()
    if name.endswith((".glb", ".gltf")):
        scene = trimesh.load(io.BytesIO(path.read_bytes()), file_type=path.suffix[1:], force="scene")
        return sum("label" in d.get("metadata", {}) for d in scene.graph.transforms.edge_data.values())
    if name.endswith(".ifc"):
        return len(ifcopenshell.open(str(path)).by_type("IfcWindow"))
    raise AssertionError(name)


def test_every_extension_writes_its_format(tmp_path, source, proc, capsys):
    rects = len(to_segmentation(proc).rects)
    found = elements(to_segmentation(proc))  # one box per element: what the annotations and the 3D exports hold
    windows = sum(r.label in (LABEL_ID["window"], LABEL_ID["shop"]) for r in found)
    boxes = len(as_annotated(to_segmentation(proc)).rects)  # those, the wall under them
    relief = len(procedure_relief(proc, 0.02).rows)  # those, and the wall's pieces
    assert len(found) == sum(label != "facade" for label in procedure_relief(proc, 0.02).labels())
    assert len(found) < boxes < rects
    expected = {".json": rects, ".png": (444, 797), ".svg": rects, ".obj": True, ".glb": relief, ".gltf": relief,
                ".ifc": windows, ".city.json": windows, ".overlay.png": (444, 797), ".coco.json": boxes,
                ".labelme.json": boxes, ".cvat.xml": boxes}
    photo = tmp_path / "photo.png"
    Image.new("RGB", (proc.width, proc.height), (120, 80, 40)).save(photo)
    for ext in EXPORTS:
        out = tmp_path / f"house{ext}"
        extra = ["--metres-per-pixel", "0.02"] if EXPORTS[ext].scaled else []
        extra += ["--photo", str(photo)] if EXPORTS[ext].needs_photo else []
        assert main(["export", str(source), "--out", str(out), *extra]) == 0, ext
        printed = capsys.readouterr().out
        assert f"wrote {out}" in printed and EXPORTS[ext].what in printed
        if EXPORTS[ext].scaled:  # every metric export says its scale
            assert "8.88 m x 15.94 m at 0.02 m per pixel (given)" in printed
        if ext == ".cga":
            assert read_back(out, proc) > 3
        else:
            assert read_back(out, proc) == expected.get(ext, rects), ext
    coco = json.loads((tmp_path / "house.coco.json").read_text())
    assert coco["images"][0]["file_name"] == "house.png"  # the label map written by --out house.png
    back = read_annotations((tmp_path / "house.coco.json").read_bytes(), size=(round(proc.width), round(proc.height)))
    assert (rasterize(back) == rasterize(to_segmentation(proc))).all()  # the same label map in fewer boxes


def test_the_longest_extension_wins():
    assert export_for("a/house.city.json")[0] == ".city.json"
    assert export_for("HOUSE.GLB")[0] == ".glb"
    assert export_for("house.json")[0] == ".json"
    assert export_for(".json") is None and export_for("house.txt") is None


def test_the_glb_takes_the_photo(tmp_path, source, proc, capsys):
    photo = tmp_path / "photo.png"
    Image.new("RGB", (proc.width, proc.height), (120, 80, 40)).save(photo)
    assert main(["export", str(source), "--out", str(tmp_path / "f.glb"), "--photo", str(photo)]) == 0
    assert "a storey 3 m tall" in capsys.readouterr().out
    scene = trimesh.load(tmp_path / "f.glb", force="scene")
    assert any(getattr(g.visual, "uv", None) is not None for g in scene.geometry.values())
    Image.new("RGB", (100, 400)).save(photo)  # not the rectified photo's shape: written, with a warning
    assert main(["export", str(source), "--out", str(tmp_path / "g.glb"), "--photo", str(photo)]) == 0
    assert "warning: the photo (100x400) is stretched" in capsys.readouterr().err


@pytest.mark.parametrize("args, message", [
    (["--out", "{tmp}/f.txt"], "the format comes from the file's extension, one of .json .segmentation.json"),
    (["--out", "{tmp}/f.ifc", "--metres-per-pixel", "0"], "--metres-per-pixel: scale must be a number"),
    (["--out", "{tmp}/f.ifc", "--metres-per-pixel", "nan"], "--metres-per-pixel: scale must be a number"),
    (["--out", "{tmp}/f.png", "--metres-per-pixel", "0.02"], "a .png file is in pixels"),
    (["--out", "{tmp}/f.ifc", "--photo", "{tmp}/p.json"], "--photo is the texture of a .glb or .gltf"),
    (["--out", "{tmp}/f.overlay.png"], "a .overlay.png file is drawn over the photo: give it with --photo"),
    (["--out", "{tmp}/f.glb", "--photo", "{tmp}/missing.png"], "cannot read photo"),
])
def test_bad_arguments_are_an_error_not_a_crash(tmp_path, source, capsys, args, message):
    args = [a.format(tmp=tmp_path) for a in args]
    assert main(["export", str(source), *args]) == 2
    assert message in capsys.readouterr().err


def test_bad_input_is_an_error_not_a_crash(tmp_path, capsys):
    huge = tmp_path / "huge.json"
    huge.write_text(window_grid(200, 60).to_json())
    for ext in (".glb", ".ifc", ".city.json", ".obj"):
        assert main(["export", str(huge), "--out", str(tmp_path / f"f{ext}")]) == 2
        assert "error: the procedure draws 24000 rectangles" in capsys.readouterr().err
    segmentation = tmp_path / "seg.json"
    segmentation.write_text(json.dumps({"width": 10, "height": 10, "rects": []}))
    assert main(["export", str(segmentation), "--out", str(tmp_path / "f.glb")]) == 2
    assert capsys.readouterr().err.startswith("error: ")
