"""The JSON API: segmentations, procedures, jobs, downloads, rectification, and their bad inputs."""

import io
import json
import xml.etree.ElementTree as ET
import zipfile

import pytest
from format_helpers import window_grid
from PIL import Image
from site_helpers import image_bytes, upload

from facaid.formats.cga import procedure_cga
from facaid.formats.mesh import procedure_mesh
from facaid.generator import generate
from webapp.facades.models import Job

pytestmark = pytest.mark.django_db


def seg_url(photo):
    return f"/api/v1/photos/{photo['code']}/segmentations/"


def test_segmentation_versions(facade_photo, as_alice):
    photo, seg = facade_photo
    assert seg["version"] == 1 and seg["rect_count"] > 10
    again = as_alice.post(seg_url(photo), seg["data"], format="json").json()
    assert again["version"] == 2
    versions = as_alice.get(seg_url(photo)).json()["results"]
    assert [v["version"] for v in versions] == [2, 1]
    assert as_alice.get(f"/api/v1/photos/{photo['code']}/").json()["segmentation"] == again["code"]


@pytest.mark.parametrize("body, message", [
    ('{"width": 10, "height": ', "JSON parse error"),
    ('[1, 2, 3]', "must be a JSON object"),
    ('{"width": "wide", "height": 10, "rects": []}', "width"),
    ('{"width": NaN, "height": 10, "rects": []}', "NaN"),
    ('{"width": -5, "height": 10, "rects": []}', "width"),
    ('{"width": 1e12, "height": 10, "rects": []}', "width"),
])
def test_bad_segmentations_are_400_with_a_message(facade_photo, as_alice, body, message):
    photo, _ = facade_photo
    r = as_alice.post(seg_url(photo), body, content_type="application/json")
    assert r.status_code == 400, r.content
    assert message in json.dumps(r.json()), r.json()
    assert as_alice.get(seg_url(photo)).json()["count"] == 1  # nothing stored


def test_bad_rectangles_and_size_mismatch(facade_photo, as_alice):
    photo, seg = facade_photo
    data = json.loads(json.dumps(seg["data"]))
    data["rects"][0]["x1"] = float("nan")
    r = as_alice.post(seg_url(photo), json.dumps(data, allow_nan=True), content_type="application/json")
    assert r.status_code == 400
    data = json.loads(json.dumps(seg["data"]))
    data["rects"][0]["label"] = "spaceship"
    r = as_alice.post(seg_url(photo), data, format="json")
    assert r.status_code == 400 and "spaceship" in json.dumps(r.json())
    data = json.loads(json.dumps(seg["data"]))
    data["width"] += 10
    r = as_alice.post(seg_url(photo), data, format="json")
    assert r.status_code == 400 and "but the photo is" in json.dumps(r.json())


def test_procedure_edit_validates_and_remeasures(facade_photo, as_alice, alice):
    from webapp.facades.models import Procedure, Segmentation

    _, seg = facade_photo
    sample = generate(3)
    proc = Procedure.objects.create(owner=alice, data=sample.procedure.to_dict(),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    url = f"/api/v1/procedures/{proc.code}/"
    r = as_alice.patch(url, {"data": sample.procedure.to_dict()}, format="json")
    assert r.status_code == 200 and r.json()["accuracy"] == pytest.approx(1.0)
    bad = sample.procedure.to_dict()
    bad["root"]["rule"] = "explode"
    r = as_alice.patch(url, {"data": bad}, format="json")
    assert r.status_code == 400 and "explode" in json.dumps(r.json())
    r = as_alice.patch(url, {"visibility": "everyone"}, format="json")
    assert r.status_code == 400
    assert as_alice.patch(url, '{"title": ', content_type="application/json").status_code == 400
    for title in (5, True, ["a"], {"a": 1}, None):  # text only: no number stored as "5"
        r = as_alice.patch(url, {"title": title, "visibility": "public"}, format="json")
        assert r.status_code == 400 and "title" in r.json(), (title, r.content)
    assert as_alice.patch(url, {"title": "x" * 201}, format="json").status_code == 400
    assert Procedure.objects.get(id=proc.id).data == sample.procedure.to_dict()  # nothing lost
    assert Procedure.objects.get(id=proc.id).visibility == "private" and Procedure.objects.get(id=proc.id).title == ""
    assert as_alice.patch(url, {"title": "Rue de Rivoli 12"}, format="json").json()["title"] == "Rue de Rivoli 12"


def test_photo_titles_are_text(facade_photo, as_alice):
    photo, _ = facade_photo
    url = f"/api/v1/photos/{photo['code']}/"
    r = as_alice.patch(url, {"title": 12}, format="json")
    assert r.status_code == 400 and "Not text" in json.dumps(r.json())
    assert as_alice.get(url).json()["title"] == photo["title"]
    assert as_alice.patch(url, {"title": "Rivoli"}, format="json").json()["title"] == "Rivoli"


def test_downloads_render_and_variations(facade_photo, as_alice, alice):
    from webapp.facades.models import Photo, Procedure

    photo, _ = facade_photo
    sample = generate(3)
    proc = Procedure.objects.create(owner=alice, data=sample.procedure.to_dict(),
                                    photo=Photo.objects.get(code=photo["code"]))
    base = f"/api/v1/procedures/{proc.code}/download/"
    r = as_alice.get(base + "procedure.json")
    assert r.status_code == 200 and "attachment" in r["Content-Disposition"]
    assert json.loads(r.content)["root"] == sample.procedure.to_dict()["root"]
    seg = json.loads(as_alice.get(base + "segmentation.json").content)
    assert seg == sample.segmentation.to_dict() or (seg["width"], seg["height"]) == (photo["width"], photo["height"])
    for name in ("labels.png", "overlay.png"):
        img = Image.open(io.BytesIO(as_alice.get(base + name).getvalue()))
        assert img.size == (photo["width"], photo["height"])
    r = as_alice.get(base + "labels.svg")
    assert r["Content-Type"] == "image/svg+xml" and r["Content-Disposition"].endswith('-labels.svg"')
    svg = ET.fromstring(r.content)
    assert (svg.get("width"), svg.get("height")) == (str(photo["width"]), str(photo["height"]))
    assert r.content.count(b"<rect") == len(seg["rects"]) + 1  # every rectangle and the background
    r = as_alice.get(base + "procedure.cga")
    assert r["Content-Type"].startswith("text/plain") and r["Content-Disposition"].endswith('-procedure.cga"')
    assert r.content.decode() == procedure_cga(sample.procedure, name=f"facaid-{str(proc.code)[:8]}")
    scaled = as_alice.get(base + "procedure.cga?metres_per_pixel=0.05").content.decode()
    assert "0.05 m per pixel" in scaled
    r = as_alice.get(base + "mesh.zip?metres_per_pixel=0.02")
    assert r["Content-Type"] == "application/zip" and r["Content-Disposition"].endswith('-mesh.zip"')
    with zipfile.ZipFile(io.BytesIO(r.content)) as z:
        assert sorted(z.namelist()) == ["facade.mtl", "facade.obj"]
        assert (z.read("facade.obj").decode(), z.read("facade.mtl").decode()) == procedure_mesh(sample.procedure, 0.02)
    for bad in ("0", "-1", "nan", "abc", "1e9"):
        for name in ("procedure.cga", "mesh.zip"):
            r = as_alice.get(base + f"{name}?metres_per_pixel={bad}")
            assert r.status_code == 400 and "metres_per_pixel" in r.json(), (name, bad)
    huge = Procedure.objects.create(owner=alice, data=window_grid(200, 60).to_dict())
    r = as_alice.get(f"/api/v1/procedures/{huge.code}/download/mesh.zip")
    assert r.status_code == 400 and "24000 rectangles" in r.json()["name"]
    assert as_alice.get(base + "overlay.png?alpha=7").status_code == 400
    assert as_alice.get(base + "nothing.txt").status_code == 404
    r = as_alice.post(f"/api/v1/procedures/{proc.code}/variations", {"n": 3, "seed": 5}, format="json")
    variants = r.json()["variants"]
    assert len(variants) == 3
    assert as_alice.post(f"/api/v1/procedures/{proc.code}/variations", {"n": 3, "seed": 5},
                         format="json").json()["variants"] == variants  # deterministic
    assert as_alice.post(f"/api/v1/procedures/{proc.code}/variations", {"n": 1000}, format="json").status_code == 400
    png = as_alice.post("/api/v1/render", variants[0], format="json")
    assert png.status_code == 200 and png["Content-Type"] == "image/png"
    assert as_alice.post("/api/v1/render", {"root": 5}, format="json").status_code == 400


def test_rectify_stores_the_rectified_photo(facade_photo, as_alice):
    photo, _ = facade_photo
    url = f"/api/v1/photos/{photo['code']}/rectify"
    w, h = photo["width"], photo["height"]
    r = as_alice.post(url, {"corners": [[10, 5], [w - 10, 0], [w, h], [0, h - 4]]}, format="json")
    assert r.status_code == 200, r.content
    body = r.json()
    assert body["rectified"] and body["corners"][0] == [10, 5]
    img = Image.open(io.BytesIO(as_alice.get(body["rectified"]).getvalue()))
    assert abs(img.width - (w - 10)) <= 2 and abs(img.height - (h - 2)) <= 3
    for corners in ([[0, 0], [1, 1]], [[0, 0], [w, 0], [0, h], [w, h]], [[0, 0], [w, 0], [w, h], ["a", 1]],
                    [[0, 0], [1e9, 0], [w, h], [0, h]]):
        assert as_alice.post(url, {"corners": corners}, format="json").status_code == 400, corners


def test_job_submission_and_errors(facade_photo, as_alice, as_bob):
    _, seg = facade_photo
    r = as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": 2}, format="json")
    assert r.status_code == 202
    job = Job.objects.get(code=r.json()["code"])
    assert job.status == "queued" and job.params == {"k": 2, "seed": 0, "structure": "editable"}
    bad = as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "structure": "tidy"}, format="json")
    assert bad.status_code == 400 and "structure" in bad.json()
    assert as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": 99}, format="json").status_code == 400
    assert as_alice.post("/api/v1/jobs/", {"segmentation": "nope"}, format="json").status_code == 400
    assert as_bob.post("/api/v1/jobs/", {"segmentation": seg["code"]}, format="json").status_code == 404


def test_openapi_schema_documents_the_api(as_charlie):
    r = as_charlie.get("/api/v1/schema", HTTP_ACCEPT="application/json")
    assert r.status_code == 200
    schema = json.loads(r.content)
    for path in ("/api/v1/photos/", "/api/v1/jobs/", "/api/v1/procedures/{code}/fork", "/api/v1/gallery/"):
        assert path in schema["paths"], path


def test_photo_list_names_each_latest_segmentation_in_one_query(facade_photo, as_alice, django_assert_max_num_queries):
    photo, seg = facade_photo
    newer = as_alice.post(seg_url(photo), seg["data"], format="json").json()
    for _ in range(4):
        upload(as_alice, image_bytes())
    with django_assert_max_num_queries(6):  # session, user, count, page: not one per photo
        listed = as_alice.get("/api/v1/photos/").json()["results"]
    assert len(listed) == 5 and listed[-1]["segmentation"] == newer["code"]
    assert [p["segmentation"] for p in listed[:4]] == [None] * 4


def test_every_registered_download_is_served_as_registered(facade_photo, as_alice, alice, as_charlie):
    from webapp.facades.downloads import DOWNLOADS
    from webapp.facades.models import Photo, Procedure

    photo, _ = facade_photo
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=Photo.objects.get(code=photo["code"]))
    for name, download in DOWNLOADS.items():
        r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/{name}")
        assert r.status_code == 200 and r["Content-Type"] == download.content_type, name
        assert r["Content-Disposition"] == f'attachment; filename="facaid-{str(proc.code)[:8]}-{name}"'
        if download.needs_photo:  # the photo is alice's and private: others are told, not served
            r = as_charlie.get(f"/api/v1/procedures/{proc.code}/download/{name}")
            assert r.status_code == 400 and "has no photo you may see" in r.json()["photo"]
    page = as_charlie.get(f"/procedures/{proc.code}").content.decode()
    assert "download/overlay.png" not in page and "download/mesh.zip" in page


def _drawn_grid(width, height, missing=()):
    """A facade rectangle and a 4 x 3 grid of windows on it, but for the ``missing`` ones (indices)."""
    rects = [{"label": "facade", "x0": 0, "y0": 0, "x1": width, "y1": height}]
    pw, ph = width // 5, height // 4
    for j in range(3):
        for i in range(4):
            if 4 * j + i not in missing:
                rects.append({"label": "window", "x0": pw // 2 + i * pw, "y0": ph // 2 + j * ph,
                              "x1": pw // 2 + i * pw + pw // 2, "y1": ph // 2 + j * ph + ph // 2})
    return {"width": width, "height": height, "rects": rects}


def test_completion_proposes_what_is_not_drawn_and_refuses_bad_input(facade_photo, as_alice, as_bob):
    photo, _ = facade_photo
    url = f"/api/v1/photos/{photo['code']}/complete"
    w, h = photo["width"], photo["height"]
    full = _drawn_grid(w, h)["rects"]
    body = {**_drawn_grid(w, h, missing=(5,)), "use_photo": False}  # the photo shows another facade than drawn
    r = as_alice.post(url, body, format="json")
    assert r.status_code == 200, r.content
    (p,) = r.json()["proposals"]
    assert {k: p[k] for k in ("label", "x0", "y0", "x1", "y1")} == full[1 + 5]
    assert p["score"] >= 0.85 and p["reason"] in ("grid", "floor")
    body["rejected"] = [{k: p[k] for k in ("label", "x0", "y0", "x1", "y1")}]
    nothing = as_alice.post(url, body, format="json").json()
    rejected_box = tuple(body["rejected"][0][k] for k in ("x0", "y0", "x1", "y1"))
    assert nothing["proposals"] == [] and rejected_box not in [  # a rejected place is not even dimmed
        tuple(d[k] for k in ("x0", "y0", "x1", "y1")) for d in nothing["dimmed"]]
    assert nothing["tried"][0].startswith("windows of ") and "with a pitch" in nothing["tried"][0]  # in words
    unsure = as_alice.post(url, {**body, "rejected": [], "min_score": 0.99}, format="json").json()
    assert unsure["proposals"] == [] and unsure["dimmed"][0]["score"] == p["score"]  # under the bar: dimmed
    assert as_alice.get(seg_url(photo)).json()["count"] == 1  # nothing stored
    for bad, field, message in (
        ({**_drawn_grid(w + 10, h)}, "segmentation", "but the photo is"),
        ({**_drawn_grid(w, h), "min_score": 2}, "min_score", "in [0, 1]"),
        ({**_drawn_grid(w, h), "min_score": "high"}, "min_score", "in [0, 1]"),
        ({**_drawn_grid(w, h), "rejected": "all"}, "rejected", "list"),
        ({**_drawn_grid(w, h), "rejected": [{"label": "window", "x0": 5, "y0": 5, "x1": 2, "y1": 9}]}, "rejected",
         "rejected[0]"),
        ({**_drawn_grid(w, h), "rejected": [7]}, "rejected", "rejected[0]"),
        ({**_drawn_grid(w, h), "use_photo": "yes"}, "use_photo", "true or false"),
        ({"width": w, "height": h, "rects": [{"label": "window", "x0": 0, "y0": 0, "x1": 1, "y1": 1}] * 2001},
         "segmentation", "too many rectangles for completion"),
    ):
        r = as_alice.post(url, bad, format="json")
        assert r.status_code == 400, (bad.keys(), r.content)
        assert field in r.json() and message in json.dumps(r.json()), r.json()
    assert as_alice.post(url, {**_drawn_grid(w, h), "rejected": None}, format="json").status_code == 200
    checked = as_alice.post(url, _drawn_grid(w, h, missing=(5,)), format="json")  # the photo is read by default
    assert checked.status_code == 200 and any("photo" in p for p in checked.json()["proposals"])
    r = as_alice.post(url, [1, 2], format="json")
    assert r.status_code == 400 and "JSON object" in json.dumps(r.json())
    assert as_bob.post(url, _drawn_grid(w, h), format="json").status_code == 404  # Alice's private photo


def test_completion_with_a_unit_proposes_its_copies_in_the_photo(as_alice):
    """``unit`` in the body: the copies of a window with its sill, found in the photo (`completion.copies`), each
    with its score and the copy it belongs to; a bad unit is a 400 naming it."""
    from photo_helpers import CLOSED, GRID, lattice_photo, sill_of

    out = io.BytesIO()
    lattice_photo().save(out, "PNG")
    photo = upload(as_alice, out.getvalue(), title="A lattice of windows").json()
    url = f"/api/v1/photos/{photo['code']}/complete"
    rects = [{"label": "facade", "x0": 0, "y0": 0, "x1": 700, "y1": 520}]
    rects += [{"label": label, **dict(zip(("x0", "y0", "x1", "y1"), box, strict=True))}
              for label, box in (("window", GRID[7]), ("sill", sill_of(GRID[7])))]
    body = {"width": 700, "height": 520, "rects": rects, "unit": [1, 2]}
    r = as_alice.post(url, body, format="json")
    assert r.status_code == 200, r.content
    proposals = r.json()["proposals"]
    copies = len(GRID) - 1 - len(CLOSED)
    assert len(proposals) == 2 * copies and {p["copy"] for p in proposals} == set(range(copies))
    assert all(p["reason"] == "copy of the unit" and 0.6 <= p["score"] <= 1 for p in proposals)
    assert len(as_alice.post(url, {**body, "min_score": 1.0}, format="json").json()["proposals"]) == 0
    for bad, message in (([], "non-empty"), ([0], "not the wall"), ([1, 5], "from 0 to 2"), ("1", "list"),
                         ([1.5], "list")):
        r = as_alice.post(url, {**body, "unit": bad}, format="json")
        assert r.status_code == 400 and "unit" in r.json() and message in json.dumps(r.json()), (bad, r.content)
    r = as_alice.post(url, {**body, "use_photo": False}, format="json")
    assert r.status_code == 400 and "use_photo true" in json.dumps(r.json())


def test_the_draft_is_kept_for_the_owner_replaced_and_dropped_by_a_save(facade_photo, as_alice, as_bob):
    photo, seg = facade_photo
    url = f"/api/v1/photos/{photo['code']}/draft"
    assert as_alice.get(url).json() == {"draft": None}
    fewer = {**seg["data"], "rects": seg["data"]["rects"][:5]}
    r = as_alice.put(url, fewer, format="json")
    assert r.status_code == 200, r.content
    kept = as_alice.get(url).json()["draft"]
    assert kept["rect_count"] == 5 and kept["data"]["rects"] == fewer["rects"] and kept["updated"]
    more = {**seg["data"], "rects": seg["data"]["rects"][:7]}
    assert as_alice.put(url, more, format="json").json()["draft"]["rect_count"] == 7  # one draft, replaced
    assert as_alice.get(seg_url(photo)).json()["count"] == 1  # a draft is no version
    # others see nothing of it and change nothing, whatever the photo's visibility
    as_alice.patch(f"/api/v1/photos/{photo['code']}/", {"visibility": "public"}, format="json")
    assert as_bob.get(url).status_code == 403 and as_bob.put(url, fewer, format="json").status_code == 403
    assert as_alice.get(url).json()["draft"]["rect_count"] == 7
    # a bad draft is a 400 naming the problem, and the kept one stays
    for bad, message in (({**fewer, "width": fewer["width"] + 3}, "but the photo is"),
                         ({**fewer, "rects": [{"label": "tower", "x0": 0, "y0": 0, "x1": 2, "y1": 2}]}, "tower")):
        r = as_alice.put(url, bad, format="json")
        assert r.status_code == 400 and message in r.content.decode(), r.content
    assert as_alice.get(url).json()["draft"]["rect_count"] == 7
    # saving a version drops the draft; DELETE drops one too
    as_alice.post(seg_url(photo), more, format="json")
    assert as_alice.get(url).json() == {"draft": None}
    as_alice.put(url, fewer, format="json")
    assert as_alice.delete(url).status_code == 204 and as_alice.get(url).json() == {"draft": None}
    # rectifying drops it: it was drawn on the image before
    as_alice.put(url, fewer, format="json")
    w, h = photo["width"], photo["height"]
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify", {"corners": [[0, 0], [w, 0], [w, h], [0, h]]},
                      format="json")
    assert r.status_code == 200, r.content
    assert as_alice.get(url).json() == {"draft": None}
