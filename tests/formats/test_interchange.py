"""COCO, LabelMe and CVAT for images: files made by hand to the published formats read as expected, every
segmentation survives writing and reading back, pycocotools reads what we write, and bad or hostile input is an
`InterchangeError` naming the field, never anything else (fuzzed in `test_interchange_fuzz.py`)."""

import json
import string
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from format_helpers import coco, labelme, rect
from hypothesis import given
from hypothesis import strategies as st

from facaid.cli import main
from facaid.formats import interchange
from facaid.formats.annotation import as_annotated
from facaid.formats.interchange import FORMATS, InterchangeError, format_for_name, load, read, write
from facaid.generator import generate
from facaid.grammar import to_segmentation
from facaid.labels import LABEL_ID, LABELS
from facaid.segmentation import Rect, Segmentation

DATA = Path(__file__).parent / "data"


def test_labelme_file_reads_corners_in_any_order_polygons_as_boxes_and_clips():
    loaded = load((DATA / "facade.labelme.json").read_bytes())
    assert loaded.format == "labelme" and loaded.image == "../photos/facade-0001.jpg"
    assert loaded.segmentation == Segmentation(120, 90, (
        rect("facade", 0, 0, 120, 90),
        rect("window", 10, 21, 30, 40),  # 40.5 rounds to 40: halves to even, as the contract's parser rounds
        rect("window", 50, 20, 70, 40),
        rect("door", 52, 60, 68, 90),  # the polygon's bounding box
        rect("balcony", 95, 35, 120, 45),  # clipped to the image
    ))
    assert loaded.warnings == ("polygons read as their bounding boxes: shapes[3]",)


def test_cvat_file_of_two_images_needs_one_named():
    data = (DATA / "facades.cvat.xml").read_bytes()
    with pytest.raises(InterchangeError, match=r"2 images \(street/IMG_0001.jpg, street/IMG_0002.jpg\)"):
        read(data)
    first = read(data, image="street/IMG_0001.jpg")
    assert first == Segmentation(200, 150, (rect("facade", 0, 0, 200, 150), rect("window", 20, 30, 41, 60)))
    loaded = load(data, "cvat", image="IMG_0002.jpg")  # the name without its folder, where that is unique
    assert loaded.image == "street/IMG_0002.jpg"
    assert loaded.segmentation == Segmentation(160, 120, (
        rect("facade", 0, 0, 160, 120), rect("window", 10, 10, 30, 40), rect("shop", 5, 80, 150, 120)))
    assert loaded.warnings == ("polygons read as their bounding boxes: image[1].polygon[0]",
                               "image tags (<tag>) skipped: image[1].tag[0]")
    with pytest.raises(InterchangeError, match="no image named 'IMG_0003.jpg'; the file holds street/IMG_0001"):
        read(data, image="IMG_0003.jpg")


def test_a_size_picks_the_only_image_of_that_size():
    cvat, coco = (DATA / "facades.cvat.xml").read_bytes(), (DATA / "facades.coco.json").read_bytes()
    assert load(cvat, size=(160, 120)).image == "street/IMG_0002.jpg"
    assert load(coco, size=(100, 80)).image == "facades/rue-12.jpg"
    with pytest.raises(InterchangeError, match="holds 2 images"):
        read(coco, size=(10, 10))
    doubled = json.loads(coco)
    doubled["images"][1].update(width=100, height=80)
    with pytest.raises(InterchangeError, match="holds 2 images"):
        read(json.dumps(doubled), size=(100, 80))
    assert load(doubled, size=(100, 80), image="rue-14.jpg").image == "facades/rue-14.jpg"  # a name comes first


def test_coco_file_reads_the_named_image_with_its_categories():
    data = (DATA / "facades.coco.json").read_text()
    with pytest.raises(InterchangeError, match="facades/rue-12.jpg, facades/rue-14.jpg"):
        read(data)
    assert read(data, image="rue-12.jpg") == Segmentation(100, 80, (
        rect("facade", 0, 0, 100, 80), rect("window", 10, 11, 26, 30), rect("balcony", 40, 50, 90, 58)))
    assert read(data, "coco", image="18") == Segmentation(64, 48, (rect("window", 5, 5, 15, 20),))  # by id


@pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")  # pycocotools' own, on numpy 2
def test_pycocotools_reads_our_export_one_annotation_per_rectangle(tmp_path):
    from pycocotools.coco import COCO

    seg = generate(3).segmentation
    path = tmp_path / "facade.coco.json"
    path.write_bytes(write(seg, "coco", image="facade-3.png"))
    coco = COCO(str(path))
    (image,) = coco.loadImgs(coco.getImgIds())
    assert (image["width"], image["height"], image["file_name"]) == (seg.width, seg.height, "facade-3.png")
    (window,) = coco.getCatIds(catNms=["window"])
    windows = coco.loadAnns(coco.getAnnIds(imgIds=[image["id"]], catIds=[window]))
    drawn = [r for r in seg.rects if LABELS[r.label] == "window"]
    assert len(windows) == len(drawn) > 10
    assert [a["bbox"] for a in windows] == [[r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0] for r in drawn]
    anns = coco.loadAnns(coco.getAnnIds(imgIds=[image["id"]]))
    assert len(anns) == len(seg.rects)
    for a, r in zip(anns, seg.rects, strict=True):  # the polygon it rasterizes covers exactly the box
        mask = coco.annToMask(a)
        assert mask.sum() == a["area"] == mask[r.y0 : r.y1, r.x0 : r.x1].sum() == r.area
        assert coco.loadCats(a["category_id"])[0]["name"] == LABELS[r.label]


def test_written_files_follow_the_formats():
    seg = Segmentation(40, 30, (rect("facade", 0, 0, 40, 30), rect("window", 5, 6, 15, 20)))
    labelme = json.loads(write(seg, "labelme"))
    assert set(labelme) == {"version", "flags", "shapes", "imagePath", "imageData", "imageHeight", "imageWidth"}
    assert (labelme["imageWidth"], labelme["imageHeight"], labelme["imageData"]) == (40, 30, None)
    assert labelme["shapes"][1] == {"label": "window", "points": [[5.0, 6.0], [15.0, 20.0]], "group_id": None,
                                    "description": "", "shape_type": "rectangle", "flags": {}}
    root = ET.fromstring(write(seg, "cvat", image="a.png"))
    assert root.findtext("version") == "1.1"
    assert [n.text for n in root.iterfind("meta/task/labels/label/name")] == list(LABELS)
    (image,) = root.iterfind("image")
    assert image.attrib == {"id": "0", "name": "a.png", "width": "40", "height": "30"}
    facade, window = image.iterfind("box")
    assert window.attrib == {"label": "window", "source": "manual", "occluded": "0", "xtl": "5.00", "ytl": "6.00",
                             "xbr": "15.00", "ybr": "20.00", "z_order": "5"}
    assert int(facade.get("z_order")) < int(window.get("z_order"))  # drawn as flattening paints them
    coco = json.loads(write(seg, "coco"))
    assert coco["annotations"][1] == {"id": 2, "image_id": 1, "category_id": LABEL_ID["window"] + 1,
                                      "bbox": [5, 6, 10, 14], "area": 140, "iscrowd": 0,
                                      "segmentation": [[5, 6, 15, 6, 15, 20, 5, 20]]}


def segmentations():
    @st.composite
    def build(draw):
        w, h = draw(st.integers(1, 300)), draw(st.integers(1, 300))
        rects = []
        for _ in range(draw(st.integers(0, 12))):
            x0, y0 = draw(st.integers(0, w - 1)), draw(st.integers(0, h - 1))
            rects.append(Rect(draw(st.integers(0, len(LABELS) - 1)), x0, y0, draw(st.integers(x0 + 1, w)),
                              draw(st.integers(y0 + 1, h))))
        return Segmentation(w, h, tuple(rects))

    return build()


@given(segmentations(), st.sampled_from(FORMATS), st.text(string.ascii_letters + "äé/ _-.&<>\"'", min_size=1,
                                                          max_size=20))
def test_write_then_read_gives_the_same_segmentation(seg, fmt, name):
    data = write(seg, fmt, image=name)
    loaded = load(data)
    assert (loaded.format, loaded.segmentation, loaded.warnings) == (fmt, seg, ())
    assert loaded.image == (None if fmt == "segmentation" else name)


@given(st.floats(0, 50, allow_nan=False), st.floats(0, 50, allow_nan=False), st.floats(1.5, 40), st.floats(1.5, 40))
def test_each_edge_is_rounded_to_the_nearest_pixel(x, y, w, h):
    doc = {"images": [{"id": 1, "width": 100, "height": 100, "file_name": "f.jpg"}],
           "categories": [{"id": 1, "name": "window"}],
           "annotations": [{"id": 1, "image_id": 1, "category_id": 1, "bbox": [x, y, w, h]}]}
    x0, y0, x1, y1 = round(x), round(y), round(x + w), round(y + h)
    expected = Segmentation(100, 100, (Rect(LABEL_ID["window"], x0, y0, x1, y1),))
    if x0 < x1 and y0 < y1:
        assert read(json.dumps(doc)) == expected
    else:
        with pytest.raises(InterchangeError, match="annotations.0..bbox is empty"):
            read(json.dumps(doc))


@pytest.mark.parametrize("name, label", [("Window", "window"), ("WINDOWS", "window"), ("balconies", "balcony"),
                                         ("Mouldings", "molding"), (" door ", "door"), ("Decoration", "deco"),
                                         ("shop_", "shop"), ("Cornices", "cornice")])
def test_label_aliases(name, label):
    doc = {"version": "5.4.1", "shapes": [{"label": name, "points": [[0, 0], [2, 2]], "shape_type": "rectangle"}],
           "imageWidth": 4, "imageHeight": 4}
    assert read(json.dumps(doc)).rects == (rect(label, 0, 0, 2, 2),)


CVAT = (DATA / "facades.cvat.xml").read_text()


BAD = [  # (file, what the message says[, the image to read, where the file has several])
    (labelme(imageWidth=None), "imageWidth is missing: the image's size is needed"),
    (labelme(imageHeight=12.5), "imageHeight must be a whole number of pixels"),
    (labelme(shape1_label="spaceship"), r"shapes\[1\].label 'spaceship' is not one of the 12 labels: background, "
                                        "facade, window"),
    (labelme(shape1_shape_type="circle"), r"shapes\[1\].shape_type 'circle' is not a rectangle or a polygon"),
    (labelme(shape1_points=[[1, 1]]), r"shapes\[1\].points: a rectangle has 2 corners, got 1"),
    (labelme(shape1_points=[[1, "a"], [3, 4]]), r"shapes\[1\].points\[0\] must be a number"),
    (labelme(shape1_points=[[130, 1], [140, 9]]), r"shapes\[1\] is empty once rounded to whole pixels and clipped "
                                                  "to the 120x90 image"),
    (labelme(shape1_points=[[5.2, 1], [5.4, 9]]), r"shapes\[1\] is empty"),
    (labelme(shapes={}), "shapes must be a list"),
    (coco(annotations_bbox=[10, 10, 0.3, 5]), r"annotations\[1\].bbox is empty"),
    (coco(annotations_bbox=[10, 10, 5]), r"annotations\[1\].bbox must be \[x, y, width, height\]"),
    (coco(annotations_bbox=[10, 10, -5, 5]), r"annotations\[1\].bbox has a negative width"),
    (coco(annotations_bbox=None), r"annotations\[1\].bbox must be a list"),
    (coco(annotations_category_id=1), r"categories\[0\].name \(of annotations\[1\]\) 'person' is not one of the "
                                      "12 labels"),
    (coco(annotations_category_id=99), r"annotations\[1\].category_id 99 is not the id of one of the categories"),
    (coco(images_width=None), r"images\[0\].width is missing"),
    (coco(images_height=0), r"images\[0\].height must be a whole number of pixels from 1 to 16384"),
    (coco(images_width=20000, images_height=20000), r"images\[0\].width must be a whole number"),
    (coco(images=[]), "images: the file holds no image"),
    (coco(categories=None), "categories must be a list"),
    (CVAT.replace('xtl="20.40"', 'xtl="twenty"'), r"image\[0\].box\[1\].xtl must be a number, got 'twenty'"),
    (CVAT.replace('xbr="40.60"', 'xbr="inf"'), r"image\[0\].box\[1\].xbr must be a finite number"),
    (CVAT.replace(' width="200"', ""), r"image\[0\].width is missing"),
    (CVAT.replace('label="window" source="manual"', 'label="car" source="manual"'),
     r"image\[0\].box\[1\].label 'car' is not one of the 12 labels"),
    (CVAT.replace("<polygon", "<polyline").replace("</polygon>", "</polyline>"),
     r"image\[1\].polyline\[0\]: a <polyline> is not a box or a polygon", "IMG_0002.jpg"),
    (CVAT.replace('points="5.20,80.00;150.00,80.40;', 'points="'),
     r"image\[1\].polygon\[0\].points must be at least 3 points", "IMG_0002.jpg"),
    ('<annotations><version>1.1</version><track id="0" label="car"/></annotations>', "CVAT for video"),
    ("<svg/>", "the XML's root is <svg>, not CVAT's <annotations>"),
    ("<annotations><image", "malformed or unsafe XML"),
    ('{"images": 5', "malformed JSON at line 1, column 13: Expecting ',' delimiter"),
    ("width: 5", "neither JSON nor XML"),
    (b"\xff\xd8\xff\xe0\x00\x10JFIF", "this is a JPEG image, not annotations: annotations are our segmentation"),
    (b"RIFF\x00\x00\x00\x00WEBPVP8 ", "this is a WebP image, not annotations"),
    ("\ufffdPNG\r\n\x1a\n\x00", "this is a binary file, not annotations"),  # a PNG read as text
    ("[1, 2]", "the JSON is a list"),
    ('{"width": 10}', "its keys are 'width'"),
    ('{"width": 10, "height": 10, "rects": [{"label": "window"}]}', r"rects\[0\] is missing 'x0'"),
    (b"\xff\xfeA", "not a UTF-8 text file"),
    ("[" * 100_000, "nested too deeply"),
]


@pytest.mark.parametrize("data, message, image", [(*case, None)[:3] for case in BAD])
def test_bad_files_are_errors_naming_the_field(data, message, image):
    with pytest.raises(InterchangeError, match=message):
        load(data, image=image or ("street/IMG_0001.jpg" if str(data).startswith("<?xml") else None))


def test_format_told_must_match_the_content():
    with pytest.raises(InterchangeError, match="the file is not coco: it reads as labelme"):
        read(labelme(), "coco")
    with pytest.raises(InterchangeError, match="format 'yolo' is not one of segmentation, coco, labelme, cvat"):
        read(labelme(), "yolo")
    with pytest.raises(InterchangeError, match="format 'yolo'"):
        write(Segmentation(1, 1, ()), "yolo")


BOMB = """<?xml version="1.0"?>
<!DOCTYPE annotations [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">
<!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;"><!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;">]>
<annotations><image name="&d;" width="10" height="10"/></annotations>"""
EXTERNAL = """<?xml version="1.0"?>
<!DOCTYPE annotations [<!ENTITY secret SYSTEM "file:///etc/passwd">]>
<annotations><image name="&secret;" width="10" height="10"/></annotations>"""


@pytest.mark.parametrize("xml", [BOMB, EXTERNAL])
def test_xml_entities_are_refused(xml):
    with pytest.raises(InterchangeError, match="malformed or unsafe XML: DTD"):
        read(xml)


@pytest.mark.parametrize("name, fmt", [("a.coco.json", "coco"), ("A.LABELME.JSON", "labelme"),
                                       ("x/b.cvat.xml", "cvat"), ("b.xml", "cvat"), ("seg.json", "segmentation"),
                                       ("seg.png", None), ("coco", None)])
def test_format_for_name(name, fmt):
    assert format_for_name(name) == fmt


def test_decoded_json_and_other_values():
    doc = json.loads((DATA / "facade.labelme.json").read_text())
    assert read(doc) == read(json.dumps(doc)) and interchange.detect(doc) == "labelme"
    with pytest.raises(InterchangeError, match="give the file's bytes, text or JSON object, not list"):
        read([{"width": 1}])
    assert interchange.detect(write(Segmentation(3, 3, ()), "cvat")) == "cvat"


# --- the command line ----------------------------------------------------------------------------------------------

def test_cli_converts_by_the_output_name_or_to(tmp_path, capsys):
    src = DATA / "facade.labelme.json"
    assert main(["convert", str(src), "--out", str(tmp_path / "f.cvat.xml")]) == 0
    out, err = capsys.readouterr()
    assert "wrote" in out and "(cvat, 120x90, 5 rectangles, read as labelme)" in out
    assert err == "warning: polygons read as their bounding boxes: shapes[3]\n"
    assert load((tmp_path / "f.cvat.xml").read_bytes()).image == "../photos/facade-0001.jpg"  # the name carried
    assert read((tmp_path / "f.cvat.xml").read_bytes()) == read(src.read_bytes())
    assert main(["convert", str(tmp_path / "f.cvat.xml"), "--out", str(tmp_path / "f.txt"), "--to", "coco"]) == 0
    assert interchange.detect((tmp_path / "f.txt").read_bytes()) == "coco"
    assert main(["convert", str(tmp_path / "f.txt"), "--out", str(tmp_path / "plain" / "f.json")]) == 0
    assert Segmentation.from_json((tmp_path / "plain" / "f.json").read_text()) == read(src.read_bytes())


def test_cli_converts_a_procedure_and_names_the_image(tmp_path):
    sample = generate(5)
    (tmp_path / "p.json").write_text(sample.procedure.to_json())
    assert main(["convert", str(tmp_path / "p.json"), "--out", str(tmp_path / "p.labelme.json"),
                 "--image", "rue-5.jpg"]) == 0
    loaded = load((tmp_path / "p.labelme.json").read_bytes())
    # an annotation tool's file holds its elements one box each (`facaid.formats.annotation`); our JSON the exact pieces
    assert (loaded.segmentation, loaded.image) == (as_annotated(to_segmentation(sample.procedure)), "rue-5.jpg")
    assert main(["convert", str(tmp_path / "p.json"), "--out", str(tmp_path / "p.seg.json"), "--to",
                 "segmentation"]) == 0
    assert load((tmp_path / "p.seg.json").read_bytes()).segmentation == to_segmentation(sample.procedure)


@pytest.mark.parametrize("args, message", [
    ([str(DATA / "facades.cvat.xml"), "--out", "x.coco.json"],
     "the file holds 2 images (street/IMG_0001.jpg, street/IMG_0002.jpg): name the one to read with --image NAME"),
    ([str(DATA / "facades.cvat.xml"), "--out", "x.coco.json", "--image", "IMG_9.jpg"], "no image named 'IMG_9.jpg'"),
    ([str(DATA / "facade.labelme.json"), "--out", "x.yaml"], "say the format of x.yaml with --to"),
    (["missing.json", "--out", "x.json"], "cannot read missing.json"),
    ([str(DATA / "facades.coco.json"), "--out", "x.json", "--image", "rue-12.jpg", "--to", "cvat"], None),
])
def test_cli_errors_end_with_status_2(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    if message is None:  # the good case among them: written where it was asked
        assert main(["convert", *args]) == 0 and interchange.detect((tmp_path / "x.json").read_bytes()) == "cvat"
        return
    assert main(["convert", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and message in err, err
    assert not list(tmp_path.iterdir())  # nothing written


def test_cli_bad_file_names_the_field(tmp_path, capsys):
    (tmp_path / "bad.json").write_text(labelme(shape1_label="spaceship"))
    assert main(["convert", str(tmp_path / "bad.json"), "--out", str(tmp_path / "x.coco.json")]) == 2
    assert "error: shapes[1].label 'spaceship' is not one of the 12 labels" in capsys.readouterr().err
