"""Issue 67, item 6: do a real facade's exports agree, and does the COCO export hold about the boxes a person drew?

    .venv/bin/python bench/bench_export_agreement.py [--facades 250-254] [--cmp PATH]

Each CMP facade (its number, 1-based: record index = number - 1; 250-254 are in the test half, 190-378, and are
only reported on, never tuned on) is reconstructed as the site does it (`facaid.pipeline.reconstruct` with the
shipped model, the editable structure) and written in every format that holds elements (`facaid export`'s
`EXPORTS`), each file read back as its own kind: COCO's annotations, LabelMe's shapes, CVAT's boxes, the label map
(labels.png) cut into its elements again, the glTF's labelled nodes, the OBJ's objects, the IFC's windows and doors
(IfcOpenShell), CityJSON's Window and Door surfaces. (The CGA rules draw the label map's rectangles exactly;
`tests/formats/test_exports_agree.py` runs them back.) Printed for each facade: the rectangles drawn (the CMP
annotation's), the COCO boxes and their ratio, the windows, doors and shop fronts of each format and the leaves of
each the procedure draws (what the 3D exports held one object each before they took the annotations' elements).
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import xml.etree.ElementTree as ET
from collections import Counter
from pathlib import Path

import numpy as np
from PIL import Image

from facaid.evaluation.real import load_records
from facaid.formats.annotation import label_map_elements
from facaid.formats.exports import EXPORTS
from facaid.formats.relief import drawn_leaves
from facaid.labels import LABEL_ID, LABELS, PALETTE
from facaid.paths import DEFAULT_CMP
from facaid.pipeline import reconstruct

OPENINGS = ("window", "door", "shop")
FORMATS = (".coco.json", ".labelme.json", ".cvat.xml", ".png", ".glb", ".obj", ".ifc", ".city.json")


def _labels(ext: str, path: Path) -> list[str]:
    """The labels of the elements a file holds (of the openings, for IFC)."""
    if ext == ".coco.json":
        doc = json.loads(path.read_text())
        names = {c["id"]: c["name"] for c in doc["categories"]}
        return [names[a["category_id"]] for a in doc["annotations"]]
    if ext == ".labelme.json":
        return [s["label"] for s in json.loads(path.read_text())["shapes"]]
    if ext == ".cvat.xml":
        return [b.get("label") for b in ET.parse(path).getroot().iter("box")]
    if ext == ".png":
        colours = {rgb: LABEL_ID[name] for name, rgb in PALETTE.items()}
        rgb = np.asarray(Image.open(path).convert("RGB")).astype(np.int64)
        code = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
        lookup = {(r << 16) | (g << 8) | b: i for (r, g, b), i in colours.items()}
        label_map = np.vectorize(lookup.__getitem__, otypes=[np.uint8])(code)
        return [LABELS[r[0]] for r in label_map_elements(label_map).tolist()]
    if ext == ".glb":
        import pygltflib

        gltf = pygltflib.GLTF2.load_binary(str(path))
        return [n.extras["label"] for n in gltf.nodes if isinstance(n.extras, dict) and "label" in n.extras]
    if ext == ".obj":
        return [line.split()[1].rsplit("_", 1)[0] for line in path.read_text().splitlines() if line.startswith("o ")]
    if ext == ".ifc":
        import ifcopenshell

        model = ifcopenshell.open(str(path))
        return (["window" if w.PredefinedType == "WINDOW" else "shop" for w in model.by_type("IfcWindow")]
                + ["door"] * len(model.by_type("IfcDoor")))
    if ext == ".city.json":
        geometry = json.loads(path.read_text())["CityObjects"]["facade"]["geometry"][0]
        return [s["label"] for s in geometry["semantics"]["surfaces"] if s["type"] != "WallSurface"]
    raise ValueError(ext)


def _facades(text: str) -> list[int]:
    lo, _, hi = text.partition("-")
    return list(range(int(lo), int(hi or lo) + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--facades", default="250-254", help="CMP facade numbers, 1-based: N or N-M")
    parser.add_argument("--cmp", default=str(DEFAULT_CMP), help="the CMP annotations (JSON lines)")
    args = parser.parse_args()
    if not Path(args.cmp).is_file():
        sys.exit(f"error: the CMP annotations are not at {args.cmp} (FACAID_CMP, or --cmp)")
    total_in = total_boxes = 0
    agree = True
    with tempfile.TemporaryDirectory() as folder:
        for number in _facades(args.facades):
            (name, seg), = load_records(args.cmp, 1, number - 1)
            proc = reconstruct(seg).procedure
            counts = {}
            for ext in FORMATS:
                path = Path(folder) / f"facade{ext}"
                EXPORTS[ext].write(proc, path, 0.02 if EXPORTS[ext].scaled else None, None)
                labels = _labels(ext, path)
                counts[ext] = Counter(label for label in labels if label in OPENINGS)
                if ext == ".coco.json":
                    boxes = len(labels)
            leaves = Counter(LABELS[r[0]] for r in drawn_leaves(proc)[0].tolist())
            total_in, total_boxes = total_in + len(seg.rects), total_boxes + boxes
            same = all(c == counts[".coco.json"] for c in counts.values())
            agree &= same
            print(f"facade {number} ({name}): {len(seg.rects)} rectangles drawn, {boxes} COCO boxes "
                  f"({boxes / len(seg.rects):.2f}x); windows/doors/shop fronts "
                  + ", ".join(f"{ext[1:]} {'/'.join(str(c[k]) for k in OPENINGS)}" for ext, c in counts.items())
                  + f"; leaves drawn {'/'.join(str(leaves[k]) for k in OPENINGS)}"
                  + ("" if same else "  <- the formats disagree"), flush=True)
    print(f"all: {total_in} rectangles drawn, {total_boxes} COCO boxes ({total_boxes / total_in:.2f}x; target "
          f"<= 1.25x); every format holds the same windows, doors and shop fronts: {'yes' if agree else 'NO'}")


if __name__ == "__main__":
    main()
