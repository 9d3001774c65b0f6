"""COCO, LabelMe and CVAT on the site: saved as a photo's segmentation (API and page), downloaded from a photo and a
procedure, converted for the editor; bad files are 400s naming the problem and store nothing."""

import json
from pathlib import Path

import pytest

from facaid.formats import interchange
from facaid.formats.annotation import as_annotated
from facaid.generator import generate
from facaid.grammar import to_segmentation
from facaid.segmentation import Segmentation

pytestmark = pytest.mark.django_db

DATA = Path(__file__).resolve().parents[1] / "formats" / "data"


def seg_url(photo):
    return f"/api/v1/photos/{photo['code']}/segmentations/"


def file_url(photo, **params):
    query = "&".join(f"{k}={v}" for k, v in params.items())
    return f"/api/v1/photos/{photo['code']}/segmentation" + (f"?{query}" if query else "")


def stored(as_alice, photo):
    return as_alice.get(seg_url(photo)).json()["count"]


@pytest.mark.parametrize("fmt", ["coco", "labelme", "cvat"])
def test_a_segmentation_saved_in_each_format_is_the_same(facade_photo, as_alice, fmt):
    photo, first = facade_photo
    seg = Segmentation.from_dict(first["data"])
    body = interchange.write(seg, fmt, image="facade.png")
    if fmt == "cvat":
        r = as_alice.post(seg_url(photo), body, content_type="application/xml")
    else:
        r = as_alice.post(seg_url(photo), json.loads(body), format="json")
    assert r.status_code == 201, r.content
    assert r.json()["version"] == 2 and r.json()["warnings"] == []
    assert Segmentation.from_dict(r.json()["data"]) == seg


def test_polygons_are_saved_as_boxes_with_a_warning(facade_photo, as_alice):
    photo, _ = facade_photo
    doc = json.loads((DATA / "facade.labelme.json").read_text())
    doc.update(imageWidth=photo["width"], imageHeight=photo["height"])
    r = as_alice.post(seg_url(photo), doc, format="json")
    assert r.status_code == 201, r.content
    assert r.json()["warnings"] == ["polygons read as their bounding boxes: shapes[3]"]
    assert r.json()["rect_count"] == 5


def _two_images(photo, second_size):
    """A CVAT file of two images: the photo's own size first, ``second_size`` next."""
    text = (DATA / "facades.cvat.xml").read_text()
    return (text.replace('width="200" height="150"', f'width="{photo["width"]}" height="{photo["height"]}"')
            .replace('width="160" height="120"', 'width="{}" height="{}"'.format(*second_size)))


def test_a_file_of_several_images_gives_the_photos_or_the_one_named(facade_photo, as_alice):
    photo, _ = facade_photo
    r = as_alice.post(seg_url(photo), _two_images(photo, (160, 120)), content_type="text/xml")
    assert r.status_code == 201 and r.json()["rect_count"] == 2, r.content  # the only one of the photo's size
    same = _two_images(photo, (photo["width"], photo["height"]))
    r = as_alice.post(seg_url(photo), same, content_type="application/xml")
    assert r.status_code == 400 and "2 images (street/IMG_0001.jpg, street/IMG_0002.jpg)" in r.json()["image"]
    r = as_alice.post(seg_url(photo) + "?image=IMG_0002.jpg", same, content_type="application/xml")
    assert r.status_code == 201 and r.json()["rect_count"] == 3
    assert r.json()["warnings"] == ["polygons read as their bounding boxes: image[1].polygon[0]",
                                    "image tags (<tag>) skipped: image[1].tag[0]"]


BOMB = ('<?xml version="1.0"?><!DOCTYPE a [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">]>'
        '<annotations><image name="&b;" width="10" height="10"/></annotations>')


def _labelme(photo, **shape):
    return {"version": "5.4.1", "imageWidth": photo["width"], "imageHeight": photo["height"],
            "shapes": [{"label": "window", "points": [[1, 1], [9, 9]], "shape_type": "rectangle", **shape}]}


@pytest.mark.parametrize("make, query, field, message", [
    (lambda p: _labelme(p, label="spaceship"), "", "segmentation", "shapes[0].label 'spaceship' is not one of"),
    (lambda p: _labelme(p, shape_type="circle"), "", "segmentation", "'circle' is not a rectangle or a polygon"),
    (lambda p: {**_labelme(p), "imageWidth": None}, "", "segmentation", "imageWidth is missing"),
    (lambda p: {**_labelme(p), "imageWidth": p["width"] + 1}, "", "segmentation", "but the photo is"),
    (lambda p: _labelme(p), "?format=coco", "segmentation", "the file is not coco: it reads as labelme"),
    (lambda p: _labelme(p), "?format=yolo", "format", "give one of segmentation, coco, labelme, cvat"),
    (lambda p: {"images": [{"id": 1, "width": p["width"], "height": p["height"]}], "categories": [],
                "annotations": [{"image_id": 1, "category_id": 3, "bbox": [0, 0, 5, 5]}]}, "", "segmentation",
     "annotations[0].category_id 3 is not the id of one of the categories"),
    (lambda p: BOMB, "", "segmentation", "malformed or unsafe XML"),
    (lambda p: "<annotations><image", "", "segmentation", "malformed or unsafe XML"),
    (lambda p: "<svg/>", "", "segmentation", "not CVAT's <annotations>"),
])
def test_bad_files_are_400_naming_the_problem(facade_photo, as_alice, make, query, field, message):
    photo, _ = facade_photo
    body = make(photo)
    if isinstance(body, str):
        r = as_alice.post(seg_url(photo) + query, body, content_type="application/xml")
    else:
        r = as_alice.post(seg_url(photo) + query, body, format="json")
    assert r.status_code == 400, r.content
    assert message in r.json()[field], r.json()
    assert stored(as_alice, photo) == 1


def test_only_the_owner_saves_in_other_formats(facade_photo, as_alice, as_bob, as_charlie):
    photo, first = facade_photo
    body = interchange.write(Segmentation.from_dict(first["data"]), "cvat")
    assert as_bob.post(seg_url(photo), body, content_type="application/xml").status_code == 404
    assert as_charlie.post(seg_url(photo), body, content_type="application/xml").status_code in (401, 403)
    assert stored(as_alice, photo) == 1


@pytest.mark.parametrize("fmt, content_type, suffix", [
    ("coco", "application/json", ".coco.json"), ("labelme", "application/json", ".labelme.json"),
    ("cvat", "application/xml", ".cvat.xml"), ("segmentation", "application/json", ".json")])
def test_the_photos_segmentation_downloads_in_each_format(facade_photo, as_alice, fmt, content_type, suffix):
    photo, first = facade_photo
    r = as_alice.get(file_url(photo, format=fmt))
    assert r.status_code == 200 and r["Content-Type"] == content_type
    assert r["Content-Disposition"] == f'attachment; filename="facaid-photo-{photo["code"][:8]}-v1{suffix}"'
    loaded = interchange.load(r.content)
    assert loaded.format == fmt and loaded.segmentation == Segmentation.from_dict(first["data"])
    if fmt != "segmentation":
        assert loaded.image == "Generated facade.png"  # the photo it was drawn on, by its title


def test_segmentation_download_versions_and_access(facade_photo, as_alice, as_bob, as_charlie):
    photo, first = facade_photo
    newer = {"width": photo["width"], "height": photo["height"],
             "rects": [{"label": "door", "x0": 1, "y0": 2, "x1": 5, "y1": 9}]}
    assert as_alice.post(seg_url(photo), newer, format="json").status_code == 201
    assert interchange.read(as_alice.get(file_url(photo, format="coco")).content).rects[0].x1 == 5  # the latest
    old = as_alice.get(file_url(photo, format="cvat", version=1))
    assert interchange.read(old.content) == Segmentation.from_dict(first["data"])
    assert as_alice.get(file_url(photo)).json() == newer  # our JSON by default
    assert as_alice.get(file_url(photo, version=7)).status_code == 404
    for bad in ("first", "²", "-1"):
        r = as_alice.get(file_url(photo, version=bad))
        assert r.status_code == 400 and "version" in r.json(), bad
    r = as_alice.get(file_url(photo, format="yolo"))
    assert r.status_code == 400 and "coco" in r.json()["format"]
    assert as_bob.get(file_url(photo, format="coco")).status_code == 404  # private
    assert as_charlie.get(file_url(photo, format="coco")).status_code == 404
    assert as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"visibility": "public"},
                          format="json").status_code == 200
    assert as_charlie.get(file_url(photo, format="labelme")).status_code == 200


def test_a_photo_without_segmentation_has_none_to_download(as_alice):
    from site_helpers import image_bytes, upload

    photo = upload(as_alice, image_bytes()).json()
    r = as_alice.get(file_url(photo, format="coco"))
    assert r.status_code == 404 and "no segmentation yet" in r.json()["detail"]


def test_a_procedures_rectangles_download_in_each_format(as_alice, alice):
    from webapp.facades.models import Procedure

    sample = generate(3)
    proc = Procedure.objects.create(owner=alice, data=sample.procedure.to_dict())
    for name in ("segmentation.coco.json", "segmentation.labelme.json", "segmentation.cvat.xml"):
        r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/{name}")
        assert r.status_code == 200, name
        loaded = interchange.load(r.content)
        assert loaded.segmentation == as_annotated(to_segmentation(sample.procedure))  # one box per element
        assert loaded.image == f"facaid-{str(proc.code)[:8]}-labels.png"


def test_a_procedures_annotations_name_its_photo_and_only_to_who_may_see_it(facade_photo, alice, as_alice,
                                                                           as_charlie):
    """Issue 67: COCO's file_name, LabelMe's imagePath and CVAT's image name are the photo the procedure was drawn
    on, by its title (made a file name), not labels.png; to a viewer who may not see the photo, a neutral name."""
    from webapp.facades.models import Photo, Procedure

    photo, _ = facade_photo
    stored = Photo.objects.get(code=photo["code"])
    stored.title = "Rue de Rivoli 12 / east: side*"
    stored.save()
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), photo=stored,
                                    visibility="public")  # facade_png draws seed 3: the photo's size
    for client, name in ((as_alice, "Rue de Rivoli 12 - east- side.png"),
                         (as_charlie, f"facaid-{str(proc.code)[:8]}-photo.png")):
        for download in ("segmentation.coco.json", "segmentation.labelme.json", "segmentation.cvat.xml"):
            r = client.get(f"/api/v1/procedures/{proc.code}/download/{download}")
            assert r.status_code == 200 and interchange.load(r.content).image == name, (download, name)
            assert "Rivoli" not in r.content.decode() or client is as_alice
    stored.title = ""
    stored.save()
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/segmentation.coco.json")
    assert interchange.load(r.content).image == f"facaid-photo-{photo['code'][:8]}.png"  # untitled: the site's name
    proc.data = generate(4).procedure.to_dict()  # another size than the photo's: the label map beside it
    proc.save()
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/segmentation.labelme.json")
    assert interchange.load(r.content).image == f"facaid-{str(proc.code)[:8]}-labels.png"


def test_convert_reads_other_tools_files_for_the_editor(as_charlie):
    text = (DATA / "facades.cvat.xml").read_text()
    r = as_charlie.post("/api/v1/convert", {"text": text, "width": 160, "height": 120}, format="json")
    assert r.status_code == 200, r.content
    body = r.json()
    assert (body["format"], body["image"]) == ("cvat", "street/IMG_0002.jpg")
    assert Segmentation.from_dict(body["segmentation"]) == interchange.read(text, image="IMG_0002.jpg")
    assert len(body["warnings"]) == 2
    r = as_charlie.post("/api/v1/convert", {"text": text, "image": "street/IMG_0001.jpg"}, format="json")
    assert r.json()["segmentation"]["width"] == 200
    ours = {"width": 3, "height": 2, "rects": [{"label": "window", "x0": 0, "y0": 0, "x1": 1, "y1": 1}]}
    r = as_charlie.post("/api/v1/convert", {"text": json.dumps(ours)}, format="json")
    assert r.json() == {"segmentation": ours, "format": "segmentation", "image": None, "warnings": []}
    for bad, field, message in (
        ({"text": text}, "image", "the file holds 2 images"),
        ({"text": text, "image": "nope.jpg"}, "text", "no image named 'nope.jpg'"),
        ({"text": "{}"}, "text", "not a segmentation ('rects'), COCO"),
        ({"text": json.dumps(ours), "format": "coco"}, "text", "the file is not coco"),
        ({"text": text, "format": "yolo"}, "format", "yolo"),
        ({"text": 5}, "text", "Not text"),
        ({}, "text", "required"),
        ({"text": text, "width": 0, "height": 10}, "width", "greater than or equal to 1"),
    ):
        r = as_charlie.post("/api/v1/convert", bad, format="json")
        assert r.status_code == 400 and message in json.dumps(r.json()[field]), (bad.keys(), r.content)


def test_the_photo_page_saves_other_tools_files_with_their_warnings(facade_photo, as_alice):
    photo, _ = facade_photo
    page = as_alice.get(f"/photos/{photo['code']}").content.decode()
    assert f"/api/v1/photos/{photo['code']}/segmentation?format=coco&amp;version=1" in page
    r = as_alice.post(f"/photos/{photo['code']}/segmentation", {"text": _two_images(photo, (160, 120))}, follow=True)
    text = r.content.decode()
    assert "Segmentation version 2 saved (2 rectangles)." in text
    doc = json.loads((DATA / "facade.labelme.json").read_text())
    doc.update(imageWidth=photo["width"], imageHeight=photo["height"])
    r = as_alice.post(f"/photos/{photo['code']}/segmentation", {"text": json.dumps(doc)}, follow=True)
    text = r.content.decode()
    assert "Segmentation version 3 saved (5 rectangles)." in text
    assert "Read with a change: polygons read as their bounding boxes: shapes[3]." in text
    r = as_alice.post(f"/photos/{photo['code']}/segmentation", {"text": BOMB}, follow=True)
    assert "malformed or unsafe XML" in r.content.decode()
    assert stored(as_alice, photo) == 3
