"""Issue 67, item 6: for one procedure, every export holds the same windows and doors. Each file is written as
`facaid export` writes it and read back as its own kind of file (the JSON, the XML, ifcopenshell, trimesh's glTF, the
OBJ's objects, CityJSON's semantic surfaces, the CGA run by the tests' interpreter, the PNG's colours), for generated
facades, a lattice-like one with exceptions and the exact procedure of an annotation drawn as people draw CMP's."""

import json
import xml.etree.ElementTree as ET
from collections import Counter

import ifcopenshell
import numpy as np
import pytest
from grammar_helpers import example, real_like
from PIL import Image
from test_cga import run_cga
from test_gltf import elements as gltf_elements
from test_gltf import load

from facaid.formats.annotation import TOLERANCE, element_array, label_map_elements
from facaid.formats.exports import EXPORTS
from facaid.generator import generate
from facaid.grammar.decompose import procedure_from_segmentation
from facaid.grammar.execute import leaf_array
from facaid.labels import LABEL_ID, LABELS, PALETTE, PRIORITY
from facaid.segmentation import Rect, Segmentation, rasterize

SCALE = 0.02
OPENINGS = ("window", "door", "shop")
COLOURS = {rgb: LABEL_ID[name] for name, rgb in PALETTE.items()}

PROCEDURES = {
    "generated 3": lambda: generate(3).procedure,
    "generated 7": lambda: generate(7).procedure,
    "generated 12": lambda: generate(12).procedure,
    "lattice with exceptions": example,  # a closed blind, a sill left out, a taller floor, a wider bay
    "drawn as people draw CMP's": lambda: procedure_from_segmentation(real_like(3)),  # windows behind blinds
}


def _count(labels) -> dict[str, int]:
    found = Counter(labels)
    return {name: found[name] for name in OPENINGS}


def read_every_format(proc, folder) -> tuple[dict[str, dict[str, int]], dict[str, set]]:
    """For each format, how many windows, doors and shop fronts the file holds; and, where a file gives them, the
    boxes of those in pixels."""
    counts, boxes = {}, {}
    w, h = round(proc.width), round(proc.height)
    for ext, export in EXPORTS.items():
        if export.needs_photo or ext in (".json", ".segmentation.json", ".svg", ".gltf"):
            continue  # no elements: the tree, its exact pieces, the pieces drawn (the .gltf is the .glb as text)
        path = folder / f"facade{ext}"
        export.write(proc, path, SCALE if export.scaled else None, None)
        if ext == ".coco.json":
            doc = json.loads(path.read_text())
            names = {c["id"]: c["name"] for c in doc["categories"]}
            found = [(names[a["category_id"]], *a["bbox"]) for a in doc["annotations"]]
            found = [(label, x, y, x + bw, y + bh) for label, x, y, bw, bh in found]
        elif ext == ".labelme.json":
            found = [(s["label"], *s["points"][0], *s["points"][1]) for s in json.loads(path.read_text())["shapes"]]
        elif ext == ".cvat.xml":
            found = [(b.get("label"), *(float(b.get(k)) for k in ("xtl", "ytl", "xbr", "ybr")))
                     for b in ET.parse(path).getroot().iter("box")]
        elif ext == ".glb":
            found = [(e["extras"]["label"], *e["extras"]["box_px"]) for e in gltf_elements(load(path.read_bytes()))
                     .values()]
        elif ext == ".png":
            pixels = np.asarray(Image.open(path).convert("RGB"))
            label_map = np.vectorize(lambda *rgb: COLOURS[rgb], otypes=[np.uint8])(*np.moveaxis(pixels, 2, 0))
            found = [(LABELS[r[0]], *r[1:]) for r in label_map_elements(label_map).tolist()]
        elif ext == ".cga":
            drawn = [(LABEL_ID[label], *np.rint([x0 / SCALE, h - y1 / SCALE, x1 / SCALE, h - y0 / SCALE]))
                     for label, x0, y0, x1, y1 in run_cga(path.read_text(), w * SCALE, h * SCALE)]
            rows = np.array([r for r in drawn if r[1] < r[3] and r[2] < r[4]], dtype=np.int64)
            found = [(LABELS[r[0]], *r[1:]) for r in element_array(w, h, rows).tolist()]
        elif ext == ".ifc":
            model = ifcopenshell.open(str(path))
            counts[ext] = {"window": sum(x.PredefinedType == "WINDOW" for x in model.by_type("IfcWindow")),
                           "door": len(model.by_type("IfcDoor")),
                           "shop": sum(x.ObjectType == "shop front" for x in model.by_type("IfcWindow"))}
            continue
        elif ext == ".obj":
            counts[ext] = _count(line.split()[1].rsplit("_", 1)[0] for line in path.read_text().splitlines()
                                 if line.startswith("o "))
            continue
        elif ext == ".city.json":
            geometry = json.loads(path.read_text())["CityObjects"]["facade"]["geometry"][0]
            counts[ext] = _count(s["label"] for s in geometry["semantics"]["surfaces"] if s["type"] != "WallSurface")
            continue
        else:
            raise AssertionError(f"a format this test does not read: {ext}")
        counts[ext] = _count(label for label, *_ in found)
        boxes[ext] = {(label, *map(round, box)) for label, *box in found if label in OPENINGS}
    return counts, boxes


@pytest.mark.parametrize("name", list(PROCEDURES))
def test_every_format_holds_the_same_windows_and_doors(name, tmp_path):
    proc = PROCEDURES[name]()
    counts, boxes = read_every_format(proc, tmp_path)
    assert set(counts) == {".coco.json", ".labelme.json", ".cvat.xml", ".png", ".cga", ".glb", ".obj", ".ifc",
                           ".city.json"}
    expected = counts[".coco.json"]
    assert expected["window"] > 0 and all(found == expected for found in counts.values()), counts
    expected = boxes[".coco.json"]
    assert all(found == expected for ext, found in boxes.items() if ext != ".cga")  # and in the same places
    # the CGA's sizes are metres to a tenth of a millimetre: an edge half way across a pixel may round either way
    cga = sorted(boxes[".cga"])
    assert len(cga) == len(expected) and all(a[0] == b[0] and max(abs(np.subtract(a[1:], b[1:]))) <= 1
                                             for a, b in zip(cga, sorted(expected), strict=True))


def test_a_window_behind_its_blind_is_one_window_and_a_cornice_along_a_floor_one_cornice():
    """The pieces an element is drawn in (a window around a blind over its middle, a cornice cut tile by tile with a
    pixel's step between tiles) come out as one box; two windows side by side stay two."""
    window, blind, cornice, wall = LABEL_ID["window"], LABEL_ID["blind"], LABEL_ID["cornice"], LABEL_ID["facade"]
    rects = [Rect(wall, 0, 0, 200, 100),
             Rect(window, 10, 10, 40, 60), Rect(blind, 20, 20, 30, 60),  # the blind hides its middle and bottom
             Rect(window, 50, 10, 80, 60),  # the next window, 10 px of wall away
             *(Rect(cornice, x, 70 + (x // 40) % 2, x + 40, 80) for x in range(0, 200, 40))]
    seg = Segmentation(200, 100, tuple(rects))
    found = element_array(200, 100, seg.to_array())
    assert sorted(map(tuple, found.tolist())) == sorted([(window, 10, 10, 40, 60), (window, 50, 10, 80, 60),
                                                         (blind, 20, 20, 30, 60), (cornice, 0, 70, 200, 80)])
    assert np.array_equal(label_map_elements(rasterize(seg)), found)  # its picture gives the same boxes


def test_pieces_further_apart_than_the_tolerance_stay_apart():
    cornice, sill = LABEL_ID["cornice"], LABEL_ID["sill"]
    step = TOLERANCE + 1
    rects = [Rect(cornice, 0, 10, 40, 20), Rect(cornice, 40, 10 + step, 80, 20),  # a step of 3 px: two cornices
             Rect(sill, 0, 40, 30, 44), Rect(sill, 60, 40, 90, 44)]  # two sills, wall between them
    found = element_array(100, 60, np.array(rects))
    assert len(found) == 4


def test_merged_boxes_paint_over_at_most_the_tolerance_along_their_edges():
    """Of every procedure above, each element's box shows its own label, or what is painted over it, everywhere
    but within `TOLERANCE` pixels of its edges; and every pixel of an element's label is in one of its boxes."""
    for make in PROCEDURES.values():
        proc = make()
        w, h = round(proc.width), round(proc.height)
        label_map = rasterize(Segmentation.from_array(w, h, leaf_array(proc)))
        priority = np.asarray(PRIORITY)[label_map]
        found = element_array(w, h, leaf_array(proc))
        for label in np.unique(found[:, 0]).tolist():
            mine = found[found[:, 0] == label]
            covered = np.zeros_like(label_map, dtype=bool)
            for x0, y0, x1, y1 in mine[:, 1:].tolist():
                covered[y0:y1, x0:x1] = True
                core = priority[y0 + TOLERANCE:y1 - TOLERANCE, x0 + TOLERANCE:x1 - TOLERANCE]
                assert (core >= PRIORITY[label]).all(), (LABELS[label], x0, y0, x1, y1)
            assert covered[label_map == label].all()
