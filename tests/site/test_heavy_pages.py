"""Pages, pictures and uploads are heavy requests too (issue 66): the procedure page and every picture that must be
drawn take one of the process's heavy slots and the heavy rate, and a page past its slots or its budget is shown
light: its tree, without what it could not draw. Uploads take the slots as the API's other heavy requests do.
And each tree a request reads is charged to its budget before any of them is drawn."""

from __future__ import annotations

import io

import pytest
from grammar_helpers import probe
from PIL import Image

from facaid.generator import generate
from facaid.grammar.layout import count_expansion
from webapp.facades import throttling
from webapp.facades.models import Photo, Procedure
from webapp.facades.views import BUSY_NOTE

pytestmark = pytest.mark.django_db


def picture_src(html: str) -> bool:
    tag = html.split('<img id="render"', 1)[1].split(">", 1)[0]
    return "src=" in tag


@pytest.fixture
def busy(settings):
    """Every heavy slot of this process taken (one, held here)."""
    settings.FACAID_HEAVY_SLOTS = 1
    slots = throttling.slots()
    assert slots.take()
    yield
    slots.give_back()


def test_a_stored_tree_that_cannot_be_drawn_is_shown_without_its_picture(alice, as_charlie):
    # issue 66's tree, stored as the site accepted it before its cost model counted exceptions
    proc = Procedure.objects.create(owner=alice, title="probe", data=probe(rows=100), visibility="public")
    r = as_charlie.get(f"/procedures/{proc.code}")
    html = r.content.decode()
    assert r.status_code == 200 and "This procedure cannot be drawn" in html and "more than 100000" in html
    assert not picture_src(html) and 'id="procedure-data"' in html  # the tree is there, the picture is not
    r = as_charlie.get(f"/api/v1/procedures/{proc.code}/download/labels.png")
    assert r.status_code == 400 and "cannot be drawn" in r.json()["data"]


def test_a_page_past_the_requests_budget_is_shown_without_its_picture(alice, as_charlie, settings):
    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict(), visibility="public")
    assert picture_src(as_charlie.get(f"/procedures/{proc.code}").content.decode())
    settings.FACAID_REQUEST_WORK = count_expansion(tree.root, tree.width, tree.height).instances - 1
    r = as_charlie.get(f"/procedures/{proc.code}")
    html = r.content.decode()
    assert r.status_code == 200 and "This procedure is not drawn here" in html and "node instances" in html
    assert not picture_src(html)


def test_pages_and_pictures_that_draw_share_the_heavy_slots(alice, as_charlie, busy):
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public")
    r = as_charlie.get(f"/procedures/{proc.code}")  # light: the tree, the kept picture, no scale worked out
    html = r.content.decode()
    assert r.status_code == 200 and BUSY_NOTE.split(":")[0] in html and picture_src(html)
    for url in (f"/api/v1/procedures/{proc.code}/download/labels.png", f"/api/v1/procedures/{proc.code}/thumbnail.png",
                f"/api/v1/procedures/{proc.code}/versions/1/labels.png"):
        r = as_charlie.get(url)  # not kept (no save committed here): to be drawn, and no slot is free
        assert r.status_code == 503 and r["Retry-After"] == "2" and r["X-Facaid-Busy"] == "slots", url
    throttling.slots().give_back()
    try:
        assert as_charlie.get(f"/api/v1/procedures/{proc.code}/download/labels.png").status_code == 200  # and kept
    finally:
        assert throttling.slots().take()
    r = as_charlie.get(f"/api/v1/procedures/{proc.code}/download/labels.png")
    assert r.status_code == 200 and r["Content-Type"] == "image/png"  # a kept picture is light: no slot needed
    assert as_charlie.get("/api/v1/gallery/").status_code == 200


def test_uploads_take_the_heavy_slots(as_alice, busy):
    buf = io.BytesIO()
    Image.new("RGB", (64, 48), (120, 110, 100)).save(buf, "PNG")
    from django.core.files.uploadedfile import SimpleUploadedFile

    r = as_alice.post("/api/v1/photos/", {"image": SimpleUploadedFile("a.png", buf.getvalue())}, format="multipart")
    assert r.status_code == 503 and r["X-Facaid-Busy"] == "slots"
    r = as_alice.post("/photos/new", {"image": SimpleUploadedFile("a.png", buf.getvalue()), "title": "t",
                                      "visibility": "private"})
    assert r.status_code == 503 and "the site is busy" in r.content.decode()
    assert not Photo.objects.exists()
    assert as_alice.get("/api/v1/photos/").status_code == 200  # listing them is light


def test_comparing_reads_each_tree_once_before_drawing_either(alice, as_charlie, settings):
    a, b = generate(3).procedure, generate(4).procedure
    proc = Procedure.objects.create(owner=alice, data=a.to_dict(), visibility="public")
    proc.data = b.to_dict()
    proc.save()
    work = sum(count_expansion(t.root, t.width, t.height).instances for t in (a, b))
    settings.FACAID_REQUEST_WORK = work  # the two trees, each read once
    url = f"/api/v1/procedures/{proc.code}/versions/compare"
    r = as_charlie.get(f"{url}?a=1&b=2")
    assert r.status_code == 200 and (r.json()["b"]["width"], r.json()["b"]["height"]) == (b.width, b.height)
    assert as_charlie.get(f"{url}.png?a=1&b=2").status_code == 200
    settings.FACAID_REQUEST_WORK = work - 1
    r = as_charlie.get(f"{url}.png?a=1&b=2")
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"]


def test_a_download_is_charged_what_writing_its_rectangles_costs_before_it_is_written(alice, as_charlie, settings):
    """IFC writes about 100 us a rectangle (bench/bench_request_cost.py): its cost is charged to the request's budget
    with the tree's own, before a byte is written, so a tree it cannot write in its budget is a 400 at once."""
    from facaid.grammar.layout import count_leaves
    from webapp.facades.downloads import DOWNLOADS

    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict(), visibility="public")
    units = count_expansion(tree.root, tree.width, tree.height).instances
    writing = DOWNLOADS["facade.ifc"].per_leaf * count_leaves(tree.root, tree.width, tree.height)
    url = f"/api/v1/procedures/{proc.code}/download/facade.ifc"
    settings.FACAID_REQUEST_WORK = units + writing
    assert as_charlie.get(url).status_code == 200
    settings.FACAID_REQUEST_WORK = units + writing - 1
    r = as_charlie.get(url)
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"]
    assert as_charlie.get(f"/api/v1/procedures/{proc.code}/download/procedure.json").status_code == 200


def test_variations_and_parameter_edits_are_refused_before_their_trees_are_made(alice, as_charlie, settings):
    """A request for n variants or k values is charged n (k) trees before one is made: past the budget, a 400 at
    once, where it was one after the work (32 variations of a 95,474-unit tree: 2 s, then a 400)."""
    from webapp.facades.api.procedures import PARAMETER_WORK, VARIANT_WORK

    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict(), visibility="public")
    units = count_expansion(tree.root, tree.width, tree.height).instances
    settings.FACAID_REQUEST_WORK = units * (1 + 2 * VARIANT_WORK)
    url = f"/api/v1/procedures/{proc.code}"
    assert as_charlie.post(f"{url}/variations", {"n": 2}, format="json").status_code == 200
    r = as_charlie.post(f"{url}/variations", {"n": 3}, format="json")
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"]
    settings.FACAID_REQUEST_WORK = units * (1 + 2 * PARAMETER_WORK)
    values = {"width": tree.width + 20, "height": tree.height + 20}
    assert as_charlie.post(f"{url}/parameters", {"values": values}, format="json").status_code == 200
    r = as_charlie.post(f"{url}/parameters", {"values": {**values, "floor_height": 90}}, format="json")
    assert r.status_code == 400 and "node instances in all" in r.json()["detail"]
