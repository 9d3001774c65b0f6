"""Procedures and files the format and download tests share."""

import json
from pathlib import Path

from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID
from facaid.segmentation import Rect

FORMATS_DATA = Path(__file__).parent / "formats" / "data"  # files made by hand to the published formats


def window_grid(columns: int, rows: int, size: int = 2000, apart: bool = False) -> Procedure:
    """``rows`` rows of ``columns`` windows, each beside a piece of wall: ``2 * columns * rows`` rectangles;
    window_grid(200, 60) draws 24,000, past every 3D export's cap. The windows of a column touch, so they are one
    element each column (one window, to an annotator); ``apart``: a band of wall under each row, so that each window
    is one (``rows`` rectangles more)."""
    row = Node.repeat("x", columns, [(Size("flt", 1), Node.leaf("window")), (Size("flt", 1), Node.leaf("facade"))])
    band = [(Size("flt", 1), Node.leaf("facade"))] if apart else []
    return Procedure(width=size, height=size, root=Node.repeat("y", rows, [(Size("flt", 1), row), *band]))


def rect(label, x0, y0, x1, y1):
    """A rectangle of the label named."""
    return Rect(LABEL_ID[label], x0, y0, x1, y1)


def labelme(**change):
    """The hand-made LabelMe file (formats/data), as text, with ``change`` made: a key set, or removed with None;
    ``shape1_<key>`` sets a key of its second shape."""
    doc = json.loads((FORMATS_DATA / "facade.labelme.json").read_text())
    for key, value in change.items():
        if key.startswith("shape1_"):
            doc["shapes"][1][key.removeprefix("shape1_")] = value
        elif value is None:
            del doc[key]
        else:
            doc[key] = value
    return json.dumps(doc)


def coco(**change):
    """The hand-made COCO file (formats/data), as text, its first image only, with ``change`` made: ``<part>`` sets
    a part; ``<part>_<key>`` sets (or removes, with None) a key of its first image, category, or its second
    annotation."""
    doc = json.loads((FORMATS_DATA / "facades.coco.json").read_text())
    doc["images"] = doc["images"][:1]
    for key, value in change.items():
        part, field = key.split("_", 1) if "_" in key else (key, None)
        if field is None:
            doc[part] = value
        elif value is None:
            del doc[part][1 if part == "annotations" else 0][field]
        else:
            doc[part][1 if part == "annotations" else 0][field] = value
    return json.dumps(doc)
