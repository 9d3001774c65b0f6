"""The site against hostile input: pictures cost what is drawn, not what is declared; deeply nested JSON, numbers
too large for a float and unbounded pages are 400s naming the problem with nothing stored; CSRF and escaping hold.
(What a request may cost, oversized bodies refused before they are read and a locked database are checked in
`test_hardening_limits.py`; a parent shown only to those who may see it in `test_hardening_lineage.py`.)"""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image
from site_helpers import image_bytes, stored_counts, upload, wall

from facaid.generator import generate
from facaid.segmentation import rasterize
from webapp.facades.drawing import label_map
from webapp.facades.models import Photo, Procedure, Segmentation

pytestmark = pytest.mark.django_db

DEEP = "[" * 100_000 + "]" * 100_000
DEEP_OBJECT = '{"a":' * 80 + "1" + "}" * 80  # parses, but deeper than the site reads
HUGE = "1" + "0" * 400  # an integer too large for a float


# --- pictures cost what is drawn ----------------------------------------------------------------------------------

def test_label_map_at_scale_is_the_nearest_neighbour_shrink_of_the_full_map():
    seg = generate(11).segmentation
    full = rasterize(seg)
    assert np.array_equal(label_map(seg, max(seg.width, seg.height)), full)  # at full size: the same map
    small = label_map(seg, max(seg.width, seg.height) // 3)
    h, w = small.shape
    shrunk = np.asarray(Image.fromarray(full).resize((w, h), Image.Resampling.NEAREST))
    assert (small == shrunk).mean() > 0.98  # PIL rounds a few pixel centres the other way


def test_declared_sizes_are_capped_and_pictures_drawn_at_their_output_size(as_charlie, alice):
    r = as_charlie.post("/api/v1/render", wall(20_000, 20_000), format="json")
    assert r.status_code == 400 and "width must be a number from 1 to 16384" in json.dumps(r.json())
    r = as_charlie.post("/api/v1/render", wall(16_384, 8_192), format="json")
    assert r.status_code == 200 and Image.open(io.BytesIO(r.content)).size == (1024, 512)
    proc = Procedure.objects.create(owner=alice, data=wall(16_384, 16_384), visibility="public")
    r = as_charlie.get(f"/api/v1/procedures/{proc.code}/download/labels.png")
    img = Image.open(io.BytesIO(r.getvalue()))
    assert r.status_code == 200 and img.size == (2048, 2048) and img.getpixel((5, 5)) != (0, 0, 0)
    r = as_charlie.post("/api/v1/procedures/", wall(20_000, 100), format="json")
    assert r.status_code in (401, 403)  # anonymous cannot store; the owner's size cap is tested below


def test_a_procedure_larger_than_the_cap_cannot_be_stored(as_alice):
    before = stored_counts()
    r = as_alice.post("/api/v1/procedures/", {"data": wall(16_385, 100)}, format="json")
    assert r.status_code == 400 and "16384" in json.dumps(r.json())
    assert stored_counts() == before


def test_a_rectified_photo_is_at_most_the_rectified_pixel_limit(as_alice, settings):
    settings.FACAID_MAX_RECTIFIED_PIXELS = 1000
    photo = upload(as_alice, image_bytes(size=(200, 100))).json()
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify",
                      {"corners": [[0, 0], [200, 0], [200, 100], [0, 100]]}, format="json")
    assert r.status_code == 200, r.content
    img = Image.open(io.BytesIO(as_alice.get(r.json()["rectified"]).getvalue()))
    assert img.width * img.height <= 1000 and abs(img.width / img.height - 2) < 0.1


# --- no 500 from input ----------------------------------------------------------------------------------------------

def test_deeply_nested_json_is_a_400_everywhere_and_stores_nothing(facade_photo, as_alice, alice):
    photo, seg = facade_photo
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    posts = ["/api/v1/render", f"/api/v1/photos/{photo['code']}/segmentations/", "/api/v1/jobs/",
             "/api/v1/procedures/", f"/api/v1/procedures/{proc.code}/rerun",
             f"/api/v1/procedures/{proc.code}/variations", f"/api/v1/photos/{photo['code']}/rectify"]
    before = stored_counts()
    for body in (DEEP, DEEP_OBJECT):
        for url in posts:
            r = as_alice.post(url, body, content_type="application/json")
            assert r.status_code == 400 and "levels deep" in r.json().get("detail", ""), (url, r.content[:300])
        r = as_alice.patch(f"/api/v1/procedures/{proc.code}/", body, content_type="application/json")
        assert r.status_code == 400 and "levels deep" in r.json()["detail"]
        r = as_alice.post(f"/photos/{photo['code']}/segmentation", {"text": body}, follow=True)
        assert r.status_code == 200 and "levels deep" in r.content.decode()
    assert stored_counts() == before
    assert Procedure.objects.get(id=proc.id).data == generate(3).procedure.to_dict()


def test_the_deepest_procedure_the_grammar_allows_is_read(as_alice):
    from facaid.grammar.procedure import MAX_DEPTH

    node = {"rule": "leaf", "label": "window"}
    for _ in range(MAX_DEPTH):
        node = {"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [node]}
    r = as_alice.post("/api/v1/procedures/", {"data": {**wall(100, 100), "root": node}}, format="json")
    assert r.status_code == 201, r.content[:300]
    node = {"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [node]}
    r = as_alice.post("/api/v1/procedures/", {"data": {**wall(100, 100), "root": node}}, format="json")
    assert r.status_code == 400 and "too deep" in json.dumps(r.json())  # the grammar's own limit names it


def test_numbers_too_large_for_a_float_are_a_400(facade_photo, as_alice, alice):
    photo, seg = facade_photo
    before = stored_counts()
    data = json.loads(json.dumps(seg["data"]))
    data["rects"][0]["x1"] = int(HUGE)
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", json.dumps(data),
                      content_type="application/json")
    assert r.status_code == 400 and "rects[0].x1 must be finite" in json.dumps(r.json()), r.content
    tree = generate(3).procedure.to_dict()
    for key in ("width", "height"):
        r = as_alice.post("/api/v1/procedures/", json.dumps({"data": {**tree, key: int(HUGE)}}),
                          content_type="application/json")
        assert r.status_code == 400 and key in json.dumps(r.json())
    tree["root"]["sizes"][0][1] = int(HUGE)
    r = as_alice.post("/api/v1/render", json.dumps(tree), content_type="application/json")
    assert r.status_code == 400 and "must be finite" in json.dumps(r.json())
    for x in (HUGE, "1e999"):  # the second is infinity once parsed
        r = as_alice.post(f"/api/v1/photos/{photo['code']}/rectify",
                          f'{{"corners": [[{x}, 0], [10, 0], [10, 10], [0, 10]]}}', content_type="application/json")
        assert r.status_code == 400 and "corners" in r.json(), r.content
    assert stored_counts() == before


@pytest.mark.parametrize("query", ["limit=99999999999999999999", "limit=100000", "offset=99999999999999999999",
                                   "limit=-5", "limit=abc&offset=-1"])
def test_pages_are_bounded(as_charlie, alice, query):
    for i in range(3):
        Procedure.objects.create(owner=alice, title=f"p{i}", data=wall(100, 100), visibility="public")
    r = as_charlie.get(f"/api/v1/gallery/?{query}")
    assert r.status_code == 200, r.content
    assert r.json()["count"] == 3 and len(r.json()["results"]) <= 100


def test_many_public_procedures_are_served_at_most_100_a_page(as_charlie, alice):
    Procedure.objects.bulk_create([Procedure(owner=alice, title=f"p{i}", data=wall(10, 10), visibility="public")
                                   for i in range(120)])
    assert len(as_charlie.get("/api/v1/gallery/?limit=99999999999999999999").json()["results"]) == 100


@pytest.mark.parametrize("body", [{"nodes": 1.9}, {"nodes": True}, {"nodes": 0}, {"nodes": 9000}, {"nodes": "x"},
                                  {"nodes": int(HUGE)}, {"k": 1.5}, {"k": 99}, {"k": False}])
def test_rerun_takes_the_same_integers_as_a_job(facade_photo, as_alice, alice, body):
    _, seg = facade_photo
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    before = stored_counts()
    r = as_alice.post(f"/api/v1/procedures/{proc.code}/rerun", json.dumps(body), content_type="application/json")
    assert r.status_code == 400 and set(r.json()) == set(body), r.content
    assert stored_counts() == before
    r = as_alice.post(f"/api/v1/procedures/{proc.code}/rerun", {"nodes": 3, "k": 2}, format="json")
    assert r.status_code == 202 and r.json()["params"]["prefix_nodes"] == 3


def test_json_bodies_parse_as_before(as_alice, facade_photo):
    """The bounded parser is DRF's: strict (no NaN), and a plain document passes."""
    photo, seg = facade_photo
    r = as_alice.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg["data"], format="json")
    assert r.status_code == 201
    r = as_alice.post("/api/v1/render", '{"width": NaN}', content_type="application/json")
    assert r.status_code == 400 and "NaN" in r.json()["detail"]


def test_deep_json_on_the_default_parser_is_a_400(facade_photo, as_alice):
    photo, _ = facade_photo
    r = as_alice.patch(f"/api/v1/photos/{photo['code']}/", DEEP, content_type="application/json")
    assert r.status_code == 400 and "levels deep" in r.json()["detail"]


@pytest.mark.parametrize("meta, message", [('{"note": "a\\u0000b"}', "NUL"), ('{"note": "\\ud800"}', "plain JSON"),
                                           ('{"n": 1e999}', "valid JSON"), (f'{{"n": "{"x" * 70000}"}}', "too long")])
def test_procedure_notes_are_plain_json_that_every_database_stores(as_alice, meta, message):
    tree = json.dumps(wall(100, 100))[:-1] + f', "meta": {meta}}}'
    before = stored_counts()
    r = as_alice.post("/api/v1/procedures/", f'{{"data": {tree}}}', content_type="application/json")
    assert r.status_code == 400 and message in json.dumps(r.json()), r.content[:300]
    assert stored_counts() == before


def test_the_page_form_reads_an_integer_of_too_many_digits_as_bad_json(facade_photo, as_alice):
    photo, _ = facade_photo
    r = as_alice.post(f"/photos/{photo['code']}/segmentation", {"text": '{"width": ' + "1" * 5000 + "}"},
                      follow=True)
    assert r.status_code == 200 and "not valid JSON" in r.content.decode()
    assert Segmentation.objects.count() == 1


# --- CSRF and escaping ----------------------------------------------------------------------------------------------

def test_csrf_is_enforced_on_pages_and_the_api(alice, facade_photo):
    from rest_framework.test import APIClient

    photo, _ = facade_photo
    client = APIClient(enforce_csrf_checks=True)
    client.force_login(alice)
    before = stored_counts()
    r = client.post("/api/v1/procedures/", {"data": wall(10, 10)}, format="json")
    assert r.status_code == 403 and "CSRF" in r.json()["detail"]
    r = client.post(f"/photos/{photo['code']}/visibility", {"visibility": "public"})
    assert r.status_code == 403
    assert Photo.objects.get(code=photo["code"]).visibility == "private" and stored_counts() == before
    # with the token from a page, the same requests pass
    client.get("/")
    token = client.cookies["csrftoken"].value
    r = client.post("/api/v1/procedures/", {"data": wall(10, 10)}, format="json", HTTP_X_CSRFTOKEN=token)
    assert r.status_code == 201


def test_titles_are_escaped_on_every_page(alice, as_alice, as_charlie):
    evil = '<script>alert("x")</script><img src=x onerror=alert(1)>'
    proc = Procedure.objects.create(owner=alice, title=evil, data=wall(100, 100), visibility="public")
    photo = upload(as_alice, image_bytes(), title=evil, visibility="public").json()
    fork = as_alice.post(f"/api/v1/procedures/{proc.code}/fork").json()
    for client, url in ((as_charlie, "/"), (as_charlie, f"/procedures/{proc.code}"), (as_alice, "/"),
                        (as_charlie, f"/photos/{photo['code']}"), (as_alice, f"/procedures/{fork['code']}")):
        page = client.get(url).content.decode()
        assert "<script>alert" not in page and "<img src=x" not in page, url
        assert "&lt;script&gt;alert" in page, url
