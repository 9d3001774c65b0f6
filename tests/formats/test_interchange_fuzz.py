"""The interchange formats fuzzed (`facaid.formats.interchange`): garbage in, an `InterchangeError` out. JSON
documents and XML trees drawn from nothing, valid files with parts replaced by garbage, and bytes: each is read as
sound rectangles inside the image, or refused with a message, never anything else."""

import json
import string
import xml.etree.ElementTree as ET
from pathlib import Path

from format_helpers import coco, rect
from hypothesis import given
from hypothesis import strategies as st

from facaid.formats.interchange import FORMATS, InterchangeError, load
from facaid.labels import LABELS
from facaid.segmentation import Segmentation

DATA = Path(__file__).parent / "data"
CVAT = (DATA / "facades.cvat.xml").read_text()


KEYS = ["images", "annotations", "categories", "shapes", "rects", "id", "image_id", "category_id", "bbox", "name",
        "file_name", "width", "height", "label", "points", "shape_type", "imageWidth", "imageHeight", "iscrowd",
        "x0", "y0", "x1", "y1"]
TEXT = string.printable + "äé\ufeff\u2028"  # a small alphabet: hypothesis's full Unicode table is slow to build
scalars = (st.none() | st.booleans() | st.integers(-10, 10**20) | st.floats() | st.sampled_from(LABELS)
           | st.sampled_from(["rectangle", "polygon", "1", "nan"]) | st.text(TEXT, max_size=5))
values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=5)
                      | st.dictionaries(st.sampled_from(KEYS) | st.text(TEXT, max_size=3), inner, max_size=6),
                      max_leaves=20)
documents = st.dictionaries(st.sampled_from(KEYS), values, max_size=6)

TAGS = ["annotations", "image", "box", "polygon", "tag", "track", "points", "mask", "meta"]
ATTRS = ["name", "id", "width", "height", "label", "xtl", "ytl", "xbr", "ybr", "points"]
attr_values = st.sampled_from(["0", "10", "-3", "1e9", "nan", "window", "Facade", "1,2;3,4;5,6", "", "x"])


@st.composite
def xml_trees(draw, depth=0):
    el = ET.Element(draw(st.sampled_from(TAGS)) if depth else "annotations",
                    draw(st.dictionaries(st.sampled_from(ATTRS), attr_values, max_size=6)))
    if depth < 3:
        el.extend(draw(st.lists(xml_trees(depth + 1), max_size=4)))
    return el


def _paths(doc, at=()):
    yield at
    children = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for key, child in children:
        yield from _paths(child, (*at, key))


SEEDS = [json.loads((DATA / "facade.labelme.json").read_text()), json.loads(coco()),
         Segmentation(50, 40, (rect("facade", 0, 0, 50, 40), rect("window", 5, 5, 20, 20))).to_dict()]


@st.composite
def mutated_files(draw):
    """A valid file with one to three of its parts (a value, a list, an object) replaced by garbage or removed: the
    garbage reaches the checks deep inside, where a document drawn from nothing rarely gets."""
    doc = json.loads(json.dumps(draw(st.sampled_from(SEEDS))))
    for _ in range(draw(st.integers(1, 3))):
        path = draw(st.sampled_from(list(_paths(doc))[1:]))
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        if draw(st.booleans()) and isinstance(parent, dict):
            del parent[path[-1]]
        else:
            parent[path[-1]] = draw(values)
    return doc


@st.composite
def mutated_cvat(draw):
    root = ET.fromstring(CVAT)
    elements = list(root.iter())
    for _ in range(draw(st.integers(1, 3))):
        el = draw(st.sampled_from(elements))
        action = draw(st.sampled_from(["set", "drop", "child"]))
        if action == "set":
            el.set(draw(st.sampled_from(ATTRS)), draw(attr_values | st.text(TEXT, max_size=8)))
        elif action == "drop" and el.attrib:
            del el.attrib[draw(st.sampled_from(sorted(el.attrib)))]
        else:
            el.append(draw(xml_trees(1)))
    return ET.tostring(root), draw(st.sampled_from([None, "0", "1", "street/IMG_0002.jpg", "IMG_0001.jpg"]))


def _accepts_or_names_the_problem(data, fmt=None, image=None):
    try:
        loaded = load(data, fmt, image=image)
    except InterchangeError as exc:
        assert str(exc)
    else:
        seg = loaded.segmentation
        for r in seg.rects:
            assert 0 <= r.x0 < r.x1 <= seg.width and 0 <= r.y0 < r.y1 <= seg.height


@given(documents)
def test_fuzzed_json_documents(doc):
    _accepts_or_names_the_problem(json.dumps(doc))


@given(mutated_files())
def test_fuzzed_parts_of_valid_files(doc):
    _accepts_or_names_the_problem(json.dumps(doc))


@given(xml_trees())
def test_fuzzed_xml_documents(root):
    _accepts_or_names_the_problem(ET.tostring(root))


@given(mutated_cvat())
def test_fuzzed_parts_of_a_valid_cvat_file(case):
    _accepts_or_names_the_problem(*case[:1], image=case[1])


@given(st.binary(max_size=200) | st.text(TEXT, max_size=200), st.sampled_from([None, *FORMATS]))
def test_fuzzed_bytes(data, fmt):
    _accepts_or_names_the_problem(data, fmt)
