"""The demo (`manage.py demo`) is read-only: its password is public, and a PATCH of its procedure as the demo account
once gave every visitor of the front page a 400 after 16 s of CPU (issue 66, finding 6b). Fork to edit. The front page
draws the demo's pictures within a budget of its own and keeps what it drew, or that it could not."""

from __future__ import annotations

import pytest
from django.core.cache import caches
from django.core.management import call_command
from rest_framework.test import APIClient
from site_helpers import client_for, facade_png, upload

from facaid.generator import generate
from webapp.facades import example
from webapp.facades.models import Photo, Procedure, Segmentation

pytestmark = pytest.mark.django_db


@pytest.fixture
def demo():
    """The demo as `scripts/run` leaves it: the account, its public photo and segmentation, and the public procedure
    the worker made of them (made here, as the worker would)."""
    call_command("demo")
    photo = Photo.objects.get(owner__username="demo")
    seg = Segmentation.objects.get(photo=photo)
    return Procedure.objects.create(owner=photo.owner, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=photo, segmentation=seg, accuracy=0.99, title="Demo")


@pytest.fixture
def as_demo(demo):
    client = APIClient()
    r = client.post("/accounts/login/", {"username": "demo", "password": "demo-facade"})  # anyone can
    assert r.status_code == 302, r.content[:300]
    return client


def refused(response) -> bool:
    return response.status_code == 403 and "fork" in response.json()["detail"]


def test_the_demo_account_cannot_change_the_demo(demo, as_demo):
    code, photo = demo.code, demo.photo.code
    before, versions = demo.data, demo.versions.count()
    wide = {**demo.data, "width": demo.data["width"] * 2}
    api = f"/api/v1/procedures/{code}"
    for r in (as_demo.patch(f"{api}/", {"data": wide}, format="json"),
              as_demo.patch(f"{api}/", {"title": "mine now"}, format="json"),
              as_demo.patch(f"{api}/", {"visibility": "private"}, format="json"),
              as_demo.delete(f"{api}/"),
              as_demo.post(f"{api}/versions/1/revert"),
              as_demo.post(f"{api}/parameters", {"values": {"floors": 3}, "save": True}, format="json"),
              as_demo.post(f"{api}/rerun", {"nodes": 2}, format="json"),
              as_demo.patch(f"/api/v1/photos/{photo}/", {"visibility": "private"}, format="json"),
              as_demo.delete(f"/api/v1/photos/{photo}/"),
              as_demo.post(f"/api/v1/photos/{photo}/segmentations/", facade_png()[1], format="json"),
              as_demo.post(f"/api/v1/photos/{photo}/rectify", {"corners": [[0, 0], [9, 0], [9, 9], [0, 9]]},
                           format="json"),
              as_demo.post("/api/v1/jobs/", {"segmentation": str(demo.segmentation.code)}, format="json")):
        assert refused(r), (r.request["PATH_INFO"], r.status_code, r.content[:300])
    demo.refresh_from_db()
    assert demo.data == before and demo.versions.count() == versions and demo.visibility == "public"
    assert Photo.objects.get(code=photo).visibility == "public" and demo.photo.segmentations.count() == 1
    r = upload(as_demo, facade_png()[0])  # a photo of the demo's would be the demo's: nobody could change it
    assert r.status_code == 403 and "sign up" in r.json()["detail"]
    # the pages say so, and offer the owner's buttons to nobody
    page = as_demo.get(f"/procedures/{code}").content.decode()
    assert 'id="demo-note"' in page and 'id="save"' not in page and 'id="save-new"' in page
    assert "Fork it" in page and "log in</a> or" not in page  # logged in: the fork is on the page
    assert as_demo.post(f"/procedures/{code}/delete").status_code == 403
    assert Procedure.objects.filter(code=code).exists()


def test_the_demo_is_forked_to_edit(demo, as_demo, alice):
    r = as_demo.post(f"/api/v1/procedures/{demo.code}/fork")
    assert r.status_code == 201
    fork = r.json()["code"]  # the demo account's own copy: it edits it
    wide = {**demo.data, "width": demo.data["width"] + 10}
    r = as_demo.patch(f"/api/v1/procedures/{fork}/", {"data": wide, "title": "my copy"}, format="json")
    assert r.status_code == 200 and r.json()["title"] == "my copy"
    assert as_demo.post(f"/api/v1/procedures/{demo.code}/save-as-new", {}, format="json").status_code == 201
    assert client_for(alice).post(f"/api/v1/procedures/{demo.code}/fork").status_code == 201
    assert Procedure.objects.get(code=demo.code).versions.count() == 1


def test_others_get_the_403_they_always_got(demo, alice):
    r = client_for(alice).patch(f"/api/v1/procedures/{demo.code}/", {"title": "x"}, format="json")
    assert r.status_code == 403 and "only the owner" in r.json()["detail"]
    mine = upload(client_for(alice), facade_png()[0]).json()  # and uploads are anyone's but the demo's
    assert client_for(alice).patch(f"/api/v1/photos/{mine['code']}/", {"title": "t"}, format="json").status_code == 200


def test_the_front_page_draws_the_demo_within_its_own_budget(demo, settings):
    """A request's budget that the demo's pictures would run past (the crafted tree's 16 s did) no longer makes the
    front page a 400: the pictures have their own budget, and are kept."""
    settings.FACAID_REQUEST_WORK = 1000  # the demo's pictures count ~15,000 node instances
    r = APIClient().get("/")
    assert r.status_code == 200
    assert r.content.decode().count('src="data:image/png;base64,') == example.VARIANTS


def test_a_demo_too_heavy_to_draw_leaves_the_front_page_up_and_is_not_redrawn(demo, monkeypatch, caplog):
    monkeypatch.setattr(example, "EXAMPLE_WORK", 1000)
    key = f"front-example:{demo.code}:{demo.digest}"
    for _ in range(2):
        r = APIClient().get("/")
        assert r.status_code == 200 and 'id="example"' in r.content.decode()
        assert 'src="data:image/png;base64,' not in r.content.decode()
    assert caches["pages"].get(key) == {"caption": "", "variations": []}
    assert sum("without its pictures" in m for m in caplog.messages) == 1  # drawn once, not on every visit
