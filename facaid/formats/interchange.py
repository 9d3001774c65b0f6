"""Rectangle annotations of other tools, read into a `Segmentation` and written from one: COCO, LabelMe and
CVAT for images, besides the segmentation contract itself.

The formats, as published:

- **COCO** object detection, the "Data format" of https://cocodataset.org/#format-data: one JSON object with
  ``images`` ``[{id, width, height, file_name}]``, ``annotations`` ``[{id, image_id, category_id, bbox: [x, y,
  width, height], area, iscrowd, segmentation}]`` and ``categories`` ``[{id, name, supercategory}]``; "box
  coordinates are measured from the top left image corner and are 0-indexed".
- **LabelMe**, the JSON file labelme saves (``LabelFile.save`` in labelme/label_file.py,
  https://github.com/wkentaro/labelme): ``version``, ``flags``, ``shapes`` ``[{label, points, group_id,
  shape_type, flags}]``, ``imagePath``, ``imageData``, ``imageHeight``, ``imageWidth``; a ``rectangle`` shape's
  points are two opposite corners, in the order they were drawn; a shape without ``shape_type`` is a polygon.
- **CVAT for images 1.1**, CVAT's "XML annotation format" (https://docs.cvat.ai/docs/other/xml_format/):
  ``<annotations><version>1.1</version><meta>…<labels>…</labels>…</meta><image id name width height><box
  label xtl ytl xbr ybr occluded z_order/>…</image>…</annotations>``.

How they map onto the contract (docs/interchange.md has the table):

- All three give continuous pixel coordinates from the image's top-left corner, as the contract does; a box's
  edges are rounded each to the nearest whole pixel (Python's `round`, halves to even, as `parse_segmentation`
  rounds), so that boxes sharing an edge still share it, then clipped to the image. A box empty after that is an
  error naming it (``annotations[3].bbox``).
- Labels are the 12 CMP classes of `facaid.labels`, read regardless of case, spaces, ``-`` and ``_``, in the
  plural ("Windows", "balconies") and as "moulding" or "decoration"; any other is an error naming the label
  and where it is used.
- A polygon (LabelMe ``polygon``, CVAT ``<polygon>``) is read as its bounding box, with a warning: facade
  elements drawn as polygons are near-rectangles, and the warning says the shape changed. Points, lines,
  circles, masks and the rest have no rectangle to read and are an error naming the shape. CVAT ``<tag>``s
  label a whole image and are skipped with a warning; COCO's ``segmentation`` is not read (``bbox`` is the
  box), nor ``iscrowd`` but for a warning.
- Written files hold one image, every class as a category or label (in `facaid.labels` order, COCO ids from
  1), the rectangles in the segmentation's order, COCO's ``segmentation`` as the rectangle's polygon and CVAT's
  ``z_order`` as the class's place in the paint order, so that tools draw overlaps as flattening paints them.

A COCO or CVAT file may hold many images: ``image=`` names the one to read (its file name, the file name
without its folders, or its id), or ``size=`` picks the only one of a size; several without either is an error
listing them. Bad input raises
`InterchangeError`, a `SegmentationError` (so a `ValueError`) whose message names the field.
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Any

import defusedxml.ElementTree as SafeET
from defusedxml import DefusedXmlException

from facaid.formats.fields import (
    Choice,
    InterchangeError,
    Notes,
    SeveralImages,
    as_list,
    as_object,
    check_count,
    label_of,
    number,
    pick,
    rect,
    size_of,
)
from facaid.labels import LABELS, PRIORITY
from facaid.segmentation import Rect, Segmentation, SegmentationError

__all__ = ["CONTENT_TYPES", "FORMATS", "SUFFIXES", "InterchangeError", "Loaded", "SeveralImages", "detect",
           "format_for_name", "load", "not_annotations", "read", "write"]  # the errors are fields.py's
FORMATS = ("segmentation", "coco", "labelme", "cvat")
SUFFIXES = {"coco": ".coco.json", "labelme": ".labelme.json", "cvat": ".cvat.xml", "segmentation": ".json"}
CONTENT_TYPES = {"coco": "application/json", "labelme": "application/json", "cvat": "application/xml",
                 "segmentation": "application/json"}
LABELME_VERSION = "5.5.0"  # labelme warns on a file of another major version than its own


@dataclass(frozen=True)
class Loaded:
    """What `load` read from a file."""

    segmentation: Segmentation
    format: str  # one of FORMATS
    image: str | None  # the image's name in the file, where it has one
    warnings: tuple[str, ...]  # what was read other than as it stands (polygons as boxes, skipped tags)


def format_for_name(name: str) -> str | None:
    """The format a file name asks for by its extension (``.coco.json``, ``.labelme.json``, ``.cvat.xml`` or
    ``.xml``, and plain ``.json`` for the segmentation contract), else None."""
    lower = name.lower()
    for fmt in ("coco", "labelme", "cvat"):
        if lower.endswith(SUFFIXES[fmt]):
            return fmt
    return "cvat" if lower.endswith(".xml") else "segmentation" if lower.endswith(".json") else None


def read(data: bytes | str | dict, format: str | None = None, *, image: str | None = None,
         size: tuple[int, int] | None = None) -> Segmentation:
    """The segmentation of an annotation file (`load` without its warnings)."""
    return load(data, format, image=image, size=size).segmentation


def load(data: bytes | str | dict, format: str | None = None, *, image: str | None = None,
         size: tuple[int, int] | None = None) -> Loaded:
    """Read an annotation file of one of `FORMATS`, the format told or else found from the content. ``data`` is
    the file's bytes or text, or its JSON already decoded. Of a file of several images, ``image`` names the one to
    read; without it, ``size`` (width, height) picks the only one of that size, if one is."""
    if format is not None and format not in FORMATS:
        raise InterchangeError(f"format {format!r} is not one of {', '.join(FORMATS)}")
    found, doc = _parse(data)
    if format is not None and format != found:
        raise InterchangeError(f"the file is not {format}: it reads as {found}")
    notes = Notes()
    if found == "segmentation":
        try:
            return Loaded(Segmentation.from_dict(doc), found, None, ())
        except SegmentationError as exc:
            raise InterchangeError(str(exc)) from None
    seg, name = _READERS[found](doc, Choice(image, size), notes)
    return Loaded(seg, found, name, notes.lines())


def detect(data: bytes | str | dict) -> str:
    """Which of `FORMATS` the content is."""
    return _parse(data)[0]


def write(seg: Segmentation, format: str, *, image: str = "facade.png") -> bytes:
    """The segmentation as a file of ``format`` (one of `FORMATS`), naming its picture ``image``."""
    if format not in FORMATS:
        raise InterchangeError(f"format {format!r} is not one of {', '.join(FORMATS)}")
    if format == "segmentation":
        return seg.to_json().encode()
    return _WRITERS[format](seg, image)


# --- reading: the document, its parts -----------------------------------------------------------------------------

KINDS = ((b"\xff\xd8\xff", "a JPEG image"), (b"\x89PNG", "a PNG image"), (b"GIF8", "a GIF image"),
         (b"%PDF", "a PDF document"), (b"PK\x03\x04", "a ZIP archive"), (b"II*\x00", "a TIFF image"),
         (b"MM\x00*", "a TIFF image"), (b"BM", "a BMP image"))
WANTED = "annotations are our segmentation JSON, COCO or LabelMe JSON, or CVAT XML (docs/interchange.md)"


def not_annotations(data: bytes | str) -> str | None:
    """Where ``data`` is plainly no annotation file (an image, a PDF, a ZIP, binary), the message that says so and
    what is; else None. A person picks the photo instead of its annotations more often than a broken file."""
    if isinstance(data, bytes):
        head = data[:16]
        kind = next((what for magic, what in KINDS if head.startswith(magic)), None)
        if kind is None and head[:4] == b"RIFF" and head[8:12] == b"WEBP":
            kind = "a WebP image"
        if kind is None and b"\x00" in data[:1024]:
            kind = "a binary file"
    else:
        kind = "a binary file" if "\x00" in data[:1024] or "\ufffd" in data[:16] else None
    return f"this is {kind}, not annotations: {WANTED}" if kind else None


def _parse(data: bytes | str | dict) -> tuple[str, Any]:
    if isinstance(data, dict):
        return _json_format(data), data
    if isinstance(data, bytes | str) and (message := not_annotations(data)):
        raise InterchangeError(message)
    if isinstance(data, bytes):
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError as exc:
            raise InterchangeError(f"not a UTF-8 text file: {exc}") from None
    elif isinstance(data, str):
        text = data.removeprefix("\ufeff")
    else:
        raise InterchangeError(f"give the file's bytes, text or JSON object, not {type(data).__name__}")
    if text.lstrip().startswith("<"):
        return "cvat", _xml(text)
    try:
        doc = json.loads(text)
    except RecursionError:
        raise InterchangeError("malformed JSON: nested too deeply") from None
    except json.JSONDecodeError as exc:
        if text.lstrip()[:1] in ("{", "["):  # JSON, broken: say where
            raise InterchangeError(f"malformed JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}") from None
        raise InterchangeError(f"neither JSON nor XML: {exc}") from None
    except ValueError as exc:
        raise InterchangeError(f"neither JSON nor XML: {exc}") from None
    if not isinstance(doc, dict):
        raise InterchangeError(f"the JSON is a {type(doc).__name__}; annotations are a JSON object")
    return _json_format(doc), doc


def _json_format(doc: dict) -> str:
    if "shapes" in doc:
        return "labelme"
    if {"images", "annotations"} & doc.keys():
        return "coco"
    if "rects" in doc:
        return "segmentation"
    keys = ", ".join(map(repr, list(doc)[:8])) or "none"
    raise InterchangeError(f"not a segmentation ('rects'), COCO ('images', 'annotations') or LabelMe ('shapes') "
                           f"file: its keys are {keys}")


def _xml(text: str) -> ET.Element:
    try:
        # no DTD at all: CVAT's files have none, and entities are how XML bombs and external fetches come in
        root = SafeET.fromstring(text.encode(), forbid_dtd=True)
    except (ET.ParseError, DefusedXmlException) as exc:
        raise InterchangeError(f"malformed or unsafe XML: {exc}") from None
    if root.tag != "annotations":
        raise InterchangeError(f"the XML's root is <{root.tag}>, not CVAT's <annotations>")
    return root


# --- the formats -------------------------------------------------------------------------------------------------

def _read_coco(doc: dict, choice: Choice, notes: Notes) -> tuple[Segmentation, str]:
    images = as_list(doc.get("images"), "images")
    for i, entry in enumerate(images):
        as_object(entry, f"images[{i}]")
    names = [e["file_name"] if isinstance(e.get("file_name"), str) and e["file_name"] else str(e.get("id"))
             for e in images]
    k = pick(names, [str(e.get("id")) for e in images], [(e.get("width"), e.get("height")) for e in images],
              choice, "images")
    entry = images[k]
    if "id" not in entry:
        raise InterchangeError(f"images[{k}].id is missing")
    size = size_of(entry.get("width"), entry.get("height"), f"images[{k}]")
    categories = {}
    for i, cat in enumerate(as_list(doc.get("categories"), "categories")):
        cat = as_object(cat, f"categories[{i}]")
        if isinstance(cat.get("id"), bool) or not isinstance(cat.get("id"), int | str):
            raise InterchangeError(f"categories[{i}].id must be a number, got {str(cat.get('id'))[:40]}")
        categories[cat["id"]] = (cat.get("name"), f"categories[{i}].name")
    rects = []
    for i, ann in enumerate(as_list(doc.get("annotations"), "annotations")):
        where = f"annotations[{i}]"
        ann = as_object(ann, where)
        if ann.get("image_id") != entry["id"] or isinstance(ann.get("image_id"), bool):
            continue
        cat = ann.get("category_id")
        if isinstance(cat, bool) or not isinstance(cat, int | str) or cat not in categories:
            raise InterchangeError(f"{where}.category_id {str(cat)[:40]} is not the id of one of the categories")
        name, cat_where = categories[cat]
        label = label_of(name, f"{cat_where} (of {where})")
        box = as_list(ann.get("bbox"), f"{where}.bbox")
        if len(box) != 4:
            raise InterchangeError(f"{where}.bbox must be [x, y, width, height], got {len(box)} numbers")
        x, y, w, h = (number(v, f"{where}.bbox") for v in box)
        if w < 0 or h < 0:
            raise InterchangeError(f"{where}.bbox has a negative width or height: {box}")
        if ann.get("iscrowd") == 1:
            notes.add("crowd annotations (iscrowd 1) read as one box each", where)
        rects.append(rect(label, x, y, x + w, y + h, size, f"{where}.bbox"))
        check_count(rects, "annotations")
    return Segmentation(*size, tuple(rects)), names[k]


def _read_labelme(doc: dict, choice: Choice, notes: Notes) -> tuple[Segmentation, str | None]:
    size = size_of(doc.get("imageWidth"), doc.get("imageHeight"), "", ("imageWidth", "imageHeight"))
    shapes = as_list(doc.get("shapes"), "shapes")
    check_count(shapes, "shapes")
    rects = []
    for i, shape in enumerate(shapes):
        where = f"shapes[{i}]"
        shape = as_object(shape, where)
        label = label_of(shape.get("label"), f"{where}.label")
        kind = shape.get("shape_type") or "polygon"  # as labelme reads a shape without one
        points = as_list(shape.get("points"), f"{where}.points")
        if kind == "rectangle" and len(points) != 2:
            raise InterchangeError(f"{where}.points: a rectangle has 2 corners, got {len(points)} points")
        if kind == "polygon" and len(points) < 3:
            raise InterchangeError(f"{where}.points: a polygon has at least 3 points, got {len(points)}")
        if kind not in ("rectangle", "polygon"):
            raise InterchangeError(f"{where}.shape_type {str(kind)[:40]!r} is not a rectangle or a polygon")
        xs, ys = [], []
        for j, p in enumerate(points):
            if not isinstance(p, list) or len(p) != 2:
                raise InterchangeError(f"{where}.points[{j}] must be [x, y]")
            xs.append(number(p[0], f"{where}.points[{j}]"))
            ys.append(number(p[1], f"{where}.points[{j}]"))
        if kind == "polygon":
            notes.add("polygons read as their bounding boxes", where)
        rects.append(rect(label, min(xs), min(ys), max(xs), max(ys), size, where))
    name = doc.get("imagePath")
    return Segmentation(*size, tuple(rects)), name if isinstance(name, str) and name else None


CVAT_SHAPES = ("box", "polygon", "polyline", "points", "ellipse", "cuboid", "mask", "skeleton")


def _read_cvat(root: ET.Element, choice: Choice, notes: Notes) -> tuple[Segmentation, str]:
    images = root.findall("image")
    if not images and root.find("track") is not None:
        raise InterchangeError("this is CVAT for video (<track>s of frames): export the task as CVAT for images")
    names = [el.get("name") or el.get("id") or f"#{i}" for i, el in enumerate(images)]
    k = pick(names, [str(el.get("id")) for el in images], [(el.get("width"), el.get("height")) for el in images],
              choice, "<image>")
    el = images[k]
    at = f"image[{k}]"
    size = size_of(el.get("width"), el.get("height"), at)
    rects: list[Rect] = []
    seen: dict[str, int] = {}
    for child in el:
        n = seen[child.tag] = seen.get(child.tag, -1) + 1
        where = f"{at}.{child.tag}[{n}]"
        if child.tag == "tag":
            notes.add("image tags (<tag>) skipped", where)
            continue
        if child.tag not in CVAT_SHAPES:
            continue  # not an annotation (CVAT adds elements in minor versions)
        label = label_of(child.get("label"), f"{where}.label")
        if child.tag == "box":
            box = (child.get("xtl"), child.get("ytl"), child.get("xbr"), child.get("ybr"))
            if None in box:
                raise InterchangeError(f"{where} needs xtl, ytl, xbr and ybr")
            rects.append(rect(label, *box, size, where, fields=("xtl", "ytl", "xbr", "ybr")))
        elif child.tag == "polygon":
            xs, ys = _points(child.get("points"), f"{where}.points")
            notes.add("polygons read as their bounding boxes", where)
            rects.append(rect(label, min(xs), min(ys), max(xs), max(ys), size, where))
        else:
            raise InterchangeError(f"{where}: a <{child.tag}> is not a box or a polygon")
        check_count(rects, "boxes")
    return Segmentation(*size, tuple(rects)), names[k]


def _points(text: str | None, where: str) -> tuple[list[float], list[float]]:
    pairs = [p.split(",") for p in (text or "").split(";") if p.strip()]
    if len(pairs) < 3 or any(len(p) != 2 for p in pairs):
        raise InterchangeError(f"{where} must be at least 3 points 'x0,y0;x1,y1;…', got {(text or '')[:40]!r}")
    return [number(x, where) for x, _ in pairs], [number(y, where) for _, y in pairs]


def _write_coco(seg: Segmentation, image: str) -> bytes:
    annotations = []
    for i, r in enumerate(seg.rects):
        w, h = r.x1 - r.x0, r.y1 - r.y0
        annotations.append({"id": i + 1, "image_id": 1, "category_id": r.label + 1, "bbox": [r.x0, r.y0, w, h],
                            "area": w * h, "iscrowd": 0,
                            "segmentation": [[r.x0, r.y0, r.x1, r.y0, r.x1, r.y1, r.x0, r.y1]]})
    doc = {"info": {"description": "FaçAID segmentation", "version": "1.0"}, "licenses": [],
           "images": [{"id": 1, "width": seg.width, "height": seg.height, "file_name": image}],
           "annotations": annotations,
           "categories": [{"id": i + 1, "name": name, "supercategory": "building"} for i, name in enumerate(LABELS)]}
    return json.dumps(doc, ensure_ascii=False).encode()


def _write_labelme(seg: Segmentation, image: str) -> bytes:
    shapes = [{"label": LABELS[r.label], "points": [[float(r.x0), float(r.y0)], [float(r.x1), float(r.y1)]],
               "group_id": None, "description": "", "shape_type": "rectangle", "flags": {}} for r in seg.rects]
    doc = {"version": LABELME_VERSION, "flags": {}, "shapes": shapes, "imagePath": image, "imageData": None,
           "imageHeight": seg.height, "imageWidth": seg.width}
    return json.dumps(doc, ensure_ascii=False, indent=2).encode()  # as labelme writes it


def _write_cvat(seg: Segmentation, image: str) -> bytes:
    root = ET.Element("annotations")
    ET.SubElement(root, "version").text = "1.1"
    task = ET.SubElement(ET.SubElement(root, "meta"), "task")
    for tag, text in (("name", "FaçAID segmentation"), ("size", "1"), ("mode", "annotation")):
        ET.SubElement(task, tag).text = text
    labels = ET.SubElement(task, "labels")
    for name in LABELS:
        label = ET.SubElement(labels, "label")
        ET.SubElement(label, "name").text = name
        ET.SubElement(label, "type").text = "bbox"
        ET.SubElement(label, "attributes")
    el = ET.SubElement(root, "image", id="0", name=image, width=str(seg.width), height=str(seg.height))
    for r in seg.rects:
        ET.SubElement(el, "box", label=LABELS[r.label], source="manual", occluded="0",
                      xtl=f"{r.x0:.2f}", ytl=f"{r.y0:.2f}", xbr=f"{r.x1:.2f}", ybr=f"{r.y1:.2f}",
                      z_order=str(PRIORITY[r.label]))
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True) + b"\n"


_READERS = {"coco": _read_coco, "labelme": _read_labelme, "cvat": _read_cvat}
_WRITERS = {"coco": _write_coco, "labelme": _write_labelme, "cvat": _write_cvat}
